#include "jobs.h"

#include <stdlib.h>
#include <string.h>

static char *dup_or_null(const unsigned char *s)
{
    return s ? strdup((const char *)s) : NULL;
}

void ag_jobs_row_clear(ag_job_row *row)
{
    if (!row)
        return;
    free(row->params_json);
    free(row->result_json);
    free(row->error_json);
    row->params_json = row->result_json = row->error_json = NULL;
}

ag_status ag_jobs_insert(ag_db *db, const char *kind, const char *params_json, int64_t user,
                         int64_t *id, ag_error *err)
{
    sqlite3_stmt *st =
        ag_db_prepare(db, "INSERT INTO jobs (kind, params, user_id) VALUES (?, ?, ?)", err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, kind, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, params_json ? params_json : "{}", -1, SQLITE_STATIC);
    if (user > 0)
        sqlite3_bind_int64(st, 3, user);
    else
        sqlite3_bind_null(st, 3);
    ag_status done = ag_db_step_done(db, st, "creating a job", err);
    if (done != AG_OK)
        return done;
    *id = sqlite3_last_insert_rowid(ag_db_handle(db));
    return AG_OK;
}

ag_status ag_jobs_get(ag_db *db, int64_t id, ag_job_row *row, ag_error *err)
{
    memset(row, 0, sizeof *row);
    sqlite3_stmt *st = ag_db_prepare(db,
                                     "SELECT id, kind, status, progress, coalesce(stage, ''), "
                                     "params, result, error, coalesce(model_id, 0), created_at, "
                                     "updated_at, coalesce(user_id, 0) FROM jobs WHERE id = ?",
                                     err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    ag_status s = AG_OK;
    if (rc == SQLITE_ROW) {
        row->id = sqlite3_column_int64(st, 0);
        ag_db_column_copy(st, 1, row->kind, sizeof row->kind);
        ag_db_column_copy(st, 2, row->status, sizeof row->status);
        row->progress = sqlite3_column_double(st, 3);
        ag_db_column_copy(st, 4, row->stage, sizeof row->stage);
        row->params_json = dup_or_null(sqlite3_column_text(st, 5));
        row->result_json = dup_or_null(sqlite3_column_text(st, 6));
        row->error_json = dup_or_null(sqlite3_column_text(st, 7));
        row->model = sqlite3_column_int64(st, 8);
        ag_db_column_copy(st, 9, row->created_at, sizeof row->created_at);
        ag_db_column_copy(st, 10, row->updated_at, sizeof row->updated_at);
        row->user = sqlite3_column_int64(st, 11);
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no job %lld", (long long)id);
    } else {
        s = ag_db_fail(db, err, "reading a job");
    }
    sqlite3_reset(st);
    return s;
}

ag_status ag_jobs_update(ag_db *db, int64_t id, const char *status, double progress,
                         const char *stage, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "UPDATE jobs SET status = ?, progress = ?, stage = coalesce(?, stage), "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') "
        "WHERE id = ? AND status IN ('queued', 'running')",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, status, -1, SQLITE_STATIC);
    sqlite3_bind_double(st, 2, progress < 0 ? 0 : progress > 1 ? 1 : progress);
    if (stage)
        sqlite3_bind_text(st, 3, stage, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 3);
    sqlite3_bind_int64(st, 4, id);
    return ag_db_step_done(db, st, "updating a job", err);
}

ag_status ag_jobs_finish(ag_db *db, int64_t id, const char *status, const char *result_json,
                         const char *error_json, int64_t model, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "UPDATE jobs SET status = ?, result = ?, error = ?, model_id = ?, "
        "progress = CASE WHEN ? = 'succeeded' THEN 1 ELSE progress END, "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') "
        "WHERE id = ? AND status IN ('queued', 'running')",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, status, -1, SQLITE_STATIC);
    if (result_json)
        sqlite3_bind_text(st, 2, result_json, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 2);
    if (error_json)
        sqlite3_bind_text(st, 3, error_json, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 3);
    if (model)
        sqlite3_bind_int64(st, 4, model);
    else
        sqlite3_bind_null(st, 4);
    sqlite3_bind_text(st, 5, status, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 6, id);
    return ag_db_step_done(db, st, "finishing a job", err);
}

ag_status ag_jobs_cancel_unfinished(ag_db *db, const char *error_json, int *count, ag_error *err)
{
    sqlite3_stmt *st = ag_db_prepare(
        db,
        "UPDATE jobs SET status = 'cancelled', error = ?, "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') "
        "WHERE status IN ('queued', 'running')",
        err);
    if (!st)
        return err ? err->code : AG_ERR_DB;
    sqlite3_bind_text(st, 1, error_json, -1, SQLITE_STATIC);
    ag_status done = ag_db_step_done(db, st, "cancelling unfinished jobs", err);
    if (done != AG_OK)
        return done;
    if (count)
        *count = sqlite3_changes(ag_db_handle(db));
    return AG_OK;
}
