/* The model_states table (migrations 0004, 0011): a kept version state comes back exactly
 * (mesh file, stats, grammar, tree), versions separated from a kept one only by rename/note ops
 * share its state while a geometry op in between makes it unavailable, restoring points the
 * model at the kept file, replaced mesh files stay while a state names them, and deleting the
 * model takes every file with it. A tree kept once (in its version's state row only, the
 * grammar row naming it) reads back through the current grammar, through a later keep of the
 * same state and through a restore; a database with states from before migration 0011 keeps
 * every row and the file clean-up through it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store/db.h"
#include "store/grammars.h"
#include "store/models.h"
#include "store/ops.h"
#include "store/states.h"
#include "store_fixture.h"

typedef struct {
    char *path;
    ag_db *db;
    int64_t model;
} fixture;

static int64_t mesh_blob(ag_db *db, int64_t model)
{
    ag_model_row row;
    assert_int_equal(ag_models_get(db, model, &row, NULL), AG_OK);
    int64_t b = row.mesh_blob;
    ag_models_row_clear(&row);
    return b;
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->path = temp_db();
    ag_error err;
    assert_int_equal(ag_db_open(f->path, NULL, &f->db, &err), AG_OK);
    static const char mesh[] = "mesh of version 1";
    ag_model_new m = {.name = "m", .mesh = mesh, .mesh_len = sizeof mesh, .stats_json = "{\"v\":1}"};
    f->model = insert_model(f->db, &m);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    ag_db_close(f->db);
    remove_db(f->path);
    free(f);
    return 0;
}

/* One op: raises the version; a geometry op also gets a new mesh file and a grammar, its tree
 * in the grammar row and copied into the kept state, or (tree_once) written once, in the kept
 * state only, as an edit stores it. */
static int64_t op_ex(fixture *f, const char *kind, int geometry, const char *grammar,
                     const char *tree_once)
{
    ag_error err;
    int64_t v = 0;
    ag_model_row row;
    assert_int_equal(ag_models_get(f->db, f->model, &row, NULL), AG_OK);
    int64_t base = row.version;
    ag_models_row_clear(&row);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(f->db, f->model, base, &v, &err), AG_OK);
    if (geometry) {
        assert_int_equal(ag_states_keep(f->db, f->model, v - 1, &err), AG_OK);
        char mesh[64], stats[64];
        snprintf(mesh, sizeof mesh, "mesh of version %lld", (long long)v);
        snprintf(stats, sizeof stats, "{\"v\":%lld}", (long long)v);
        int64_t blob = 0;
        assert_int_equal(ag_models_set_mesh(f->db, f->model, mesh, strlen(mesh), stats, &blob,
                                              &err),
                         AG_OK);
        ag_grammar_new g = {.model = f->model, .version = v, .mesh_blob = blob, .text = grammar,
                            .text_len = strlen(grammar),
                            .tree_json = tree_once ? "" : "{\"nodes\":[]}",
                            .tree_numbering = tree_once ? 2 : 0};
        assert_int_equal(ag_grammars_put(f->db, &g, &err), AG_OK);
        if (tree_once)
            assert_int_equal(ag_states_keep_with_tree(f->db, f->model, v, tree_once, &err), AG_OK);
        else
            assert_int_equal(ag_states_keep(f->db, f->model, v, &err), AG_OK);
    }
    char cid[32];
    snprintf(cid, sizeof cid, "c%lld", (long long)v);
    ag_op_row o = {.model = f->model, .version = v, .author = "ana", .cid = cid, .kind = kind,
                   .body_json = "{}"};
    assert_int_equal(ag_ops_insert(f->db, &o, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    return v;
}

static int64_t op(fixture *f, const char *kind, int geometry, const char *grammar)
{
    return op_ex(f, kind, geometry, grammar, NULL);
}

static void kept_states_come_back_and_gaps_are_named(void **state)
{
    fixture *f = *state;
    ag_error err;
    int64_t v2 = op(f, "resize", 1, "grammar two");   /* keeps 1 and 2 */
    int64_t v3 = op(f, "rename", 0, NULL);            /* shares 2's state */
    int64_t v4 = op(f, "grammar", 1, "grammar four"); /* keeps 3 (= 2's mesh) and 4 */
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_states"), 4);

    ag_state_row r;
    assert_int_equal(ag_states_get(f->db, f->model, 1, &r, &err), AG_OK);
    assert_int_equal(r.version, 1);
    assert_null(r.grammar); /* version 1 had no grammar */
    assert_string_equal(r.stats_json, "{\"v\":1}");
    ag_states_row_clear(&r);

    assert_int_equal(ag_states_get(f->db, f->model, v3, &r, &err), AG_OK);
    assert_string_equal(r.grammar, "grammar two");
    assert_string_equal(r.tree_json, "{\"nodes\":[]}");
    int64_t blob2 = r.mesh_blob;
    ag_states_row_clear(&r);

    /* version 5 is a rename after 4: it shares 4's state; 6 does not exist yet */
    int64_t v5 = op(f, "note", 0, NULL);
    assert_int_equal(ag_states_get(f->db, f->model, v5, &r, &err), AG_OK);
    assert_int_equal(r.version, v4);
    ag_states_row_clear(&r);
    assert_int_equal(ag_states_get(f->db, f->model, v5 + 1, &r, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "no version"));

    /* a geometry op that kept nothing: the versions after it are not available */
    int64_t v6 = op(f, "proceduralize", 0, NULL);
    assert_int_equal(ag_states_get(f->db, f->model, v6, &r, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "proceduralize op of version 6"));

    /* restoring version 2: the model points at 2's file again, with its grammar current */
    int64_t v = 0;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(f->db, f->model, v6, &v, &err), AG_OK);
    assert_int_equal(ag_states_get(f->db, f->model, v2, &r, &err), AG_OK);
    assert_int_equal(ag_states_restore(f->db, f->model, v, &r, &err), AG_OK);
    ag_states_row_clear(&r);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(mesh_blob(f->db, f->model), blob2);
    ag_grammar_row g;
    assert_int_equal(ag_grammars_current(f->db, f->model, 1, &g, &err), AG_OK);
    assert_string_equal(g.text, "grammar two");
    ag_grammars_row_clear(&g);
    void *data;
    size_t len;
    assert_int_equal(ag_blobs_get(f->db, blob2, &data, &len, &err), AG_OK);
    assert_memory_equal(data, "mesh of version 2", len);
    free(data);

    /* every mesh file a state names is still there; the model's deletion takes them all */
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_states s WHERE NOT EXISTS "
                                  "(SELECT 1 FROM blobs b WHERE b.id = s.mesh_blob)"),
                     0);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_delete(f->db, f->model, v, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_states"), 0);
    assert_int_equal(count(f->db, "SELECT count(*) FROM blobs"), 0);
}

static void restoring_a_version_without_grammar_ends_the_grammar(void **state)
{
    fixture *f = *state;
    ag_error err;
    int64_t v2 = op(f, "resize", 1, "grammar two");
    int64_t v = 0;
    ag_state_row r;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(f->db, f->model, v2, &v, &err), AG_OK);
    assert_int_equal(ag_states_get(f->db, f->model, 1, &r, &err), AG_OK);
    assert_int_equal(ag_states_restore(f->db, f->model, v, &r, &err), AG_OK);
    ag_states_row_clear(&r);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    ag_grammar_row g;
    assert_int_equal(ag_grammars_current(f->db, f->model, 0, &g, &err), AG_ERR_NOT_FOUND);
    /* keeping the same version twice keeps the first */
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_states_keep(f->db, f->model, v2, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(ag_states_get(f->db, f->model, v2, &r, &err), AG_OK);
    assert_string_equal(r.grammar, "grammar two");
    ag_states_row_clear(&r);
}

/* A tree larger than many pages, different for each version. */
static char *big_tree(int64_t v)
{
    size_t n = 300000;
    char *t = malloc(n + 64);
    int at = snprintf(t, 64, "{\"version\":%lld,\"pad\":\"", (long long)v);
    for (size_t i = 0; i < n; i++)
        t[at + i] = (char)('a' + (i * 7 + (size_t)v) % 26);
    strcpy(t + at + n, "\"}");
    return t;
}

/* A geometry op as an edit stores it: its tree only in its version's state row. */
static int64_t edit_once(fixture *f, const char *tree)
{
    return op_ex(f, "resize", 1, "g", tree);
}

static void a_tree_kept_once_reads_back_everywhere(void **state)
{
    fixture *f = *state;
    ag_error err;
    char *t2 = big_tree(2), *t3 = big_tree(3);
    int64_t v2 = edit_once(f, t2);
    /* written once: the grammar row names the state row */
    assert_int_equal(count(f->db, "SELECT count(*) FROM grammars WHERE tree = ''"), 1);
    ag_grammar_row g;
    assert_int_equal(ag_grammars_current(f->db, f->model, 1, &g, &err), AG_OK);
    assert_string_equal(g.tree_json, t2);
    assert_int_equal(g.tree_numbering, 2);
    ag_grammars_row_clear(&g);
    /* without the tree asked for, none is read */
    assert_int_equal(ag_grammars_current(f->db, f->model, 0, &g, &err), AG_OK);
    assert_null(g.tree_json);
    ag_grammars_row_clear(&g);

    /* a rename, then an edit: the edit keeps the rename's version (the same state) by copying
     * the tree from the state row the grammar names */
    int64_t v3 = op(f, "rename", 0, NULL);
    int64_t v4 = edit_once(f, t3);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_states"), 4); /* 1, 2, 3, 4 */
    ag_state_row r;
    assert_int_equal(ag_states_get(f->db, f->model, v3, &r, &err), AG_OK);
    assert_int_equal(r.version, v3);
    assert_string_equal(r.tree_json, t2);
    assert_string_equal(r.grammar, "g");
    assert_int_equal(r.tree_numbering, 2);
    ag_states_row_clear(&r);
    assert_int_equal(ag_states_get(f->db, f->model, v4, &r, &err), AG_OK);
    assert_string_equal(r.tree_json, t3);
    ag_states_row_clear(&r);

    /* restoring version 2 makes its tree current again */
    int64_t v = 0;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_bump_version(f->db, f->model, v4, &v, &err), AG_OK);
    assert_int_equal(ag_states_get(f->db, f->model, v2, &r, &err), AG_OK);
    assert_int_equal(ag_states_restore(f->db, f->model, v, &r, &err), AG_OK);
    ag_states_row_clear(&r);
    assert_int_equal(ag_states_keep(f->db, f->model, v, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(ag_grammars_current(f->db, f->model, 1, &g, &err), AG_OK);
    assert_string_equal(g.tree_json, t2);
    ag_grammars_row_clear(&g);
    assert_int_equal(ag_states_get(f->db, f->model, v, &r, &err), AG_OK);
    assert_string_equal(r.tree_json, t2);
    ag_states_row_clear(&r);

    /* a state kept with its tree needs the version's grammar: refused, nothing written */
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_states_keep_with_tree(f->db, f->model, v + 7, t3, &err), AG_ERR_INTERNAL);
    ag_db_rollback(f->db);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_states WHERE version > 5"), 0);
    free(t2);
    free(t3);
}

/* States written before migration 0011 (a WITHOUT ROWID table) come through it whole, and
 * deleting them still takes their mesh files. */
static void states_survive_migration_11(void **state)
{
    (void)state;
    char *path = old_database(10);
    sqlite3 *raw;
    assert_int_equal(sqlite3_open(path, &raw), SQLITE_OK);
    assert_int_equal(sqlite3_exec(raw,
                                  "INSERT INTO blobs (id, media_type, bytes, data) VALUES "
                                  "(2, 'x', 3, 'def');"
                                  "INSERT INTO model_states VALUES (5, 2, 2, '{\"v\":2}', "
                                  "'grammar two', '{\"t\":2}', '{}', 2);"
                                  "INSERT INTO model_states VALUES (5, 3, 1, '{}', NULL, NULL, "
                                  "NULL, 1);",
                                  NULL, NULL, NULL),
                     SQLITE_OK);
    sqlite3_close(raw);
    ag_db *db = open_old_database(path);
    assert_int_equal(count(db, "SELECT count(*) FROM sqlite_master WHERE name = 'model_states' "
                               "AND sql LIKE '%WITHOUT ROWID%'"),
                     0);
    assert_int_equal(count(db, "SELECT count(*) FROM sqlite_master WHERE name = "
                               "'model_states_copy'"),
                     0);
    ag_error err;
    ag_state_row r;
    assert_int_equal(ag_states_get(db, 5, 2, &r, &err), AG_OK);
    assert_int_equal(r.mesh_blob, 2);
    assert_string_equal(r.grammar, "grammar two");
    assert_string_equal(r.tree_json, "{\"t\":2}");
    assert_int_equal(r.tree_numbering, 2);
    ag_states_row_clear(&r);
    /* the clean-up trigger came through: blob 2 goes with the last row naming it, blob 1
     * (the model's mesh) stays */
    assert_int_equal(sqlite3_exec(ag_db_handle(db), "DELETE FROM model_states", NULL, NULL, NULL),
                     SQLITE_OK);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs WHERE id = 2"), 0);
    assert_int_equal(count(db, "SELECT count(*) FROM blobs WHERE id = 1"), 1);
    ag_db_close(db);
    remove_db(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(kept_states_come_back_and_gaps_are_named, setup, teardown),
        cmocka_unit_test_setup_teardown(restoring_a_version_without_grammar_ends_the_grammar,
                                        setup, teardown),
        cmocka_unit_test_setup_teardown(a_tree_kept_once_reads_back_everywhere, setup, teardown),
        cmocka_unit_test(states_survive_migration_11),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
