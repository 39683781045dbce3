/* Schema migrations on an empty database, an older one, a newer one, and a failing script. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "store_fixture.h"

static int table_exists(sqlite3 *db, const char *name)
{
    sqlite3_stmt *st;
    assert_int_equal(sqlite3_prepare_v2(db, "SELECT count(*) FROM sqlite_master WHERE name = ?",
                                         -1, &st, NULL),
                     SQLITE_OK);
    sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    int n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return n;
}

static void empty_database_gets_every_migration(void **state)
{
    (void)state;
    char *path = temp_db();
    ag_db *db;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    assert_int_equal(ag_db_schema_version(db), (int)ag_migrations_count);
    assert_true(table_exists(ag_db_handle(db), "models"));
    assert_true(table_exists(ag_db_handle(db), "jobs"));
    assert_true(table_exists(ag_db_handle(db), "ops"));
    assert_true(table_exists(ag_db_handle(db), "blobs"));
    /* The settings every connection must have. */
    sqlite3_stmt *st;
    sqlite3_prepare_v2(ag_db_handle(db), "PRAGMA journal_mode", -1, &st, NULL);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    assert_string_equal((const char *)sqlite3_column_text(st, 0), "wal");
    sqlite3_finalize(st);
    sqlite3_prepare_v2(ag_db_handle(db), "PRAGMA foreign_keys", -1, &st, NULL);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    assert_int_equal(sqlite3_column_int(st, 0), 1);
    sqlite3_finalize(st);
    ag_db_close(db);
    /* Opening again applies nothing and keeps the version. */
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    assert_int_equal(ag_db_schema_version(db), (int)ag_migrations_count);
    ag_db_close(db);
    remove_db(path);
}

static const struct ag_migration two[] = {
    {"0001_a", "CREATE TABLE a (x INTEGER);"},
    {"0002_b", "CREATE TABLE b (y INTEGER); INSERT INTO a VALUES (1);"},
};

static void older_database_is_brought_up_to_date(void **state)
{
    (void)state;
    char *path = temp_db();
    sqlite3 *db;
    assert_int_equal(sqlite3_open(path, &db), SQLITE_OK);
    ag_error err;
    assert_int_equal(ag_migrate(db, two, 1, &err), AG_OK);
    assert_int_equal(ag_migrate_user_version(db), 1);
    assert_true(table_exists(db, "a"));
    assert_false(table_exists(db, "b"));
    assert_int_equal(ag_migrate(db, two, 2, &err), AG_OK);
    assert_int_equal(ag_migrate_user_version(db), 2);
    assert_true(table_exists(db, "b"));
    sqlite3_close(db);
    remove_db(path);
}

static void newer_database_is_refused_untouched(void **state)
{
    (void)state;
    char *path = temp_db();
    sqlite3 *raw;
    assert_int_equal(sqlite3_open(path, &raw), SQLITE_OK);
    char sql[64];
    snprintf(sql, sizeof sql, "PRAGMA user_version = %zu", ag_migrations_count + 1);
    assert_int_equal(sqlite3_exec(raw, sql, NULL, NULL, NULL), SQLITE_OK);
    sqlite3_close(raw);

    ag_db *db = NULL;
    ag_error err;
    ag_error_clear(&err);
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_ERR_DB_TOO_NEW);
    assert_null(db);
    assert_non_null(strstr(err.text, "newer archgram"));
    assert_int_equal(ag_db_open(path, &(ag_db_options){.no_migrate = 1}, &db, &err),
                     AG_ERR_DB_TOO_NEW);

    assert_int_equal(sqlite3_open(path, &raw), SQLITE_OK);
    assert_int_equal(ag_migrate_user_version(raw), (int)ag_migrations_count + 1);
    assert_false(table_exists(raw, "models"));
    sqlite3_close(raw);
    remove_db(path);
}

static void failing_migration_leaves_nothing_behind(void **state)
{
    (void)state;
    static const struct ag_migration broken[] = {
        {"0001_a", "CREATE TABLE a (x INTEGER);"},
        {"0002_broken", "CREATE TABLE c (z INTEGER); INSERT INTO nowhere VALUES (1);"},
    };
    char *path = temp_db();
    sqlite3 *db;
    assert_int_equal(sqlite3_open(path, &db), SQLITE_OK);
    ag_error err;
    ag_error_clear(&err);
    assert_int_equal(ag_migrate(db, broken, 2, &err), AG_ERR_DB);
    assert_non_null(strstr(err.text, "0002_broken"));
    assert_int_equal(ag_migrate_user_version(db), 1);
    assert_true(table_exists(db, "a"));
    assert_false(table_exists(db, "c"));
    sqlite3_close(db);
    remove_db(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(empty_database_gets_every_migration),
        cmocka_unit_test(older_database_is_brought_up_to_date),
        cmocka_unit_test(newer_database_is_refused_untouched),
        cmocka_unit_test(failing_migration_leaves_nothing_behind),
    };
    return cmocka_run_group_tests_name("migrate", tests, NULL, NULL);
}
