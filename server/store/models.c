#include "models.h"

#include <stdlib.h>
#include <string.h>

void ag_models_row_clear(ag_model_row *row)
{
    if (row) {
        free(row->stats_json);
        row->stats_json = NULL;
        free(row->up_json);
        row->up_json = NULL;
    }
}

ag_status ag_models_check_name(const char *name, ag_error *err)
{
    if (!name)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a name is required");
    size_t chars = 0;
    const unsigned char *p = (const unsigned char *)name;
    while (*p) {
        int extra;
        if (*p < 0x20 || *p == 0x7f)
            return ag_error_set(err, AG_ERR_INVALID, (long)chars + 1,
                                "the name holds a control character at position %zu", chars + 1);
        if (*p < 0x80) extra = 0;
        else if ((*p & 0xe0) == 0xc0 && *p >= 0xc2) extra = 1;
        else if ((*p & 0xf0) == 0xe0) extra = 2;
        else if ((*p & 0xf8) == 0xf0 && *p <= 0xf4) extra = 3;
        else
            return ag_error_set(err, AG_ERR_INVALID, (long)chars + 1, "the name is not valid UTF-8");
        p++;
        for (int i = 0; i < extra; i++, p++)
            if ((*p & 0xc0) != 0x80)
                return ag_error_set(err, AG_ERR_INVALID, (long)chars + 1,
                                    "the name is not valid UTF-8");
        chars++;
    }
    if (chars == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the name is empty");
    if (chars > AG_MODEL_NAME_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "the name has %zu characters; at most %d are allowed", chars,
                            AG_MODEL_NAME_MAX);
    return AG_OK;
}

static ag_status insert_blob(ag_db *db, const char *media, const void *data, size_t len,
                             int64_t *id, const char *doing, ag_error *err)
{
    sqlite3_stmt *st =
        ag_db_prepare(db, "INSERT INTO blobs (media_type, bytes, data) VALUES (?, ?, ?)", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, media ? media : "application/octet-stream", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, (sqlite3_int64)len);
    sqlite3_bind_blob64(st, 3, len ? data : "", len, SQLITE_STATIC);
    ag_status done = ag_db_step_done(db, st, doing, err);
    if (done != AG_OK)
        return done;
    *id = sqlite3_last_insert_rowid(ag_db_handle(db));
    return AG_OK;
}

ag_status ag_models_insert(ag_db *db, const ag_model_new *m, int64_t *id, ag_error *err)
{
    ag_status s = ag_models_check_name(m->name, err);
    if (s != AG_OK)
        return s;
    int64_t mesh_id = 0, source_id = 0;
    if ((s = insert_blob(db, "application/x-archgram-mesh", m->mesh, m->mesh_len, &mesh_id,
                         "storing a file", err)))
        return s;
    if (m->source && (s = insert_blob(db, m->source_media_type, m->source, m->source_len,
                                      &source_id, "storing a file", err)))
        return s;
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "INSERT INTO models (name, kind, mesh_blob, source_blob, source_format, stats, up_axis) "
        "VALUES (?, ?, ?, ?, ?, ?, ?)",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, m->name, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, m->kind ? m->kind : "mesh", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, mesh_id);
    if (source_id)
        sqlite3_bind_int64(st, 4, source_id);
    else
        sqlite3_bind_null(st, 4);
    if (m->source_format)
        sqlite3_bind_text(st, 5, m->source_format, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 5);
    sqlite3_bind_text(st, 6, m->stats_json ? m->stats_json : "{}", -1, SQLITE_STATIC);
    if (m->up_json)
        sqlite3_bind_text(st, 7, m->up_json, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 7);
    ag_status done = ag_db_step_done(db, st, "storing the model", err);
    if (done != AG_OK)
        return done;
    *id = sqlite3_last_insert_rowid(ag_db_handle(db));
    return AG_OK;
}

#define MODEL_COLUMNS                                                                     \
    "id, name, kind, version, mesh_blob, coalesce(source_blob, 0), coalesce(source_format, " \
    "''), created_at, updated_at, stats, public_read, up_axis"

static ag_status read_row(sqlite3_stmt *st, ag_model_row *row)
{
    memset(row, 0, sizeof *row);
    row->id = sqlite3_column_int64(st, 0);
    ag_db_column_copy(st, 1, row->name, sizeof row->name);
    ag_db_column_copy(st, 2, row->kind, sizeof row->kind);
    row->version = sqlite3_column_int64(st, 3);
    row->mesh_blob = sqlite3_column_int64(st, 4);
    row->source_blob = sqlite3_column_int64(st, 5);
    ag_db_column_copy(st, 6, row->source_format, sizeof row->source_format);
    ag_db_column_copy(st, 7, row->created_at, sizeof row->created_at);
    ag_db_column_copy(st, 8, row->updated_at, sizeof row->updated_at);
    row->public_read = sqlite3_column_int(st, 10) != 0;
    const unsigned char *stats = sqlite3_column_text(st, 9);
    row->stats_json = strdup(stats ? (const char *)stats : "{}");
    const unsigned char *up = sqlite3_column_text(st, 11);
    row->up_json = up ? strdup((const char *)up) : NULL;
    return row->stats_json && (row->up_json || !up) ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_models_get(ag_db *db, int64_t id, ag_model_row *row, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT " MODEL_COLUMNS " FROM models WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    ag_status s;
    if (rc == SQLITE_ROW)
        s = read_row(st, row);
    else if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)id);
    else
        s = ag_db_fail(db, err, "reading a model");
    sqlite3_reset(st);
    return s;
}

ag_status ag_models_list(ag_db *db, int64_t visible_to, int64_t after_id, size_t limit,
                         ag_model_row **rows, size_t *count, ag_error *err)
{
    *rows = NULL;
    *count = 0;
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "SELECT " MODEL_COLUMNS ", (SELECT role FROM model_members WHERE model_id = models.id "
        "AND user_id = ?1) FROM models WHERE id > ?2 AND (?1 = 0 OR public_read = 1 OR "
        "EXISTS (SELECT 1 FROM model_members WHERE model_id = models.id AND user_id = ?1)) "
        "ORDER BY id LIMIT ?3",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, visible_to);
    sqlite3_bind_int64(st, 2, after_id);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)limit);
    ag_model_row *out = calloc(limit ? limit : 1, sizeof *out);
    if (!out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory listing models");
    size_t n = 0;
    int rc = SQLITE_DONE;
    ag_status s = AG_OK;
    while (n < limit && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        if ((s = read_row(st, &out[n])) != AG_OK)
            break;
        ag_db_column_copy(st, 12, out[n].member_role, sizeof out[n].member_role);
        n++;
    }
    if (s == AG_OK && n < limit && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "listing models");
    sqlite3_reset(st);
    if (s != AG_OK) {
        for (size_t i = 0; i < n; i++)
            ag_models_row_clear(&out[i]);
        free(out);
        return s;
    }
    *rows = out;
    *count = n;
    return AG_OK;
}

size_t ag_models_count(ag_db *db)
{
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT count(*) FROM models", NULL);
    size_t n = 0;
    if (st && sqlite3_step(st) == SQLITE_ROW)
        n = (size_t)sqlite3_column_int64(st, 0);
    if (st)
        sqlite3_reset(st);
    return n;
}

static ag_status current_version(ag_db *db, int64_t id, int64_t *version, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT version FROM models WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    ag_status s = AG_OK;
    if (rc == SQLITE_ROW)
        *version = sqlite3_column_int64(st, 0);
    else if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)id);
    else
        s = ag_db_fail(db, err, "reading a model's version");
    sqlite3_reset(st);
    return s;
}

/* AG_OK when the model is at `expected`; AG_ERR_STALE with the current version in
 * err->element otherwise. */
static ag_status expect_version(ag_db *db, int64_t id, int64_t expected, int64_t *current,
                                ag_error *err)
{
    ag_status s = current_version(db, id, current, err);
    if (s == AG_OK && *current != expected)
        s = ag_error_set(err, AG_ERR_STALE, (long)*current, "model %lld is at version %lld, not %lld",
                         (long long)id, (long long)*current, (long long)expected);
    return s;
}

ag_status ag_models_bump_version(ag_db *db, int64_t id, int64_t base, int64_t *new_version,
                                 ag_error *err)
{
    int64_t v;
    ag_status s = expect_version(db, id, base, &v, err);
    if (s != AG_OK)
        return s;
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "UPDATE models SET version = version + 1, "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE id = ?",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    ag_status done = ag_db_step_done(db, st, "raising a model's version", err);
    if (done != AG_OK)
        return done;
    *new_version = v + 1;
    return AG_OK;
}

ag_status ag_models_set_name(ag_db *db, int64_t id, const char *name, ag_error *err)
{
    ag_status s = ag_models_check_name(name, err);
    if (s != AG_OK)
        return s;
    sqlite3_stmt *st = ag_db_prepare(db, "UPDATE models SET name = ? WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, id);
    return ag_db_step_done(db, st, "renaming a model", err);
}

ag_status ag_models_set_stats(ag_db *db, int64_t id, const char *stats_json, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "UPDATE models SET stats = ?, updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') "
        "WHERE id = ?",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, stats_json ? stats_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 2, id);
    ag_status s = ag_db_step_done(db, st, "describing a model", err);
    if (s == AG_OK && sqlite3_changes(ag_db_handle(db)) == 0)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)id);
    return s;
}

ag_status ag_models_set_public_read(ag_db *db, int64_t id, int on, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(db, "UPDATE models SET public_read = ? WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int(st, 1, on ? 1 : 0);
    sqlite3_bind_int64(st, 2, id);
    ag_status s = ag_db_step_done(db, st, "changing who may read a model", err);
    if (s == AG_OK && sqlite3_changes(ag_db_handle(db)) == 0)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)id);
    return s;
}

ag_status ag_models_set_mesh(ag_db *db, int64_t id, const void *mesh, size_t mesh_len,
                             const char *stats_json, int64_t *blob, ag_error *err)
{
    int64_t b = 0;
    ag_status s = insert_blob(db, "application/x-archgram-mesh", mesh, mesh_len, &b,
                              "storing a mesh", err);
    if (s != AG_OK)
        return s;
    if (blob)
        *blob = b;
    sqlite3_stmt *st = ag_db_prepare(db,
                                     "UPDATE models SET mesh_blob = ?, stats = ?, "
                                     "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') "
                                     "WHERE id = ?",
                                     err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, b);
    sqlite3_bind_text(st, 2, stats_json ? stats_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, id);
    if ((s = ag_db_step_done(db, st, "replacing a model's mesh", err)) != AG_OK)
        return s;
    if (sqlite3_changes(ag_db_handle(db)) == 0)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)id);
    return AG_OK;
}

ag_status ag_models_delete(ag_db *db, int64_t id, int64_t version, ag_error *err)
{
    int64_t v;
    ag_status s = expect_version(db, id, version, &v, err);
    if (s != AG_OK)
        return s;
    sqlite3_stmt *st = ag_db_prepare(db, "DELETE FROM models WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    return ag_db_step_done(db, st, "deleting a model", err);
}

ag_status ag_blobs_get(ag_db *db, int64_t id, void **data, size_t *len, ag_error *err)
{
    *data = NULL;
    *len = 0;
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT data FROM blobs WHERE id = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    ag_status s = AG_OK;
    if (rc == SQLITE_ROW) {
        const void *p = sqlite3_column_blob(st, 0); /* before _bytes, as SQLite asks */
        size_t n = (size_t)sqlite3_column_bytes(st, 0);
        void *copy = malloc(n ? n : 1);
        if (!copy)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a file");
        else {
            if (n)
                memcpy(copy, p, n);
            *data = copy;
            *len = n;
        }
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no stored file %lld", (long long)id);
    } else {
        s = ag_db_fail(db, err, "reading a stored file");
    }
    sqlite3_reset(st);
    return s;
}
