/* Shared by the store tests (test_migrate.c, test_*_store.c, test_states.c): a throw-away
 * database file, row counts, a model to hang rows on, and a database as an older archgram left
 * it. Header-only because every test file is its own binary; include it after <cmocka.h>. */
#ifndef AG_TEST_STORE_FIXTURE_H
#define AG_TEST_STORE_FIXTURE_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "embedded.h"
#include "store/db.h"
#include "store/migrate.h"
#include "store/models.h"
#include "store/users.h"

/* A fresh path for a database that does not exist yet; free it with remove_db. */
static inline char *temp_db(void)
{
    char *path = strdup("/tmp/archgram-test-XXXXXX");
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    unlink(path);
    return path;
}

/* Deletes the database with its WAL side files, and frees path. */
static inline void remove_db(char *path)
{
    char side[4200];
    unlink(path);
    snprintf(side, sizeof side, "%s-wal", path);
    unlink(side);
    snprintf(side, sizeof side, "%s-shm", path);
    unlink(side);
    free(path);
}

/* A fresh database at a temp path, migrated; close it with close_temp_db. */
static inline ag_db *open_temp_db(char **path)
{
    ag_db *db;
    ag_error err;
    *path = temp_db();
    assert_int_equal(ag_db_open(*path, NULL, &db, &err), AG_OK);
    return db;
}

static inline void close_temp_db(ag_db *db, char *path)
{
    ag_db_close(db);
    remove_db(path);
}

/* Makes an account in a transaction of its own; returns its id. */
static inline int64_t insert_user(ag_db *db, const char *name, ag_account_role role)
{
    ag_error err;
    int64_t id = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_users_insert(db, name, role, &id, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return id;
}

/* The one integer a `SELECT count(*) ...` returns. */
static inline long long count(ag_db *db, const char *sql)
{
    sqlite3_stmt *st;
    assert_int_equal(sqlite3_prepare_v2(ag_db_handle(db), sql, -1, &st, NULL), SQLITE_OK);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    long long n = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return n;
}

/* Inserts a model in a transaction of its own; returns its id. */
static inline int64_t insert_model(ag_db *db, const ag_model_new *m)
{
    ag_error err;
    int64_t id = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_insert(db, m, &id, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return id;
}

/* A database as archgram left it with only its first `migrations` migrations, holding model 5
 * ("old", version 4, its mesh blob 1 and one op); returns its path (free with remove_db). */
static inline char *old_database(size_t migrations)
{
    char *path = temp_db();
    sqlite3 *raw;
    ag_error err;
    assert_int_equal(sqlite3_open(path, &raw), SQLITE_OK);
    assert_int_equal(ag_migrate(raw, ag_migrations, migrations, &err), AG_OK);
    assert_int_equal(ag_migrate_user_version(raw), (int)migrations);
    assert_int_equal(sqlite3_exec(raw,
                                  "INSERT INTO blobs (id, media_type, bytes, data) VALUES "
                                  "(1, 'x', 3, 'abc');"
                                  "INSERT INTO models (id, name, version, mesh_blob) VALUES "
                                  "(5, 'old', 4, 1);"
                                  "INSERT INTO ops VALUES (5, 2, 'ana', 'c1', 'note', "
                                  "'{\"kind\":\"note\",\"text\":\"hi\"}', '2024-01-01');",
                                  NULL, NULL, NULL),
                     SQLITE_OK);
    sqlite3_close(raw);
    return path;
}

/* Opens an old_database, which migrates it to the current schema, and checks that model 5 and
 * its op came through. */
static inline ag_db *open_old_database(const char *path)
{
    ag_db *db;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    assert_int_equal(ag_db_schema_version(db), (int)ag_migrations_count);
    ag_model_row row;
    assert_int_equal(ag_models_get(db, 5, &row, &err), AG_OK);
    assert_string_equal(row.name, "old");
    assert_int_equal(row.version, 4);
    ag_models_row_clear(&row);
    assert_int_equal(count(db, "SELECT count(*) FROM ops WHERE model_id = 5"), 1);
    return db;
}

#endif
