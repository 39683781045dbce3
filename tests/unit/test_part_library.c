/* The parts library over both workspaces, without a daemon: the same buildings proceduralized
 * in a folder and in the store give the same part (save use case) and the same composed
 * grammar byte for byte (compose use case, the store's through the compose op); the store's
 * composition is one new version whose tree puts the part's pieces in every slot of the
 * target's rule (checked on the kept mesh, welded independently), undone by the restore the
 * log holds; the library exports what it imported byte for byte, stores a thumbnail that is a
 * picture of the part (decoded, pixels counted), keeps terminals once, and refuses a bad
 * bundle with nothing stored. Variants: the target building turned by a quarter turn and moved
 * to UTM-sized coordinates, windows recessed and proud. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/compose_ops.h"
#include "app/events.h"
#include "app/folder_ws.h"
#include "app/modelops.h"
#include "app/part_library.h"
#include "app/store_ws.h"
#include "app/usecase_compose.h"
#include "app/usecase_import.h"
#include "app/usecase_proceduralize.h"
#include "app/usecase_save_part.h"
#include "io/image_png.h"
#include "io/obj.h"
#include "io/part_bundle.h"
#include "store/grammars.h"
#include "store/models.h"
#include "store/parts.h"
#include "file_fixture.h"
#include "parts_fixture.h"
#include "store_fixture.h"

static pf_options design_a(int depth)
{
    return (pf_options){.cols = 3, .rows = 2, .ww = 1.2, .wh = 1.8, .frame = 0.08, .mullions = 1,
                        .depth = depth};
}

static pf_options design_b(int depth, int turn, double ox, double oy)
{
    return (pf_options){.cols = 4, .rows = 2, .ww = 1.6, .wh = 2.0, .frame = 0.12, .mullions = 2,
                        .depth = depth, .turn = turn, .ox = ox, .oy = oy};
}

typedef struct {
    char dir[64], db_path[128];
    ag_db *db;
    ag_events *bus;
    ag_store_env env;
} fx;

static int setup(void **state)
{
    fx *f = calloc(1, sizeof *f);
    snprintf(f->dir, sizeof f->dir, "/tmp/archgram-partlib-XXXXXX");
    assert_non_null(mkdtemp(f->dir));
    snprintf(f->db_path, sizeof f->db_path, "%s/t.db", f->dir);
    ag_error err;
    assert_int_equal(ag_db_open(f->db_path, NULL, &f->db, &err), AG_OK);
    f->bus = ag_events_create();
    f->env = (ag_store_env){.db = f->db, .seq = ag_sequencer_create(f->bus)};
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fx *f = *state;
    ag_sequencer_free(f->env.seq);
    ag_events_free(f->bus);
    ag_db_close(f->db);
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", f->dir);
    assert_int_equal(system(cmd), 0);
    free(f);
    return 0;
}

/* A building as an OBJ file, proceduralized into a folder and into the store (model `name`);
 * returns the store's model id (its version is 2). */
static int64_t both(fx *f, const pf_options *o, const char *name, ag_box **slots, size_t *ns)
{
    ag_error err;
    ag_mesh *m = pf_building(o, slots, ns);
    char obj[128], out[128];
    snprintf(obj, sizeof obj, "%s/%s.obj", f->dir, name);
    snprintf(out, sizeof out, "%s/%s", f->dir, name);
    assert_int_equal(ag_obj_write_file(m, AG_UP_Z, obj, &err), AG_OK);
    ag_mesh_free(m);
    ag_folder_ws fw;
    ag_folder_ws_init(&fw, &(ag_folder_ws_options){.mesh_path = obj, .up = AG_UP_Z, .out_dir = out});
    ag_usecase_proceduralize_result pr;
    assert_int_equal(ag_usecase_proceduralize_run(&fw.ws, NULL, &pr, &err), AG_OK);
    ag_workspace_close(&fw.ws);
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = f->env});
    int64_t model = 0;
    ag_mesh_source src = {.path = obj, .up = AG_UP_Z, .what = "the file"};
    assert_int_equal(ag_usecase_import_run(&w.ws, &src, name, &model, &err), AG_OK);
    ag_store_ws_end(&w, AG_OK);
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = f->env, .model = model, .base = 1,
                                                .author = "t", .cid = "proc"});
    assert_int_equal(ag_usecase_proceduralize_run(&w.ws, NULL, &pr, &err), AG_OK);
    ag_store_ws_end(&w, AG_OK);
    return model;
}

/* The store model's edit model at its current version (freed by the caller). */
static ag_edit_model *store_model(fx *f, int64_t model)
{
    ag_edit_state *st;
    ag_error err;
    assert_int_equal(ag_edit_session_acquire(NULL, f->db, model, &st, &err), AG_OK);
    ag_edit_model *em = st->em;
    st->em = NULL;
    ag_edit_session_release(NULL, st);
    return em;
}

/* Visible nodes (components) of em inside box b. */
static size_t pieces_in(const ag_edit_model *em, const ag_box *b, size_t *jambs, double frame)
{
    const ag_splittree *t = em->proc->tree;
    size_t n = 0;
    *jambs = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *x = &t->nodes[i];
        if (x->kind != AG_NODE_COMPONENT || !pf_inside(&x->box, b, 1e-6))
            continue;
        n++;
        /* a jamb: frame wide along the slot's width (x or y, whichever the slot is wider on) */
        int w = b->max[0] - b->min[0] > b->max[1] - b->min[1] ? 0 : 1;
        *jambs += fabs(x->box.max[w] - x->box.min[w] - frame) < 1e-6 &&
                  x->box.max[2] - x->box.min[2] > 1.0;
    }
    return n;
}

static int64_t save_store(fx *f, int64_t model, int32_t node, const char *name)
{
    ag_error err;
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = f->env, .model = model, .base = 2});
    ag_part_meta meta = {.name = name};
    ag_usecase_save_part_result r;
    ag_status s = ag_usecase_save_part_run(
        &w.ws, &(ag_usecase_save_part_params){.nodes = &node, .nnodes = 1, .meta = &meta}, &r,
        &err);
    ag_store_ws_end(&w, s);
    if (s)
        fail_msg("save: %s", err.text);
    assert_int_equal(w.part_version, 1);
    return w.part_id;
}

static void the_store_and_a_folder_save_and_compose_the_same(void **state)
{
    fx *f = *state;
    const int variants[2][2] = {{PF_RECESSED, 0}, {PF_PROUD, 1}};
    for (int v = 0; v < 2; v++) {
        char an[16], bn[16];
        snprintf(an, sizeof an, "a%d", v);
        snprintf(bn, sizeof bn, "b%d", v);
        pf_options oa = design_a(variants[v][0]);
        pf_options ob = design_b(variants[v][0], variants[v][1], v ? 690512.3 : 0, v ? 5402311.7 : 0);
        ag_box *sa, *sb;
        size_t na, nb;
        int64_t ma = both(f, &oa, an, &sa, &na);
        int64_t mb = both(f, &ob, bn, &sb, &nb);
        ag_edit_model *ea = store_model(f, ma), *eb = store_model(f, mb);
        int32_t wa = pf_node_with_box(ea->proc, &sa[1], 1e-6);
        int32_t tb = pf_node_with_box(eb->proc, &sb[2], 1e-6);
        assert_true(wa > 0 && tb > 0);
        ag_error err;

        /* save: the folder writes a bundle, the store its library; the same part */
        char adir[128], bundle[160], bdir[128], out[160];
        snprintf(adir, sizeof adir, "%s/%s", f->dir, an);
        snprintf(bdir, sizeof bdir, "%s/%s", f->dir, bn);
        snprintf(bundle, sizeof bundle, "%s/w%d.agpart", f->dir, v);
        snprintf(out, sizeof out, "%s/%s-composed", f->dir, bn);
        ag_folder_ws fw;
        ag_folder_ws_init(&fw, &(ag_folder_ws_options){.in_dir = adir, .bundle_out = bundle});
        ag_part_meta meta = {.name = "window"};
        ag_usecase_save_part_result fr;
        assert_int_equal(ag_usecase_save_part_run(&fw.ws,
                                                  &(ag_usecase_save_part_params){
                                                      .nodes = &wa, .nnodes = 1, .meta = &meta},
                                                  &fr, &err),
                         AG_OK);
        ag_workspace_close(&fw.ws);
        int64_t part = save_store(f, ma, wa, "window");
        ag_part **fp;
        size_t nfp;
        assert_int_equal(ag_part_bundle_read_file(bundle, &fp, &nfp, &err), AG_OK);
        ag_part *sp;
        assert_int_equal(ag_part_library_load(f->db, part, 0, &sp, &err), AG_OK);
        char *ft, *st;
        size_t fl, sl;
        assert_int_equal(ag_grammar_text_print(fp[0]->grammar, &ft, &fl, &err), AG_OK);
        assert_int_equal(ag_grammar_text_print(sp->grammar, &st, &sl, &err), AG_OK);
        assert_string_equal(ft, st);
        assert_int_equal(fp[0]->nnodes, sp->nnodes);
        assert_string_equal(sp->source, an); /* the model's name, as the folder's name */
        assert_int_equal(sp->source_version, 2);
        assert_int_equal(sp->source_node, wa);
        free(ft);
        free(st);
        ag_part_free(sp);
        ag_part_bundle_free(fp, nfp);

        /* compose with scope rule: the folder and the store write the same grammar */
        ag_folder_ws_init(&fw, &(ag_folder_ws_options){.in_dir = bdir, .out_dir = out});
        ag_part_ref ref = {.path = bundle};
        ag_usecase_compose_result cr;
        ag_compose_op cop = {.target = tb, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_RULE};
        assert_int_equal(
            ag_usecase_compose_run(&fw.ws, &(ag_usecase_compose_params){.part = &ref, .op = cop},
                                   &cr, &err),
            AG_OK);
        ag_workspace_close(&fw.ws);
        assert_int_equal(cr.report.instances, nb);
        json_t *op = json_pack("{s:s,s:I,s:i,s:s,s:s}", "kind", "compose", "part",
                               (json_int_t)part, "target", tb, "mode", "replace", "scope", "rule");
        ag_op_request rq = {.model = mb, .base = 2, .author = "t", .cid = "c1", .op = op};
        int64_t nv;
        int dup;
        if (ag_modelops_apply(&f->env, &rq, &nv, &dup, &err))
            fail_msg("compose op: %s", err.text);
        assert_int_equal(nv, 3);
        char path[200];
        snprintf(path, sizeof path, "%s/grammar.txt", out);
        char *folder_text = read_text_file(path);
        ag_grammar_row g;
        assert_int_equal(ag_grammars_current(f->db, mb, 0, &g, &err), AG_OK);
        assert_string_equal(g.text, folder_text);
        free(folder_text);
        ag_grammars_row_clear(&g);

        /* the kept model: every slot of B holds A's seven pieces, its jambs A's width */
        ag_edit_model *e3 = store_model(f, mb);
        for (size_t i = 0; i < nb; i++) {
            size_t jambs;
            size_t n = pieces_in(e3, &sb[i], &jambs, 0.08);
            if (n != 7 || jambs != 2)
                fail_msg("variant %d slot %zu: %zu pieces, %zu jambs of 0.08 m", v, i, n, jambs);
        }
        ag_edit_model_free(e3);
        json_decref(op);

        /* undo: the version before, grammar byte for byte */
        assert_int_equal(ag_grammars_current(f->db, mb, 0, &g, &err), AG_OK);
        ag_grammars_row_clear(&g);
        json_t *undo = json_pack("{s:s}", "kind", "undo");
        ag_op_request ru = {.model = mb, .base = 3, .author = "t", .cid = "u1", .op = undo};
        assert_int_equal(ag_modelops_apply(&f->env, &ru, &nv, &dup, &err), AG_OK);
        json_decref(undo);
        ag_edit_model *e4 = store_model(f, mb);
        for (size_t i = 0; i < nb; i++) {
            size_t jambs;
            assert_int_equal(pieces_in(e4, &sb[i], &jambs, 0.12), 8); /* B's own windows */
            assert_int_equal(jambs, 2);
        }
        ag_edit_model_free(e4);
        ag_edit_model_free(ea);
        ag_edit_model_free(eb);
        free(sa);
        free(sb);
    }
}

static void the_library_exports_what_it_imported_and_refuses_bad_bundles(void **state)
{
    fx *f = *state;
    ag_error err;
    pf_options oa = design_a(PF_FLUSH);
    ag_box *sa;
    size_t na;
    int64_t ma = both(f, &oa, "a", &sa, &na);
    ag_edit_model *ea = store_model(f, ma);
    int32_t w0 = pf_node_with_box(ea->proc, &sa[0], 1e-6);
    int32_t w1 = pf_node_with_box(ea->proc, &sa[4], 1e-6);
    int64_t p0 = save_store(f, ma, w0, "window");
    int64_t p1 = save_store(f, ma, w1, "another window");
    /* two parts of the same window design share every terminal */
    long long texts = count(f->db, "SELECT count(*) FROM part_terminals");
    assert_int_equal(count(f->db, "SELECT count(DISTINCT sha256) FROM part_version_terminals"),
                     texts);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_version_terminals"), 2 * texts);

    /* the thumbnail is a picture of the window: transparent corners, the part in the middle */
    void *png;
    size_t len;
    assert_int_equal(ag_parts_thumbnail(f->db, p0, 1, &png, &len, &err), AG_OK);
    ag_raster_image im;
    assert_int_equal(ag_image_png_decode(png, len, &im, &err), AG_OK);
    assert_int_equal(im.width, 128);
    assert_int_equal(im.rgba[3], 0);
    assert_int_equal(im.rgba[4 * (64 * 128 + 64) + 3], 255);
    free(png);
    ag_raster_image_clear(&im);

    /* exported, imported into a second library, exported again: the same bytes */
    int64_t ids[2] = {p0, p1};
    char *text;
    size_t tl;
    assert_int_equal(ag_part_library_export(f->db, ids, 2, 0, &text, &tl, &err), AG_OK);
    char db2[160];
    snprintf(db2, sizeof db2, "%s/second.db", f->dir);
    ag_db *other;
    assert_int_equal(ag_db_open(db2, NULL, &other, &err), AG_OK);
    int64_t *got;
    size_t n;
    assert_int_equal(ag_part_library_import(other, text, tl, &got, &n, &err), AG_OK);
    assert_int_equal(n, 2);
    char *again;
    size_t al;
    assert_int_equal(ag_part_library_export(other, got, 2, 0, &again, &al, &err), AG_OK);
    assert_int_equal(al, tl);
    assert_memory_equal(again, text, tl);
    free(again);
    free(got);
    /* the whole library too */
    assert_int_equal(ag_part_library_export(other, NULL, 0, 0, &again, &al, &err), AG_OK);
    assert_memory_equal(again, text, tl);
    free(again);

    /* a bad bundle: nothing stored, the element named */
    json_t *doc = json_loads(text, 0, NULL);
    json_object_set_new(json_array_get(json_object_get(doc, "parts"), 1), "root",
                        json_string("9 lives"));
    char *bad = json_dumps(doc, JSON_COMPACT);
    long long before = count(other, "SELECT count(*) FROM parts");
    long long terms = count(other, "SELECT count(*) FROM part_terminals");
    assert_int_equal(ag_part_library_import(other, bad, strlen(bad), &got, &n, &err),
                     AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "parts[1].root"));
    assert_int_equal(count(other, "SELECT count(*) FROM parts"), before);
    assert_int_equal(count(other, "SELECT count(*) FROM part_terminals"), terms);
    assert_int_equal(count(other, "SELECT count(*) FROM parts_search"), before);
    free(bad);
    json_decref(doc);
    ag_db_close(other);
    free(text);

    /* a part read twice (the second from the library's cache of parts read back) is the same
     * part: the same bundle bytes; the two parts stay apart */
    ag_part *r1 = NULL, *r2 = NULL, *r3 = NULL;
    assert_int_equal(ag_part_library_load(f->db, p0, 1, &r1, &err), AG_OK);
    assert_int_equal(ag_part_library_load(f->db, p0, 0, &r2, &err), AG_OK);
    assert_int_equal(ag_part_library_load(f->db, p1, 1, &r3, &err), AG_OK);
    char *b1, *b2, *b3;
    size_t l1, l2, l3;
    assert_int_equal(ag_part_bundle_write((const ag_part *const[]){r1}, 1, &b1, &l1, &err), AG_OK);
    assert_int_equal(ag_part_bundle_write((const ag_part *const[]){r2}, 1, &b2, &l2, &err), AG_OK);
    assert_int_equal(ag_part_bundle_write((const ag_part *const[]){r3}, 1, &b3, &l3, &err), AG_OK);
    assert_int_equal(l1, l2);
    assert_memory_equal(b1, b2, l1);
    assert_string_equal(r3->name, "another window");
    assert_string_equal(r2->name, "window");
    assert_true(r1 != r2 && r1->grammar != r2->grammar); /* each caller its own copy */
    free(b1);
    free(b2);
    free(b3);
    ag_part_free(r1);
    ag_part_free(r2);
    ag_part_free(r3);

    /* deleting a part keeps the terminals the other uses; deleting both frees them */
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_delete(f->db, p0, 1, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    /* a deleted part does not come back from the cache */
    assert_int_equal(ag_part_library_load(f->db, p0, 1, &r1, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_terminals"), texts);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_delete(f->db, p1, 1, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_terminals"), 0);
    ag_edit_model_free(ea);
    free(sa);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(the_store_and_a_folder_save_and_compose_the_same, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(the_library_exports_what_it_imported_and_refuses_bad_bundles,
                                        setup, teardown),
    };
    return cmocka_run_group_tests_name("part_library", tests, NULL, NULL);
}
