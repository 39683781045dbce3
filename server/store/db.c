#include "db.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../embedded.h"
#include "migrate.h"

#define AG_DB_STMT_CACHE 48

struct ag_db {
    sqlite3 *handle;
    char *path;
    struct {
        const char *sql;
        sqlite3_stmt *stmt;
    } cache[AG_DB_STMT_CACHE];
    size_t ncache;
};

static ag_status exec(ag_db *db, const char *sql, ag_error *err)
{
    char *msg = NULL;
    if (sqlite3_exec(db->handle, sql, NULL, NULL, &msg) != SQLITE_OK) {
        ag_error_set(err, AG_ERR_DB, 0, "%s: %s", sql, msg ? msg : "?");
        sqlite3_free(msg);
        return AG_ERR_DB;
    }
    return AG_OK;
}

ag_status ag_db_open(const char *path, const ag_db_options *opt, ag_db **out, ag_error *err)
{
    *out = NULL;
    ag_db *db = calloc(1, sizeof *db);
    if (!db || !(db->path = strdup(path))) {
        free(db);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory opening %s", path);
    }
    int rc = sqlite3_open_v2(path, &db->handle,
                             SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, NULL);
    if (rc != SQLITE_OK) {
        ag_error_set(err, AG_ERR_DB, 0, "cannot open database %s: %s", path,
                     db->handle ? sqlite3_errmsg(db->handle) : sqlite3_errstr(rc));
        ag_db_close(db);
        return AG_ERR_DB;
    }
    sqlite3_extended_result_codes(db->handle, 1);
    sqlite3_busy_timeout(db->handle, opt && opt->busy_timeout_ms ? opt->busy_timeout_ms : 10000);
    /* A new database gets 64 KiB pages: a version's mesh file is megabytes, and a commit
     * writes the log page by page, sixteen times the calls with SQLite's 4 KiB. A database
     * capped below 64 MiB keeps 4 KiB pages so that a small cap still holds its schema. An
     * existing database keeps the size it was made with (the pragma does nothing then). */
    ag_status s = exec(db,
                       opt && opt->max_bytes && opt->max_bytes < ((size_t)64 << 20)
                           ? "PRAGMA page_size = 4096"
                           : "PRAGMA page_size = 65536",
                       err);
    if (s == AG_OK)
        s = exec(db, "PRAGMA journal_mode = WAL", err);
    if (s == AG_OK)
        s = exec(db, "PRAGMA foreign_keys = ON", err);
    if (s == AG_OK)
        s = exec(db, "PRAGMA synchronous = NORMAL", err);
    if (s == AG_OK && opt && opt->no_autocheckpoint)
        s = exec(db, "PRAGMA wal_autocheckpoint = 0", err);
    /* the WAL is cut back to this size when it is reset, so one large write does not keep
     * its file large */
    if (s == AG_OK)
        s = exec(db, "PRAGMA journal_size_limit = 67108864", err);
    if (s == AG_OK && opt && opt->max_bytes) {
        sqlite3_stmt *st = NULL;
        long long page = 4096;
        if (sqlite3_prepare_v2(db->handle, "PRAGMA page_size", -1, &st, NULL) == SQLITE_OK &&
            sqlite3_step(st) == SQLITE_ROW)
            page = sqlite3_column_int64(st, 0);
        sqlite3_finalize(st);
        char sql[64];
        snprintf(sql, sizeof sql, "PRAGMA max_page_count = %lld",
                 (long long)(opt->max_bytes / (size_t)(page > 0 ? page : 4096)) + 1);
        s = exec(db, sql, err);
    }
    if (s == AG_OK) {
        if (opt && opt->no_migrate) {
            int v = ag_migrate_user_version(db->handle);
            if (v > (int)ag_migrations_count)
                s = ag_error_set(err, AG_ERR_DB_TOO_NEW, v,
                                 "the database has schema version %d but this archgram knows "
                                 "only %zu; use a newer archgram",
                                 v, ag_migrations_count);
        } else {
            s = ag_migrate(db->handle, ag_migrations, ag_migrations_count, err);
        }
    }
    if (s != AG_OK) {
        ag_db_close(db);
        return s;
    }
    *out = db;
    return AG_OK;
}

void ag_db_close(ag_db *db)
{
    if (!db)
        return;
    for (size_t i = 0; i < db->ncache; i++)
        sqlite3_finalize(db->cache[i].stmt);
    sqlite3_close(db->handle);
    free(db->path);
    free(db);
}

ag_status ag_db_checkpoint(ag_db *db, int *pending, ag_error *err)
{
    int log = 0, done = 0;
    int rc = sqlite3_wal_checkpoint_v2(db->handle, NULL, SQLITE_CHECKPOINT_PASSIVE, &log, &done);
    if (pending)
        *pending = log > done ? log - done : 0;
    if (rc == SQLITE_OK || rc == SQLITE_BUSY || rc == SQLITE_LOCKED)
        return AG_OK; /* busy: another checkpoint is under way */
    return ag_db_fail(db, err, "copying the write-ahead log into the database");
}

sqlite3 *ag_db_handle(ag_db *db) { return db->handle; }
const char *ag_db_path(const ag_db *db) { return db->path; }
int ag_db_schema_version(ag_db *db) { return ag_migrate_user_version(db->handle); }

ag_status ag_db_fail(ag_db *db, ag_error *err, const char *doing)
{
    int code = sqlite3_extended_errcode(db->handle) & 0xff;
    ag_status s = AG_ERR_DB;
    if (code == SQLITE_BUSY || code == SQLITE_LOCKED)
        s = AG_ERR_BUSY;
    else if (code == SQLITE_FULL)
        s = AG_ERR_STORAGE_FULL;
    else if (code == SQLITE_IOERR || code == SQLITE_CANTOPEN || code == SQLITE_READONLY ||
             code == SQLITE_CORRUPT || code == SQLITE_NOTADB || code == SQLITE_PROTOCOL)
        s = AG_ERR_STORE_UNAVAILABLE;
    return ag_error_set(err, s, 0, "%s: %s", doing, sqlite3_errmsg(db->handle));
}

ag_status ag_db_begin(ag_db *db, ag_error *err)
{
    if (sqlite3_exec(db->handle, "BEGIN IMMEDIATE", NULL, NULL, NULL) != SQLITE_OK)
        return ag_db_fail(db, err, "starting a write transaction");
    return AG_OK;
}

ag_status ag_db_commit(ag_db *db, ag_error *err)
{
    if (sqlite3_exec(db->handle, "COMMIT", NULL, NULL, NULL) != SQLITE_OK) {
        ag_status s = ag_db_fail(db, err, "committing");
        ag_db_rollback(db);
        return s;
    }
    return AG_OK;
}

void ag_db_rollback(ag_db *db)
{
    if (!sqlite3_get_autocommit(db->handle))
        sqlite3_exec(db->handle, "ROLLBACK", NULL, NULL, NULL);
}

sqlite3_stmt *ag_db_prepare(ag_db *db, const char *sql, ag_error *err)
{
    for (size_t i = 0; i < db->ncache; i++) {
        if (db->cache[i].sql == sql || strcmp(db->cache[i].sql, sql) == 0) {
            sqlite3_stmt *st = db->cache[i].stmt;
            sqlite3_reset(st);
            sqlite3_clear_bindings(st);
            return st;
        }
    }
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(db->handle, sql, -1, &st, NULL) != SQLITE_OK) {
        ag_db_fail(db, err, "preparing a statement");
        return NULL;
    }
    if (db->ncache < AG_DB_STMT_CACHE) {
        db->cache[db->ncache].sql = sql;
        db->cache[db->ncache].stmt = st;
        db->ncache++;
    } else {
        /* Full cache: the statement set is fixed and small, so this only happens if a
         * caller builds SQL dynamically — keep it working by evicting the oldest. */
        sqlite3_finalize(db->cache[0].stmt);
        memmove(&db->cache[0], &db->cache[1], sizeof db->cache[0] * (AG_DB_STMT_CACHE - 1));
        db->cache[AG_DB_STMT_CACHE - 1].sql = sql;
        db->cache[AG_DB_STMT_CACHE - 1].stmt = st;
    }
    return st;
}

ag_status ag_db_step_done(ag_db *db, sqlite3_stmt *st, const char *doing, ag_error *err)
{
    int rc = sqlite3_step(st);
    ag_status s = rc == SQLITE_DONE ? AG_OK : ag_db_fail(db, err, doing);
    sqlite3_reset(st);
    return s;
}

void ag_db_column_copy(sqlite3_stmt *st, int col, char *dst, size_t cap)
{
    const unsigned char *src = sqlite3_column_text(st, col);
    size_t n = src ? strlen((const char *)src) : 0;
    if (n >= cap)
        n = cap - 1;
    if (n)
        memcpy(dst, src, n);
    dst[n] = '\0';
}

ag_status ag_db_prepared(ag_db *db, sqlite3_stmt **st, const char *sql, ag_error *err)
{
    *st = ag_db_prepare(db, sql, err);
    return *st ? AG_OK : (err ? err->code : AG_ERR_DB);
}

char *ag_db_column_dup(sqlite3_stmt *st, int col, size_t *len, int *nomem)
{
    if (len)
        *len = 0;
    if (sqlite3_column_type(st, col) == SQLITE_NULL)
        return NULL;
    const unsigned char *p = sqlite3_column_text(st, col);
    size_t n = p ? (size_t)sqlite3_column_bytes(st, col) : 0;
    char *s = malloc(n + 1);
    if (!s) {
        *nomem = 1;
        return NULL;
    }
    if (n)
        memcpy(s, p, n);
    s[n] = '\0';
    if (len)
        *len = n;
    return s;
}
