/* The grammars and terminals tables: store and read back, what makes a grammar current,
 * deleting a model leaves nothing behind, and migration 0002 on a database at version 1. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store/grammars.h"
#include "store_fixture.h"

static int64_t add_model(ag_db *db, const char *name)
{
    static const char mesh[] = "not really a mesh, the store does not look";
    ag_model_new m = {.name = name, .mesh = mesh, .mesh_len = sizeof mesh,
                      .source = "v 0 0 0\n", .source_len = 8,
                      .source_media_type = "text/plain", .source_format = "obj"};
    return insert_model(db, &m);
}

/* One proceduralization as the job stores it: version + 1, a new mesh, grammar, terminals. */
static int64_t store_grammar(ag_db *db, int64_t model, int64_t base, const char *text)
{
    ag_error err;
    int64_t version = 0, blob = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(db, model, base, &version, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, model, "derived", 7, "{\"triangles\":2}", &blob,
                                          &err),
                     AG_OK);
    ag_grammar_new g = {.model = model, .version = version, .mesh_blob = blob, .text = text,
                        .text_len = strlen(text), .tree_json = "{\"root\":0}",
                        .summary_json = "{\"rules\":1}"};
    assert_int_equal(ag_grammars_put(db, &g, &err), AG_OK);
    assert_int_equal(ag_grammars_clear_terminals(db, model, &err), AG_OK);
    assert_int_equal(ag_grammars_put_terminal(db, model, "terminals/00aa.obj", "v 0 0 0\n", 8,
                                              &err),
                     AG_OK);
    assert_int_equal(ag_grammars_put_terminal(db, model, "terminals/00bb.obj", "v 1 1 1\n", 8,
                                              &err),
                     AG_OK);
    /* the same path again keeps one row */
    assert_int_equal(ag_grammars_put_terminal(db, model, "terminals/00aa.obj", "v 0 0 0\n", 8,
                                              &err),
                     AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return version;
}

static void stores_and_reads_back(void **state)
{
    (void)state;
    char *path = temp_db();
    ag_db *db;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    int64_t id = add_model(db, "facade");
    ag_model_row before;
    assert_int_equal(ag_models_get(db, id, &before, &err), AG_OK);

    ag_grammar_row row;
    assert_int_equal(ag_grammars_current(db, id, 1, &row, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "has not been proceduralized"));
    assert_int_equal(ag_grammars_current(db, id + 100, 1, &row, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "there is no model"));

    const char *text = "archgram-grammar 1\n\naxiom box 0 0 0 1 1 1 {\n}\n";
    int64_t v = store_grammar(db, id, 1, text);
    assert_int_equal(v, 2);
    assert_int_equal(ag_grammars_current(db, id, 1, &row, &err), AG_OK);
    assert_int_equal(row.version, 2);
    assert_int_equal(row.model_version, 2);
    assert_string_equal(row.text, text);
    assert_int_equal(row.text_len, strlen(text));
    assert_string_equal(row.tree_json, "{\"root\":0}");
    assert_string_equal(row.summary_json, "{\"rules\":1}");
    ag_grammars_row_clear(&row);
    assert_int_equal(ag_grammars_current(db, id, 0, &row, &err), AG_OK);
    assert_null(row.tree_json);
    ag_grammars_row_clear(&row);

    /* the model now points at the new mesh; the old mesh file is gone, the source stays */
    ag_model_row after;
    assert_int_equal(ag_models_get(db, id, &after, &err), AG_OK);
    assert_int_not_equal(after.mesh_blob, before.mesh_blob);
    assert_string_equal(after.stats_json, "{\"triangles\":2}");
    assert_int_equal(count(db, "SELECT count(*) FROM blobs"), 2);
    void *data;
    size_t len;
    assert_int_equal(ag_blobs_get(db, after.mesh_blob, &data, &len, &err), AG_OK);
    assert_int_equal(len, 7);
    assert_memory_equal(data, "derived", 7);
    free(data);
    assert_int_equal(ag_blobs_get(db, before.mesh_blob, &data, &len, &err), AG_ERR_NOT_FOUND);

    int yes = 0;
    assert_int_equal(ag_grammars_is_current(db, id, after.mesh_blob, &yes, &err), AG_OK);
    assert_true(yes);
    assert_int_equal(ag_grammars_is_current(db, id, before.mesh_blob, &yes, &err), AG_OK);
    assert_false(yes);

    char *obj;
    assert_int_equal(ag_grammars_get_terminal(db, id, "terminals/00bb.obj", &obj, &len, &err),
                     AG_OK);
    assert_string_equal(obj, "v 1 1 1\n");
    assert_int_equal(len, 8);
    free(obj);
    assert_int_equal(ag_grammars_get_terminal(db, id, "terminals/ffff.obj", &obj, &len, &err),
                     AG_ERR_NOT_FOUND);
    assert_int_equal(ag_grammars_count_terminals(db, id), 2);

    /* an op that leaves the geometry alone keeps the grammar current, at the new version */
    int64_t v3;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(db, id, 2, &v3, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    assert_int_equal(ag_grammars_current(db, id, 0, &row, &err), AG_OK);
    assert_int_equal(row.version, 2);
    assert_int_equal(row.model_version, 3);
    ag_grammars_row_clear(&row);

    /* a second grammar replaces the first: one row per model */
    const char *text2 = "archgram-grammar 1\n\naxiom box 0 0 0 2 2 2 {\n}\n";
    assert_int_equal(store_grammar(db, id, 3, text2), 4);
    assert_int_equal(count(db, "SELECT count(*) FROM grammars"), 1);
    assert_int_equal(ag_grammars_current(db, id, 0, &row, &err), AG_OK);
    assert_string_equal(row.text, text2);
    ag_grammars_row_clear(&row);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs"), 2);

    /* a new mesh without a grammar ends it */
    int64_t blob;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, id, "other", 5, NULL, &blob, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    assert_int_equal(ag_grammars_current(db, id, 0, &row, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_set_mesh(db, id + 100, "other", 5, NULL, &blob, &err),
                     AG_ERR_NOT_FOUND);
    ag_db_rollback(db);

    ag_models_row_clear(&before);
    ag_models_row_clear(&after);
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
    int64_t keep = add_model(db, "kept");
    int64_t id = add_model(db, "gone");
    store_grammar(db, keep, 1, "archgram-grammar 1\n");
    int64_t v = store_grammar(db, id, 1, "archgram-grammar 1\n");
    assert_int_equal(count(db, "SELECT count(*) FROM grammars"), 2);
    assert_int_equal(count(db, "SELECT count(*) FROM terminals"), 4);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs"), 4);

    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_delete(db, id, v, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    char sql[128];
    snprintf(sql, sizeof sql, "SELECT count(*) FROM grammars WHERE model_id = %lld", (long long)id);
    assert_int_equal(count(db, sql), 0);
    snprintf(sql, sizeof sql, "SELECT count(*) FROM terminals WHERE model_id = %lld",
             (long long)id);
    assert_int_equal(count(db, sql), 0);
    /* only the kept model's rows remain: its source, its mesh, its grammar and terminals */
    assert_int_equal(count(db, "SELECT count(*) FROM grammars"), 1);
    assert_int_equal(count(db, "SELECT count(*) FROM terminals"), 2);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs"), 2);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs WHERE id NOT IN "
                               "(SELECT mesh_blob FROM models UNION SELECT source_blob FROM models)"),
                     0);
    assert_int_equal(count(db, "SELECT count(*) FROM pragma_foreign_key_check"), 0);
    ag_db_close(db);
    remove_db(path);
}

static void migration_keeps_an_older_database(void **state)
{
    (void)state;
    assert_true(ag_migrations_count >= 2);
    assert_string_equal(ag_migrations[1].name, "0002_proceduralization");
    /* a database as archgram with only migration 0001 left it, holding a model */
    char *path = old_database(1);
    ag_db *db = open_old_database(path);
    ag_error err;
    ag_grammar_row g;
    assert_int_equal(ag_grammars_current(db, 5, 0, &g, &err), AG_ERR_NOT_FOUND);
    /* the upgraded model takes a grammar like a new one */
    assert_int_equal(store_grammar(db, 5, 4, "archgram-grammar 1\n"), 5);
    assert_int_equal(ag_grammars_current(db, 5, 0, &g, &err), AG_OK);
    assert_int_equal(g.version, 5);
    ag_grammars_row_clear(&g);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs WHERE id = 1"), 0);
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
    return cmocka_run_group_tests_name("grammars_store", tests, NULL, NULL);
}
