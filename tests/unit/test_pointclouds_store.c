/* The point cloud tables (store/pointclouds.h, migration 0009): a cloud with normals and a
 * property of every type stored in chunks of 7, 64 and 1000 points (chunk borders inside
 * and at the end) and read back whole and column by column, the level-of-detail prefix,
 * segmentations with their ids read back, the states undo keeps and restores, segmentations
 * released when nothing names them any more, everything gone with the model, and a model
 * that is not a cloud. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "core/points/lod.h"
#include "random_fixture.h"
#include "store/grammars.h"
#include "store/models.h"
#include "store/pointclouds.h"
#include "store/states.h"
#include "store_fixture.h"

static int64_t a_model(ag_db *db, const char *kind)
{
    ag_model_new m = {.name = "cloud", .kind = kind, .mesh = "", .mesh_len = 0};
    return insert_model(db, &m);
}

static ag_cloud *make_cloud(size_t n, uint64_t seed)
{
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    assert_int_equal(ag_cloud_add_normals(c, NULL), AG_OK);
    c->offset[0] = 85000;
    c->offset[1] = 446000;
    for (size_t i = 0; i < 3 * c->n; i++) {
        c->xyz[i] = uniform(&seed, -30, 30);
        c->normals[i] = (float)uniform(&seed, -1, 1);
    }
    for (int t = 0; t < AG_SCALAR_COUNT; t++) {
        char name[16];
        snprintf(name, sizeof name, "p_%s", ag_scalar_name((ag_scalar_type)t));
        size_t idx;
        assert_int_equal(ag_cloud_add_property(c, name, (ag_scalar_type)t, &idx, NULL), AG_OK);
        for (size_t i = 0; i < n; i++)
            ag_cloud_set(&c->props[idx], i, (double)(next_random(&seed) % 200) - 50);
    }
    return c;
}

static void put_cloud(ag_db *db, int64_t model, const ag_cloud *c, size_t chunk, uint32_t *lod)
{
    ag_error err;
    assert_int_equal(ag_lod_order(c, 0, lod, NULL), AG_OK);
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    if (ag_pointclouds_put(db, model, c, lod, chunk, &err) != AG_OK)
        fail_msg("%s", err.text);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

static void clouds_come_back_in_every_chunking(void **state)
{
    (void)state;
    const size_t chunks[] = {7, 64, 1000};
    for (size_t k = 0; k < 3; k++) {
        char *path;
        ag_db *db = open_temp_db(&path);
        size_t n = 500;
        ag_cloud *c = make_cloud(n, 5 + k);
        uint32_t *lod = malloc(n * sizeof *lod);
        int64_t model = a_model(db, "pointcloud");
        put_cloud(db, model, c, chunks[k], lod);
        ag_pointcloud_info info;
        ag_error err;
        assert_int_equal(ag_pointclouds_info(db, model, &info, &err), AG_OK);
        assert_int_equal(info.points, n);
        assert_int_equal(info.chunk_points, chunks[k]);
        assert_int_equal(info.nprops, AG_SCALAR_COUNT);
        assert_true(info.normals);
        assert_int_equal(info.positions, AG_CLOUDBLOB_F64);
        assert_int_equal(info.segmentation, 0);
        assert_true(info.offset[0] == 85000 && info.offset[1] == 446000);
        size_t rows = (n + chunks[k] - 1) / chunks[k];
        char sql[128];
        snprintf(sql, sizeof sql, "SELECT count(*) FROM pointcloud_columns WHERE model_id = %lld",
                 (long long)model);
        assert_int_equal(count(db, sql), (long long)rows * (3 + AG_SCALAR_COUNT));
        ag_cloud *back;
        assert_int_equal(ag_pointclouds_load(db, &info,
                                             AG_POINTCLOUDS_POSITIONS | AG_POINTCLOUDS_NORMALS |
                                                 AG_POINTCLOUDS_PROPERTIES,
                                             NULL, &back, &err),
                         AG_OK);
        assert_int_equal(back->n, n);
        assert_memory_equal(back->xyz, c->xyz, 3 * n * sizeof(double));
        assert_memory_equal(back->normals, c->normals, 3 * n * sizeof(float));
        assert_memory_equal(back->offset, c->offset, sizeof c->offset);
        assert_int_equal(back->nprops, c->nprops);
        for (size_t p = 0; p < c->nprops; p++) {
            assert_string_equal(back->props[p].name, c->props[p].name);
            assert_int_equal(back->props[p].type, c->props[p].type);
            assert_memory_equal(back->props[p].values, c->props[p].values,
                                n * ag_scalar_size(c->props[p].type));
        }
        ag_cloud_free(back);
        /* one property by name, no normals */
        const char *only[] = {"p_uint16", NULL};
        assert_int_equal(ag_pointclouds_load(db, &info,
                                             AG_POINTCLOUDS_POSITIONS | AG_POINTCLOUDS_PROPERTIES,
                                             only, &back, &err),
                         AG_OK);
        assert_null(back->normals);
        assert_int_equal(back->nprops, 1);
        assert_memory_equal(back->props[0].values, ag_cloud_find(c, "p_uint16")->values,
                            n * sizeof(uint16_t));
        ag_cloud_free(back);
        /* any prefix of the order */
        uint32_t got[500];
        for (size_t m = 1; m <= n; m += 83) {
            memset(got, 0xff, sizeof got);
            assert_int_equal(ag_pointclouds_load_order(db, &info, m, got, &err), AG_OK);
            assert_memory_equal(got, lod, m * sizeof *got);
            if (m < n)
                assert_int_equal(got[m], 0xffffffffu);
        }
        free(lod);
        ag_cloud_free(c);
        close_temp_db(db, path);
    }
}

/* A segmentation of n points with s segments (the second half planes: planes need not be
 * the first ids). */
static ag_segment_cloud_result *fake_segmentation(size_t n, size_t s, int shift)
{
    ag_segment_cloud_result *r = calloc(1, sizeof *r);
    r->n = n;
    r->segment = malloc(n * sizeof(int32_t));
    r->label = malloc(n * sizeof(int32_t));
    r->piece = malloc(n * sizeof(int32_t));
    for (size_t i = 0; i < n; i++) {
        int32_t seg = i % 11 == 0 ? -1 : (int32_t)((i + (size_t)shift) % s);
        r->segment[i] = seg;
        r->label[i] = seg < 0 ? -1 : seg / 3;
        r->piece[i] = seg < 0 ? -1 : 2 * seg;
    }
    r->nsegments = s;
    r->nplanes = s / 2;
    r->segments = calloc(s, sizeof *r->segments);
    for (size_t k = 0; k < s; k++)
        r->segments[k].kind = k >= s - s / 2 ? AG_SEGMENT_CLOUD_PLANE : AG_SEGMENT_CLOUD_CLUSTERED;
    r->npieces = 2 * s;
    r->nlabels = (s + 2) / 3;
    r->spacing = 0.125;
    return r;
}

static void put_seg(ag_db *db, int64_t model, int64_t version, const ag_segment_cloud_result *r)
{
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    if (ag_pointclouds_put_segmentation(db, model, version, r, "{\"x\":1}", NULL, &err) != AG_OK)
        fail_msg("%s", err.text);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

static void assert_current(ag_db *db, int64_t model, const ag_segment_cloud_result *want)
{
    ag_pointcloud_info info;
    ag_pointcloud_segmentation s;
    ag_error err;
    assert_int_equal(ag_pointclouds_info(db, model, &info, &err), AG_OK);
    if (!want) {
        assert_int_equal(ag_pointclouds_get_segmentation(db, &info, 1, &s, &err), AG_ERR_NOT_FOUND);
        assert_non_null(strstr(err.text, "not segmented"));
        return;
    }
    assert_int_equal(ag_pointclouds_get_segmentation(db, &info, 1, &s, &err), AG_OK);
    assert_int_equal(s.nsegments, want->nsegments);
    assert_int_equal(s.nplanes, want->nplanes);
    assert_int_equal(s.npieces, want->npieces);
    assert_int_equal(s.nlabels, want->nlabels);
    assert_true(s.spacing == want->spacing);
    assert_string_equal(s.summary_json, "{\"x\":1}");
    assert_memory_equal(s.segment, want->segment, want->n * sizeof(int32_t));
    assert_memory_equal(s.label, want->label, want->n * sizeof(int32_t));
    assert_memory_equal(s.piece, want->piece, want->n * sizeof(int32_t));
    assert_non_null(s.kind); /* each id's kind */
    for (size_t k = 0; k < want->nsegments; k++)
        assert_int_equal(s.kind[k], want->segments[k].kind);
    ag_pointcloud_segmentation_clear(&s);

}

static void keep(ag_db *db, int64_t model, int64_t version)
{
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_states_keep(db, model, version, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

static void restore(ag_db *db, int64_t model, int64_t version)
{
    ag_error err;
    ag_state_row row;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_states_get(db, model, version, &row, &err), AG_OK);
    assert_int_equal(ag_states_restore(db, model, version, &row, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    ag_states_row_clear(&row);
}

static void segmentations_follow_the_states(void **state)
{
    (void)state;
    char *path;
    ag_db *db = open_temp_db(&path);
    size_t n = 300;
    ag_cloud *c = make_cloud(n, 1);
    uint32_t *lod = malloc(n * sizeof *lod);
    int64_t model = a_model(db, "pointcloud");
    put_cloud(db, model, c, 64, lod);
    assert_current(db, model, NULL);
    /* ids in every width: 5 segments (1 byte), 200 (2 bytes), 40000 (4 bytes) */
    ag_segment_cloud_result *a = fake_segmentation(n, 5, 0), *b = fake_segmentation(n, 200, 3),
                            *w = fake_segmentation(n, 40000, 7);
    sqlite3_exec(ag_db_handle(db), "UPDATE models SET version = 4", NULL, NULL, NULL);
    keep(db, model, 1); /* not segmented then */
    put_seg(db, model, 2, a);
    assert_current(db, model, a);
    keep(db, model, 2);
    put_seg(db, model, 3, b);
    keep(db, model, 3);
    assert_current(db, model, b);
    /* back to version 2, then 1, then 3 */
    restore(db, model, 2);
    assert_current(db, model, a);
    restore(db, model, 1);
    assert_current(db, model, NULL);
    restore(db, model, 3);
    assert_current(db, model, b);
    /* a segmentation no state keeps goes when it stops being current */
    put_seg(db, model, 4, w);
    assert_current(db, model, w);
    assert_int_equal(count(db, "SELECT count(*) FROM pointcloud_segmentations"), 3);
    put_seg(db, model, 4, a);
    assert_int_equal(count(db, "SELECT count(*) FROM pointcloud_segmentations"), 3);
    assert_int_equal(count(db, "SELECT count(*) FROM pointcloud_segmentations WHERE segments = 40000"), 0);
    assert_int_equal(count(db, "SELECT count(*) FROM pointcloud_segmentation_chunks WHERE "
                               "segmentation_id NOT IN (SELECT id FROM pointcloud_segmentations)"),
                     0);
    /* a mesh model: its states keep nothing of clouds, and a restore touches none */
    int64_t mesh = a_model(db, NULL);
    keep(db, mesh, 1);
    assert_int_equal(count(db, "SELECT count(*) FROM pointcloud_states WHERE model_id = 2"), 0);
    restore(db, mesh, 1);
    ag_pointcloud_info info;
    ag_error err;
    assert_int_equal(ag_pointclouds_info(db, mesh, &info, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "not a point cloud"));
    /* everything goes with the model */
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_delete(db, model, 4, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    const char *tables[] = {"pointclouds", "pointcloud_columns", "pointcloud_segmentations",
                            "pointcloud_segmentation_chunks", "pointcloud_states"};
    for (size_t t = 0; t < 5; t++) {
        char sql[96];
        snprintf(sql, sizeof sql, "SELECT count(*) FROM %s", tables[t]);
        assert_int_equal(count(db, sql), 0);
    }
    assert_int_equal(count(db, "SELECT count(*) FROM pragma_foreign_key_check"), 0);
    ag_segment_cloud_free(a);
    ag_segment_cloud_free(b);
    ag_segment_cloud_free(w);
    free(lod);
    ag_cloud_free(c);
    close_temp_db(db, path);
}

static void a_segmentation_of_another_cloud_is_refused(void **state)
{
    (void)state;
    char *path;
    ag_db *db = open_temp_db(&path);
    ag_cloud *c = make_cloud(50, 2);
    uint32_t lod[50];
    int64_t model = a_model(db, "pointcloud");
    put_cloud(db, model, c, 0, lod);
    ag_segment_cloud_result *r = fake_segmentation(49, 3, 0);
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_pointclouds_put_segmentation(db, model, 2, r, NULL, NULL, &err),
                     AG_ERR_INTERNAL);
    ag_db_rollback(db);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    close_temp_db(db, path);
}

/* A segmentation stored before each id had its kind (migration 0012: kinds NULL) reads back
 * without kinds, for the reader to take the ids below planes as the planes; kinds that do
 * not cover every id are refused by the schema. */
static void a_segmentation_stored_before_kinds_reads_without_them(void **state)
{
    (void)state;
    char *path;
    ag_db *db = open_temp_db(&path);
    ag_cloud *c = make_cloud(60, 2);
    uint32_t lod[60];
    int64_t model = a_model(db, "pointcloud");
    put_cloud(db, model, c, 0, lod);
    ag_segment_cloud_result *r = fake_segmentation(60, 6, 1);
    put_seg(db, model, 1, r);
    sqlite3 *h = ag_db_handle(db);
    assert_int_equal(sqlite3_exec(h, "UPDATE pointcloud_segmentations SET kinds = x'0001'",
                                  NULL, NULL, NULL) & 0xff,
                     SQLITE_CONSTRAINT);
    assert_int_equal(sqlite3_exec(h, "UPDATE pointcloud_segmentations SET kinds = NULL", NULL,
                                  NULL, NULL),
                     SQLITE_OK);
    ag_pointcloud_info info;
    ag_pointcloud_segmentation s;
    ag_error err;
    assert_int_equal(ag_pointclouds_info(db, model, &info, &err), AG_OK);
    assert_int_equal(ag_pointclouds_get_segmentation(db, &info, 1, &s, &err), AG_OK);
    assert_null(s.kind);
    assert_int_equal(s.nsegments, 6);
    assert_int_equal(s.nplanes, 3);
    assert_memory_equal(s.segment, r->segment, 60 * sizeof(int32_t));
    ag_pointcloud_segmentation_clear(&s);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    close_temp_db(db, path);
}

/* A point grammar saved as a new version, with the terminals it brings, and its state kept. */
static int64_t save_points(ag_db *db, int64_t model, int64_t base, const char *text,
                           const char *const *paths)
{
    ag_error err;
    int64_t version = 0, blob = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(db, model, base, &version, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, model, "", 0, "{}", &blob, &err), AG_OK);
    ag_grammar_new g = {.model = model, .version = version, .mesh_blob = blob, .text = text,
                        .text_len = strlen(text), .tree_json = "{\"root\":0}",
                        .summary_json = "{}"};
    assert_int_equal(ag_grammars_put(db, &g, &err), AG_OK);
    for (size_t i = 0; paths[i]; i++)
        assert_int_equal(ag_grammars_put_terminal(db, model, paths[i], "ply\n", 4, &err), AG_OK);
    assert_int_equal(ag_states_keep(db, model, version, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return version;
}

static size_t release(ag_db *db, int64_t model)
{
    ag_error err;
    size_t n = 99;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_pointclouds_release_terminals(db, model, &n, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return n;
}

static int has_terminal(ag_db *db, int64_t model, const char *path)
{
    char *data = NULL;
    size_t len = 0;
    ag_error err;
    ag_status s = ag_grammars_get_terminal(db, model, path, &data, &len, &err);
    free(data);
    assert_true(s == AG_OK || s == AG_ERR_NOT_FOUND);
    return s == AG_OK;
}

/* Terminals stay while the current grammar or a kept state names them (as a whole quoted
 * path: a path inside a longer one is not a name), and go once none does. */
static void terminals_go_when_no_version_names_them(void **state)
{
    (void)state;
    char *path;
    ag_db *db = open_temp_db(&path);
    int64_t model = a_model(db, "pointcloud"), other = a_model(db, "pointcloud");
    static const char *const first[] = {"terminals/00aa.ply", "terminals/00bb.ply", NULL};
    static const char *const second[] = {"terminals/00cc.ply", "terminals/00a.ply", NULL};
    int64_t v2 = save_points(db, model, 1,
                             "axiom A\nA -> I(\"terminals/00aa.ply\") I(\"terminals/00bb.ply\")\n",
                             first);
    /* the other model's terminal of the same path is its own */
    save_points(db, other, 1, "axiom A\nA -> I(\"terminals/00cc.ply\")\n", second);
    /* the second version drops 00aa, brings 00cc and a terminal it does not name (00a) */
    int64_t v3 = save_points(db, model, v2,
                             "axiom A\nA -> I(\"terminals/00bb.ply\") I(\"terminals/00cc.ply\")\n",
                             second);
    assert_int_equal(ag_grammars_count_terminals(db, model), 4);
    assert_int_equal(release(db, model), 1);
    assert_false(has_terminal(db, model, "terminals/00a.ply"));
    /* 00aa: version 2's kept state names it (a restore brings it back) */
    assert_true(has_terminal(db, model, "terminals/00aa.ply"));
    assert_true(has_terminal(db, model, "terminals/00bb.ply"));
    assert_true(has_terminal(db, model, "terminals/00cc.ply"));
    assert_int_equal(release(db, model), 0);
    /* without version 2's state nothing names 00aa any more */
    char sql[128];
    snprintf(sql, sizeof sql, "DELETE FROM model_states WHERE model_id = %lld AND version = %lld",
             (long long)model, (long long)v2);
    assert_int_equal(sqlite3_exec(ag_db_handle(db), sql, NULL, NULL, NULL), SQLITE_OK);
    assert_int_equal(release(db, model), 1);
    assert_false(has_terminal(db, model, "terminals/00aa.ply"));
    assert_int_equal(ag_grammars_count_terminals(db, model), 2);
    assert_true(v3 > v2);
    /* the other model is untouched: both of its terminals stay until it is saved itself */
    assert_int_equal(ag_grammars_count_terminals(db, other), 2);
    assert_int_equal(release(db, other), 1);
    assert_true(has_terminal(db, other, "terminals/00cc.ply"));
    close_temp_db(db, path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(clouds_come_back_in_every_chunking),
        cmocka_unit_test(segmentations_follow_the_states),
        cmocka_unit_test(a_segmentation_of_another_cloud_is_refused),
        cmocka_unit_test(a_segmentation_stored_before_kinds_reads_without_them),

        cmocka_unit_test(terminals_go_when_no_version_names_them),
    };
    return cmocka_run_group_tests_name("pointclouds_store", tests, NULL, NULL);
}
