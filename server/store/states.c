#include "states.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grammars.h"
#include "pointclouds.h"

void ag_states_row_clear(ag_state_row *row)
{
    if (!row)
        return;
    free(row->stats_json);
    free(row->grammar);
    free(row->tree_json);
    free(row->summary_json);
    memset(row, 0, sizeof *row);
}

ag_status ag_states_keep(ag_db *db, int64_t model, int64_t version, ag_error *err)
{
    sqlite3_stmt *st;
    /* kept already (an edit keeps its version): asked by key alone, so that the large row
     * the statement below would copy is not read */
    ag_status s = ag_db_prepared(
        db, &st, "SELECT EXISTS (SELECT 1 FROM model_states WHERE model_id = ? AND version = ?)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, version);
    int rc = sqlite3_step(st), kept = rc == SQLITE_ROW && sqlite3_column_int(st, 0);
    sqlite3_reset(st);
    if (rc != SQLITE_ROW)
        return ag_db_fail(db, err, "reading a model version's state");
    if (kept)
        return ag_pointclouds_states_keep(db, model, version, err);
    /* grammars keeps one row per model; it describes the model only while the mesh is its */
    s = ag_db_prepared(
        db, &st,
        "INSERT OR IGNORE INTO model_states "
        "(model_id, version, mesh_blob, stats, grammar, tree, summary, tree_numbering) "
        "SELECT m.id, ?, m.mesh_blob, m.stats, g.text, coalesce(nullif(g.tree, ''), "
        "(SELECT s.tree FROM model_states s WHERE s.model_id = m.id AND s.version = g.version)), "
        "g.summary, coalesce(g.tree_numbering, 1) FROM models m "
        "LEFT JOIN grammars g ON g.model_id = m.id AND g.mesh_blob = m.mesh_blob "
        "WHERE m.id = ? AND NOT EXISTS (SELECT 1 FROM model_states k " /* kept: not read again */
        "WHERE k.model_id = m.id AND k.version = ?1)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, version);
    sqlite3_bind_int64(st, 2, model);
    s = ag_db_step_done(db, st, "keeping a model version's state", err);
    /* a point cloud's segmentation is part of its state */
    return s == AG_OK ? ag_pointclouds_states_keep(db, model, version, err) : s;
}

ag_status ag_states_keep_with_tree(ag_db *db, int64_t model, int64_t version,
                                   const char *tree_json, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "INSERT INTO model_states "
        "(model_id, version, mesh_blob, stats, grammar, tree, summary, tree_numbering) "
        "SELECT m.id, ?, m.mesh_blob, m.stats, g.text, ?, g.summary, g.tree_numbering "
        "FROM models m JOIN grammars g ON g.model_id = m.id AND g.mesh_blob = m.mesh_blob "
        "AND g.version = ?1 WHERE m.id = ?",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, version);
    sqlite3_bind_text(st, 2, tree_json, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, model);
    if ((s = ag_db_step_done(db, st, "keeping a model version's state", err)) != AG_OK)
        return s;
    if (sqlite3_changes(ag_db_handle(db)) != 1)
        return ag_error_set(err, AG_ERR_INTERNAL, 0,
                            "model %lld has no grammar of version %lld to keep with its tree",
                            (long long)model, (long long)version);
    return ag_pointclouds_states_keep(db, model, version, err);
}

/* The first op after `from` up to `to` that changes geometry: its version, or 0. */
static ag_status geometry_op_between(ag_db *db, int64_t model, int64_t from, int64_t to,
                                     int64_t *found, char kind[32], ag_error *err)
{
    *found = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT version, kind FROM ops WHERE model_id = ? AND version > ? "
                                 "AND version <= ? AND kind NOT IN ('rename', 'note') "
                                 "ORDER BY version LIMIT 1",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, from);
    sqlite3_bind_int64(st, 3, to);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        *found = sqlite3_column_int64(st, 0);
        ag_db_column_copy(st, 1, kind, 32);
    } else if (rc != SQLITE_DONE) {
        s = ag_db_fail(db, err, "reading the op log");
    }
    sqlite3_reset(st);
    return s;
}

ag_status ag_states_get(ag_db *db, int64_t model, int64_t version, ag_state_row *row,
                        ag_error *err)
{
    memset(row, 0, sizeof *row);
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT version, mesh_blob, stats, grammar, tree, summary, "
                                 "(SELECT version FROM models WHERE id = ?), tree_numbering "
                                 "FROM model_states "
                                 "WHERE model_id = ? AND version <= ? ORDER BY version DESC LIMIT 1",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, model);
    sqlite3_bind_int64(st, 3, version);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0,
                         "the state of version %lld of model %lld was not kept (states are kept "
                         "from the first structural edit on)",
                         (long long)version, (long long)model);
    } else if (rc != SQLITE_ROW) {
        s = ag_db_fail(db, err, "reading a model version's state");
    } else if (version > sqlite3_column_int64(st, 6)) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld has no version %lld yet",
                         (long long)model, (long long)version);
    } else {
        int bad = 0;
        row->model = model;
        row->version = sqlite3_column_int64(st, 0);
        row->mesh_blob = sqlite3_column_int64(st, 1);
        row->stats_json = ag_db_column_dup(st, 2, NULL, &bad);
        row->grammar = ag_db_column_dup(st, 3, &row->grammar_len, &bad);
        row->tree_json = ag_db_column_dup(st, 4, NULL, &bad);
        row->summary_json = ag_db_column_dup(st, 5, NULL, &bad);
        row->tree_numbering = sqlite3_column_int(st, 7);
        if (bad || !row->stats_json) {
            ag_states_row_clear(row);
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a state");
        }
    }
    sqlite3_reset(st);
    if (s != AG_OK || row->version == version)
        return s;
    int64_t later = 0;
    char kind[32] = "";
    if ((s = geometry_op_between(db, model, row->version, version, &later, kind, err)) == AG_OK &&
        later)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0,
                         "the state of version %lld of model %lld was not kept (the %s op of "
                         "version %lld changed it)",
                         (long long)version, (long long)model, kind, (long long)later);
    if (s != AG_OK)
        ag_states_row_clear(row);
    return s;
}

ag_status ag_states_restore(ag_db *db, int64_t model, int64_t version, const ag_state_row *row,
                            ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "UPDATE models SET mesh_blob = ?, stats = ?, "
                                 "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE id = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, row->mesh_blob);
    sqlite3_bind_text(st, 2, row->stats_json ? row->stats_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, model);
    if ((s = ag_db_step_done(db, st, "restoring a model's mesh", err)) != AG_OK)
        return s;
    if (sqlite3_changes(ag_db_handle(db)) == 0)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    if ((s = ag_pointclouds_states_restore(db, model, row->version, err)) != AG_OK)
        return s;
    if (!row->grammar)
        return AG_OK; /* the grammar no longer describes the mesh: not proceduralized then */
    ag_grammar_new g = {.model = model,
                        .version = version,
                        .mesh_blob = row->mesh_blob,
                        .text = row->grammar,
                        .text_len = row->grammar_len,
                        .tree_json = row->tree_json ? row->tree_json : "{}",
                        .tree_numbering = row->tree_numbering,
                        .summary_json = row->summary_json};
    return ag_grammars_put(db, &g, err);
}
