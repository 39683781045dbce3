/* One pipeline over two workspaces (app/workspace.h): the same mesh file imported into the
 * store and proceduralized there, and proceduralized into a folder as `archgram` does, gives
 * the same grammar text byte for byte and the same tree; the same edit then gives the same
 * grammar again in both. The use cases run on a store environment of their own, no daemon.
 * What a workspace cannot do is refused as unsupported; problems name the file (a folder) or
 * the model (the store). */
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

#include "app/edit_ops.h"
#include "app/folder_ws.h"
#include "app/model_tree.h"
#include "app/store_ws.h"
#include "app/usecase_edit.h"
#include "app/usecase_import.h"
#include "app/usecase_proceduralize.h"
#include "core/gen_facade.h"
#include "io/obj.h"
#include "store/grammars.h"
#include "store/states.h"
#include "file_fixture.h"

static char dir[64];

static void the_store_and_a_folder_run_the_same_pipeline(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/archgram-ws-XXXXXX");
    assert_non_null(mkdtemp(dir));
    char obj[128], db_path[128], p1[128], p2[128], opfile[128];
    snprintf(obj, sizeof obj, "%s/facade.obj", dir);
    snprintf(db_path, sizeof db_path, "%s/t.db", dir);
    snprintf(p1, sizeof p1, "%s/p", dir);
    snprintf(p2, sizeof p2, "%s/wide", dir);
    snprintf(opfile, sizeof opfile, "%s/op.json", dir);
    ag_error err;
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 5, .rows = 3, .annex = 1}, &m,
                                   &err),
                     AG_OK);
    assert_int_equal(ag_obj_write_file(m, AG_UP_Z, obj, &err), AG_OK); /* exact: %.17g */
    ag_mesh_free(m);

    /* the folder, as `archgram proceduralize facade.obj --out p --up z` */
    ag_folder_ws f;
    ag_folder_ws_init(&f, &(ag_folder_ws_options){.mesh_path = obj, .up = AG_UP_Z, .out_dir = p1});
    ag_usecase_proceduralize_result fr;
    assert_int_equal(ag_usecase_proceduralize_run(&f.ws, NULL, &fr, &err), AG_OK);
    ag_workspace_close(&f.ws);
    assert_int_equal(fr.fidelity.unmatched, 0);

    /* the store: imported from the same file, then proceduralized at version 1 */
    ag_db *db = NULL;
    assert_int_equal(ag_db_open(db_path, NULL, &db, &err), AG_OK);
    ag_events *bus = ag_events_create();
    ag_store_env env = {.db = db, .seq = ag_sequencer_create(bus)};
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env});
    int64_t model = 0;
    ag_mesh_source src = {.path = obj, .up = AG_UP_Z, .what = "the uploaded file"};
    assert_int_equal(ag_usecase_import_run(&w.ws, &src, "facade", &model, &err), AG_OK);
    ag_store_ws_end(&w, AG_OK);
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .model = model, .base = 1,
                                                .author = "t", .cid = "p"});
    ag_usecase_proceduralize_result sr;
    assert_int_equal(ag_usecase_proceduralize_run(&w.ws, NULL, &sr, &err), AG_OK);
    ag_store_ws_end(&w, AG_OK);
    assert_int_equal(w.version, 2);

    /* the same grammar, byte for byte, and the same tree */
    char path[256];
    snprintf(path, sizeof path, "%s/grammar.txt", p1);
    char *folder_text = read_text_file(path);
    ag_grammar_row g;
    assert_int_equal(ag_grammars_current(db, model, 1, &g, &err), AG_OK);
    assert_string_equal(g.text, folder_text);
    snprintf(path, sizeof path, "%s/tree.json", p1);
    json_t *ft = json_load_file(path, 0, NULL), *st = json_loads(g.tree_json, 0, NULL);
    assert_non_null(ft);
    assert_non_null(st);
    size_t i;
    json_t *fn;
    size_t live = 0;
    json_array_foreach(json_object_get(ft, "nodes"), i, fn)
    {
        json_int_t id = json_integer_value(json_object_get(fn, "id"));
        json_t *sn = json_array_get(json_object_get(st, "nodes"), (size_t)id);
        assert_non_null(sn);
        assert_true(json_equal(json_object_get(fn, "kind"), json_object_get(sn, "kind")));
        assert_true(json_equal(json_object_get(fn, "box"), json_object_get(sn, "box")));
        assert_true(json_equal(json_object_get(fn, "children"), json_object_get(sn, "children")));
        if (json_object_get(fn, "label"))
            assert_true(json_equal(json_object_get(fn, "label"), json_object_get(sn, "label")));
        live++;
    }
    assert_true(live > 10);
    /* the proceduralized version is kept as a state when it is written (its tree once, in
     * the state), so that the first edit's commit copies nothing of it */
    ag_state_row kept;
    assert_int_equal(ag_states_get(db, model, 2, &kept, &err), AG_OK);
    assert_non_null(kept.tree_json);
    assert_string_equal(kept.tree_json, g.tree_json);
    assert_string_equal(kept.grammar, g.text);
    ag_states_row_clear(&kept);
    ag_grammars_row_clear(&g);
    free(folder_text);

    /* the same edit in both: the same grammar again */
    FILE *o = fopen(opfile, "w");
    fputs("{\"kind\":\"resize\",\"node\":\"root\",\"scale\":[1.4,1,1]}", o);
    fclose(o);
    ag_edit_op op;
    ag_edit_op_origin from;
    assert_int_equal(ag_edit_op_json_read_file_ex(opfile, &op, &from, &err), AG_OK);
    ag_folder_ws_init(&f, &(ag_folder_ws_options){.in_dir = p1, .op_path = opfile, .out_dir = p2});
    ag_usecase_edit_result er;
    assert_int_equal(ag_usecase_edit_run(&f.ws, &(ag_usecase_edit_params){&op, &from}, &er, &err),
                     AG_OK);
    ag_workspace_close(&f.ws);
    json_t *jop = json_loads("{\"kind\":\"resize\",\"node\":\"root\",\"scale\":[1.4,1,1]}", 0, NULL);
    ag_op_request rq = {.model = model, .base = 2, .author = "t", .cid = "e1", .op = jop};
    int64_t v;
    int dup;
    assert_int_equal(ag_edit_ops_run_edit(&env, &rq, &v, &dup, &err), AG_OK);
    assert_int_equal(v, 3);
    snprintf(path, sizeof path, "%s/grammar.txt", p2);
    folder_text = read_text_file(path);
    assert_int_equal(ag_grammars_current(db, model, 0, &g, &err), AG_OK);
    assert_string_equal(g.text, folder_text);
    ag_grammars_row_clear(&g);
    free(folder_text);
    /* a retry of the same op is answered with its version, not applied again */
    assert_int_equal(ag_edit_ops_run_edit(&env, &rq, &v, &dup, &err), AG_OK);
    assert_int_equal(v, 3);
    assert_true(dup);
    ag_edit_report_clear(&er.report);
    ag_edit_op_clear(&op);
    ag_edit_op_origin_clear(&from);
    json_decref(jop);
    json_decref(ft);
    json_decref(st);

    /* what a workspace cannot do, and problems naming what they are about */
    int64_t none;
    ag_folder_ws_init(&f, &(ag_folder_ws_options){.out_dir = p1});
    assert_int_equal(ag_workspace_add_model(&f.ws, "x", NULL, NULL, 0, NULL, NULL, &none, &err),
                     AG_ERR_UNSUPPORTED);
    ag_folder_ws_init(&f, &(ag_folder_ws_options){.in_dir = "/nonexistent", .out_dir = p2});
    assert_int_not_equal(ag_usecase_edit_run(&f.ws, &(ag_usecase_edit_params){&op, NULL}, &er, &err),
                         AG_OK);
    assert_true(f.blamed);
    assert_string_equal(f.blame, "/nonexistent/grammar.txt");
    ag_workspace_close(&f.ws);
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .model = 999, .base = 1,
                                                .author = "t", .cid = "x"});
    ag_usecase_proceduralize_result nr;
    assert_int_equal(ag_usecase_proceduralize_run(&w.ws, NULL, &nr, &err), AG_ERR_NOT_FOUND);
    ag_store_ws_end(&w, AG_ERR_NOT_FOUND);
    /* a stale base fails the proceduralization and stores nothing */
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .model = model, .base = 2,
                                                .author = "t", .cid = "y"});
    assert_int_equal(ag_usecase_proceduralize_run(&w.ws, NULL, &nr, &err), AG_ERR_STALE);
    ag_store_ws_end(&w, AG_ERR_STALE);

    ag_sequencer_free(env.seq);
    ag_events_free(bus);
    ag_db_close(db);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_store_and_a_folder_run_the_same_pipeline),
    };
    return cmocka_run_group_tests_name("workspace", tests, NULL, NULL);
}
