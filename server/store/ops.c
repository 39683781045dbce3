#include "ops.h"

ag_status ag_ops_insert(ag_db *db, const ag_op_row *op, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(
        db, "INSERT INTO ops (model_id, version, author, cid, kind, body) VALUES (?,?,?,?,?,?)",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, op->model);
    sqlite3_bind_int64(st, 2, op->version);
    sqlite3_bind_text(st, 3, op->author, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 4, op->cid, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 5, op->kind, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 6, op->body_json, -1, SQLITE_STATIC);
    return ag_db_step_done(db, st, "writing the op log", err);
}

ag_status ag_ops_find_cid(ag_db *db, int64_t model, const char *author, const char *cid,
                          int64_t *version, ag_error *err)
{
    *version = 0;
    sqlite3_stmt *st = ag_db_prepare(
        db, "SELECT version FROM ops WHERE model_id = ? AND author = ? AND cid = ?", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_text(st, 2, author, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 3, cid, -1, SQLITE_STATIC);
    int rc = sqlite3_step(st);
    ag_status s = AG_OK;
    if (rc == SQLITE_ROW)
        *version = sqlite3_column_int64(st, 0);
    else if (rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading the op log");
    sqlite3_reset(st);
    return s;
}

ag_status ag_ops_each_since(ag_db *db, int64_t model, int64_t since, int64_t limit,
                            void (*fn)(void *user, const ag_op_row *op), void *user,
                            ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(db,
                                     "SELECT version, author, cid, kind, body, at FROM ops "
                                     "WHERE model_id = ? AND version > ? ORDER BY version LIMIT ?",
                                     err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, since);
    sqlite3_bind_int64(st, 3, limit > 0 ? limit : -1);
    int rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW) {
        ag_op_row row = {
            .model = model,
            .version = sqlite3_column_int64(st, 0),
            .author = (const char *)sqlite3_column_text(st, 1),
            .cid = (const char *)sqlite3_column_text(st, 2),
            .kind = (const char *)sqlite3_column_text(st, 3),
            .body_json = (const char *)sqlite3_column_text(st, 4),
            .at = (const char *)sqlite3_column_text(st, 5),
        };
        fn(user, &row);
    }
    ag_status s = rc == SQLITE_DONE ? AG_OK : ag_db_fail(db, err, "reading the op log");
    sqlite3_reset(st);
    return s;
}
