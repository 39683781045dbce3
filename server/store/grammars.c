#include "grammars.h"

#include <stdlib.h>
#include <string.h>

#include "models.h"

void ag_grammars_row_clear(ag_grammar_row *row)
{
    if (!row)
        return;
    free(row->text);
    free(row->tree_json);
    free(row->summary_json);
    row->text = row->tree_json = row->summary_json = NULL;
}

/* A malloc'd NUL-terminated copy of a text column ("" for NULL). */
static char *column_dup(sqlite3_stmt *st, int col, size_t *len)
{
    const unsigned char *p = sqlite3_column_text(st, col);
    size_t n = p ? (size_t)sqlite3_column_bytes(st, col) : 0;
    char *s = malloc(n + 1);
    if (!s)
        return NULL;
    if (n)
        memcpy(s, p, n);
    s[n] = '\0';
    if (len)
        *len = n;
    return s;
}

ag_status ag_grammars_put(ag_db *db, const ag_grammar_new *g, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "DELETE FROM grammars WHERE model_id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, g->model);
    if ((s = ag_db_step_done(db, st, "replacing a model's grammar", err)) != AG_OK)
        return s;
    if ((s = ag_db_prepared(db, &st,
                            "INSERT INTO grammars (model_id, version, mesh_blob, text, tree, summary, "
                            "tree_numbering) VALUES (?, ?, ?, ?, ?, ?, ?)",
                            err)) != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, g->model);
    sqlite3_bind_int64(st, 2, g->version);
    sqlite3_bind_int64(st, 3, g->mesh_blob);
    sqlite3_bind_text64(st, 4, g->text, g->text_len, SQLITE_STATIC, SQLITE_UTF8);
    sqlite3_bind_text(st, 5, g->tree_json ? g->tree_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 6, g->summary_json ? g->summary_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 7, g->tree_numbering);
    return ag_db_step_done(db, st, "storing a grammar", err);
}

ag_status ag_grammars_current(ag_db *db, int64_t model, int with_tree, ag_grammar_row *row,
                              ag_error *err)
{
    memset(row, 0, sizeof *row);
    /* The LEFT JOIN tells "no such model" from "no grammar" in one statement. */
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "SELECT m.version, g.version, g.mesh_blob, g.text, g.summary, "
        "CASE WHEN ? THEN coalesce(nullif(g.tree, ''), (SELECT k.tree FROM model_states k "
        "WHERE k.model_id = g.model_id AND k.version = g.version)) END, g.tree_numbering "
        "FROM models m LEFT JOIN grammars g ON g.model_id = m.id AND g.mesh_blob = m.mesh_blob "
        "WHERE m.id = ? ORDER BY g.version DESC LIMIT 1",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int(st, 1, with_tree ? 1 : 0);
    sqlite3_bind_int64(st, 2, model);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    else if (rc != SQLITE_ROW)
        s = ag_db_fail(db, err, "reading a grammar");
    else if (sqlite3_column_type(st, 1) == SQLITE_NULL)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld has not been proceduralized",
                         (long long)model);
    else {
        row->model = model;
        row->model_version = sqlite3_column_int64(st, 0);
        row->version = sqlite3_column_int64(st, 1);
        row->mesh_blob = sqlite3_column_int64(st, 2);
        row->tree_numbering = sqlite3_column_int(st, 6);
        row->text = column_dup(st, 3, &row->text_len);
        row->summary_json = column_dup(st, 4, NULL);
        if (with_tree)
            row->tree_json = column_dup(st, 5, NULL);
        if (!row->text || !row->summary_json || (with_tree && !row->tree_json)) {
            ag_grammars_row_clear(row);
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a grammar");
        }
    }
    sqlite3_reset(st);
    return s;
}

ag_status ag_grammars_set_tree(ag_db *db, int64_t model, int64_t mesh_blob, const char *tree_json,
                               int tree_numbering, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "UPDATE grammars SET tree = ?, tree_numbering = ? "
                                 "WHERE model_id = ? AND mesh_blob = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_text(st, 1, tree_json, -1, SQLITE_STATIC);
    sqlite3_bind_int(st, 2, tree_numbering);
    sqlite3_bind_int64(st, 3, model);
    sqlite3_bind_int64(st, 4, mesh_blob);
    return ag_db_step_done(db, st, "replacing a split tree", err);
}

ag_status ag_grammars_is_current(ag_db *db, int64_t model, int64_t mesh_blob, int *yes,
                                 ag_error *err)
{
    *yes = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "SELECT EXISTS (SELECT 1 FROM grammars WHERE model_id = ? AND mesh_blob = ?)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, mesh_blob);
    if (sqlite3_step(st) == SQLITE_ROW)
        *yes = sqlite3_column_int(st, 0);
    else
        s = ag_db_fail(db, err, "reading a grammar");
    sqlite3_reset(st);
    return s;
}

ag_status ag_grammars_clear_terminals(ag_db *db, int64_t model, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "DELETE FROM terminals WHERE model_id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    return ag_db_step_done(db, st, "removing terminals", err);
}

ag_status ag_grammars_put_terminal(ag_db *db, int64_t model, const char *path, const char *obj,
                                   size_t len, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "INSERT OR IGNORE INTO terminals (model_id, path, obj) VALUES (?, ?, ?)", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_text(st, 2, path, -1, SQLITE_STATIC);
    sqlite3_bind_text64(st, 3, len ? obj : "", len, SQLITE_STATIC, SQLITE_UTF8);
    return ag_db_step_done(db, st, "storing a terminal", err);
}

ag_status ag_grammars_get_terminal(ag_db *db, int64_t model, const char *path, char **obj,
                                   size_t *len, ag_error *err)
{
    *obj = NULL;
    *len = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "SELECT obj FROM terminals WHERE model_id = ? AND path = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_text(st, 2, path, -1, SQLITE_STATIC);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        if (!(*obj = column_dup(st, 0, len)))
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a terminal");
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld has no terminal %s",
                         (long long)model, path);
    } else {
        s = ag_db_fail(db, err, "reading a terminal");
    }
    sqlite3_reset(st);
    return s;
}

size_t ag_grammars_count_terminals(ag_db *db, int64_t model)
{
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT count(*) FROM terminals WHERE model_id = ?", NULL);
    size_t n = 0;
    if (!st)
        return 0;
    sqlite3_bind_int64(st, 1, model);
    if (sqlite3_step(st) == SQLITE_ROW)
        n = (size_t)sqlite3_column_int64(st, 0);
    sqlite3_reset(st);
    return n;
}
