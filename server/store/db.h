/* One SQLite connection with archgram's settings: WAL, foreign keys, a busy timeout, and the
 * schema brought up to date from the embedded migrations when it is opened.
 *
 * A connection belongs to one thread at a time. Every write goes through
 * ag_db_begin (BEGIN IMMEDIATE: a deferred transaction that later writes fails with
 * SQLITE_BUSY_SNAPSHOT under WAL and ignores the busy timeout). */
#ifndef AG_DB_H
#define AG_DB_H

#include <sqlite3.h>

#include "../core/status.h"

typedef struct ag_db ag_db;

typedef struct {
    int busy_timeout_ms; /* 0 = 10000 */
    int no_migrate;      /* 1: open an existing schema as it is (still refuses a newer one) */
    size_t max_bytes;    /* the file may grow to about this size (PRAGMA max_page_count);
                            0: no limit. Writes past it fail with AG_ERR_STORAGE_FULL */
    int no_autocheckpoint; /* 1: a commit never copies the WAL into the database file itself
                              (SQLite's auto-checkpoint, tens of milliseconds after a large
                              write, would be paid by the writer before its change is
                              acknowledged); the opener calls ag_db_checkpoint instead */
} ag_db_options;

/* Copies what the WAL holds into the database file as far as readers allow, without waiting
 * for anyone (a passive checkpoint); *pending (may be NULL) is set to the frames left. */
ag_status ag_db_checkpoint(ag_db *db, int *pending, ag_error *err);

ag_status ag_db_open(const char *path, const ag_db_options *opt, ag_db **out, ag_error *err);
void ag_db_close(ag_db *db);

sqlite3 *ag_db_handle(ag_db *db);
const char *ag_db_path(const ag_db *db);
int ag_db_schema_version(ag_db *db);

ag_status ag_db_begin(ag_db *db, ag_error *err);
ag_status ag_db_commit(ag_db *db, ag_error *err);
void ag_db_rollback(ag_db *db);

/* Turns the connection's last SQLite error into a status with the message and what was
 * being done: AG_ERR_BUSY for a lock timeout, AG_ERR_STORAGE_FULL when the disk or the
 * configured size is full, AG_ERR_STORE_UNAVAILABLE for I/O errors and a file that cannot be
 * read or written, AG_ERR_DB otherwise. */
ag_status ag_db_fail(ag_db *db, ag_error *err, const char *doing);

/* Prepares (and caches per connection) a statement; NULL with err filled on failure.
 * The statement is reset and its bindings cleared before it is returned. */
sqlite3_stmt *ag_db_prepare(ag_db *db, const char *sql, ag_error *err);

/* Steps a statement that returns no row and resets it; AG_OK or the failure, described as
 * what was being done. */
ag_status ag_db_step_done(ag_db *db, sqlite3_stmt *st, const char *doing, ag_error *err);

/* Copies a text column into a fixed buffer (truncating; "" for NULL). */
void ag_db_column_copy(sqlite3_stmt *st, int col, char *dst, size_t cap);

/* ag_db_prepare as a status: AG_OK with *st, or the failure (err filled). */
ag_status ag_db_prepared(ag_db *db, sqlite3_stmt **st, const char *sql, ag_error *err);

/* A malloc'd NUL-terminated copy of a text column and its length (len may be NULL); NULL for
 * SQL NULL, and NULL with *nomem set when out of memory. */
char *ag_db_column_dup(sqlite3_stmt *st, int col, size_t *len, int *nomem);

#endif
