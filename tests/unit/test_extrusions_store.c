/* The extrusions and extrusion_buildings tables: store and read back (also replacing a
 * building and the model's mesh), deleting a model leaves nothing behind, and migration 0003
 * on a database at version 2 keeps what it held. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store/extrusions.h"
#include "store_fixture.h"

static int64_t add_model(ag_db *db, const char *name, const char *kind)
{
    static const char mesh[] = "whole mesh";
    ag_model_new m = {.name = name, .kind = kind, .mesh = mesh, .mesh_len = sizeof mesh};
    return insert_model(db, &m);
}

/* A batch of three buildings as the extrude job stores it; the middle one failed. */
static void store_batch(ag_db *db, int64_t model)
{
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_extrusions_put(db, model, 1, "{\"style\":\"hip\"}", &err), AG_OK);
    const char *ids[] = {"a", "b", "c"};
    for (int i = 0; i < 3; i++) {
        char plan[64];
        snprintf(plan, sizeof plan, "{\"loops\":[%d]}", i);
        ag_extrusion_building b = {.model = model, .building = i, .footprint = (char *)ids[i],
                                   .plan_json = plan, .triangles = i == 1 ? 0 : 10 + i};
        if (i == 1) {
            snprintf(b.status, sizeof b.status, "failed");
            b.reason = "loop 0: edges 0 and 2 cross";
        } else {
            snprintf(b.status, sizeof b.status, "ok");
            b.mesh = ids[i] == ids[0] ? "mesh-a" : "mesh-c";
            b.mesh_len = 6;
        }
        assert_int_equal(ag_extrusions_put_building(db, &b, &err), AG_OK);
    }
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

typedef struct {
    int n;
    char seen[8][64];
    size_t mesh_bytes;
} visit;

static ag_status collect(void *user, ag_extrusion_building *b)
{
    visit *v = user;
    assert_int_equal(b->building, v->n);
    snprintf(v->seen[v->n], sizeof v->seen[v->n], "%s:%s", b->footprint, b->status);
    v->mesh_bytes += b->mesh_len;
    assert_null(b->plan_json); /* not asked for */
    v->n++;
    return AG_OK;
}

static ag_status stop_at_second(void *user, ag_extrusion_building *b)
{
    int *n = user;
    return ++*n == 2 ? AG_ERR_CANCELLED : AG_OK;
}

static void stores_and_reads_back(void **state)
{
    (void)state;
    char *path = temp_db();
    ag_db *db;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    int64_t plain = add_model(db, "plain", NULL);
    int64_t id = add_model(db, "city", "extrusion");

    ag_extrusion_row row;
    assert_int_equal(ag_extrusions_get(db, plain, &row, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "not an extrusion"));
    assert_int_equal(ag_extrusions_get(db, id + 100, &row, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "there is no model"));

    store_batch(db, id);
    assert_int_equal(ag_extrusions_get(db, id, &row, &err), AG_OK);
    assert_int_equal(row.batch, 1);
    assert_int_equal(row.buildings, 3);
    assert_string_equal(row.meta_json, "{\"style\":\"hip\"}");
    ag_extrusions_row_clear(&row);

    ag_extrusion_building b;
    assert_int_equal(ag_extrusions_get_building(db, id, 1, AG_EXTRUSIONS_PLAN | AG_EXTRUSIONS_MESH,
                                                &b, &err),
                     AG_OK);
    assert_string_equal(b.footprint, "b");
    assert_string_equal(b.status, "failed");
    assert_string_equal(b.reason, "loop 0: edges 0 and 2 cross");
    assert_string_equal(b.plan_json, "{\"loops\":[1]}");
    assert_null(b.mesh);
    ag_extrusions_building_clear(&b);
    assert_int_equal(ag_extrusions_get_building(db, id, 2, AG_EXTRUSIONS_MESH, &b, &err), AG_OK);
    assert_null(b.plan_json);
    assert_int_equal(b.mesh_len, 6);
    assert_memory_equal(b.mesh, "mesh-c", 6);
    assert_int_equal(b.triangles, 12);
    assert_null(b.reason);
    ag_extrusions_building_clear(&b);
    assert_int_equal(ag_extrusions_get_building(db, id, 3, 0, &b, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_extrusions_get_building(db, plain, 0, 0, &b, &err), AG_ERR_NOT_FOUND);

    visit v = {0};
    assert_int_equal(ag_extrusions_each_building(db, id, AG_EXTRUSIONS_MESH, collect, &v, &err),
                     AG_OK);
    assert_int_equal(v.n, 3);
    assert_string_equal(v.seen[0], "a:ok");
    assert_string_equal(v.seen[1], "b:failed");
    assert_string_equal(v.seen[2], "c:ok");
    assert_int_equal(v.mesh_bytes, 12);
    int n = 0;
    assert_int_equal(ag_extrusions_each_building(db, id, 0, stop_at_second, &n, &err),
                     AG_ERR_CANCELLED);
    assert_int_equal(n, 2);

    /* an edit replaces one building in place and the model's mesh; the old mesh file goes */
    ag_model_row before, after;
    assert_int_equal(ag_models_get(db, id, &before, &err), AG_OK);
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    ag_extrusion_building fix = {.model = id, .building = 1, .footprint = "b",
                                 .plan_json = "{\"loops\":[7]}", .mesh = "mesh-b2",
                                 .mesh_len = 7, .triangles = 4};
    snprintf(fix.status, sizeof fix.status, "ok");
    assert_int_equal(ag_extrusions_put_building(db, &fix, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, id, "assembled", 9, "{\"triangles\":26}", NULL, &err),
                     AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    assert_int_equal(count(db, "SELECT count(*) FROM extrusion_buildings"), 3);
    assert_int_equal(ag_extrusions_get_building(db, id, 1, AG_EXTRUSIONS_PLAN | AG_EXTRUSIONS_MESH,
                                                &b, &err),
                     AG_OK);
    assert_string_equal(b.status, "ok");
    assert_null(b.reason);
    assert_string_equal(b.plan_json, "{\"loops\":[7]}");
    assert_memory_equal(b.mesh, "mesh-b2", 7);
    ag_extrusions_building_clear(&b);
    assert_int_equal(ag_models_get(db, id, &after, &err), AG_OK);
    assert_int_not_equal(after.mesh_blob, before.mesh_blob);
    assert_string_equal(after.stats_json, "{\"triangles\":26}");
    void *data;
    size_t len;
    assert_int_equal(ag_blobs_get(db, after.mesh_blob, &data, &len, &err), AG_OK);
    assert_int_equal(len, 9);
    assert_memory_equal(data, "assembled", 9);
    free(data);
    assert_int_equal(ag_blobs_get(db, before.mesh_blob, &data, &len, &err), AG_ERR_NOT_FOUND);
    ag_models_row_clear(&before);
    ag_models_row_clear(&after);

    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, id + 100, "x", 1, NULL, NULL, &err), AG_ERR_NOT_FOUND);
    ag_db_rollback(db);
    /* a building must belong to an extrusion */
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    ag_extrusion_building stray = {.model = plain, .building = 0, .footprint = "x",
                                   .plan_json = "{}"};
    assert_int_not_equal(ag_extrusions_put_building(db, &stray, &err), AG_OK);
    ag_db_rollback(db);

    ag_db_close(db);
    remove_db(path);
}

static void deleting_a_model_leaves_nothing(void **state)
{
    (void)state;
    char *path = temp_db();
    ag_db *db;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    int64_t keep = add_model(db, "kept", "extrusion");
    int64_t id = add_model(db, "gone", "extrusion");
    store_batch(db, keep);
    store_batch(db, id);
    assert_int_equal(count(db, "SELECT count(*) FROM extrusions"), 2);
    assert_int_equal(count(db, "SELECT count(*) FROM extrusion_buildings"), 6);

    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_delete(db, id, 1, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    char sql[128];
    snprintf(sql, sizeof sql, "SELECT count(*) FROM extrusion_buildings WHERE model_id = %lld",
             (long long)id);
    assert_int_equal(count(db, sql), 0);
    assert_int_equal(count(db, "SELECT count(*) FROM extrusions"), 1);
    assert_int_equal(count(db, "SELECT count(*) FROM extrusion_buildings"), 3);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs"), 1);
    assert_int_equal(count(db, "SELECT count(*) FROM pragma_foreign_key_check"), 0);
    ag_extrusion_row row;
    assert_int_equal(ag_extrusions_get(db, id, &row, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_extrusions_get(db, keep, &row, &err), AG_OK);
    ag_extrusions_row_clear(&row);
    ag_db_close(db);
    remove_db(path);
}

static void migration_keeps_an_older_database(void **state)
{
    (void)state;
    assert_true(ag_migrations_count >= 3);
    assert_string_equal(ag_migrations[2].name, "0003_extrusions");
    /* a database as archgram with migrations 0001 and 0002 left it, holding a model */
    char *path = old_database(2);
    ag_db *db = open_old_database(path);
    ag_error err;
    ag_extrusion_row e;
    assert_int_equal(ag_extrusions_get(db, 5, &e, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "not an extrusion"));
    /* the upgraded database takes extrusions */
    int64_t id = add_model(db, "new", "extrusion");
    store_batch(db, id);
    assert_int_equal(ag_extrusions_get(db, id, &e, &err), AG_OK);
    assert_int_equal(e.buildings, 3);
    ag_extrusions_row_clear(&e);
    ag_db_close(db);
    remove_db(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stores_and_reads_back),
        cmocka_unit_test(deleting_a_model_leaves_nothing),
        cmocka_unit_test(migration_keeps_an_older_database),
    };
    return cmocka_run_group_tests_name("extrusions_store", tests, NULL, NULL);
}
