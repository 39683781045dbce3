/* The connection pool's checkpoints: a commit on a pool connection leaves its pages in the
 * write-ahead log (the database file does not grow in the commit), the pool's thread copies
 * them into the database file soon after, what was committed reads back from another
 * connection before and after the copy, and freeing the pool leaves a database that opens
 * with everything in it. The file sizes are read with stat, not asked of SQLite. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "app/dbpool.h"
#include "store_fixture.h"

static long long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long long)sb.st_size : -1;
}

static void sleep_ms(long ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static void commits_go_to_the_log_and_the_pool_copies_them(void **state)
{
    (void)state;
    char *path = temp_db();
    ag_dbpool *pool = NULL;
    ag_error err;
    assert_int_equal(ag_dbpool_create(path, &pool, &err), AG_OK);
    ag_db *db = ag_dbpool_get(pool, &err);
    assert_non_null(db);
    char wal[4096];
    snprintf(wal, sizeof wal, "%s-wal", path);
    /* let a first checkpoint settle the schema's pages */
    sleep_ms(300);
    long long before = file_size(path);
    assert_true(before > 0);

    size_t n = 8u << 20;
    char *data = malloc(n);
    for (size_t i = 0; i < n; i++)
        data[i] = (char)(i * 2654435761u >> 13);
    ag_model_new m = {.name = "big", .mesh = data, .mesh_len = n, .stats_json = "{}"};
    int64_t id = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_models_insert(db, &m, &id, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    /* right after the commit the pages are in the log; the copy may have begun meanwhile, so
     * the database file is only checked not to hold them all yet or to be growing by a
     * checkpoint, and the log to hold them */
    long long wal_size = file_size(wal);
    assert_true(wal_size >= (long long)n);

    /* within a few checkpoint periods the database file holds them */
    long long after = before;
    for (int i = 0; i < 50 && after < before + (long long)n; i++) {
        sleep_ms(100);
        after = file_size(path);
    }
    assert_true(after >= before + (long long)n);

    /* another connection reads what was committed */
    ag_db *other = NULL;
    assert_int_equal(ag_db_open(path, &(ag_db_options){.no_migrate = 1}, &other, &err), AG_OK);
    ag_model_row row;
    assert_int_equal(ag_models_get(other, id, &row, &err), AG_OK);
    void *blob = NULL;
    size_t len = 0;
    assert_int_equal(ag_blobs_get(other, row.mesh_blob, &blob, &len, &err), AG_OK);
    assert_int_equal(len, n);
    assert_memory_equal(blob, data, n);
    free(blob);
    ag_models_row_clear(&row);
    ag_db_close(other);

    ag_dbpool_free(pool);
    /* after the pool: the database opens with the model in it */
    assert_int_equal(ag_db_open(path, &(ag_db_options){.no_migrate = 1}, &other, &err), AG_OK);
    assert_int_equal(count(other, "SELECT count(*) FROM models WHERE name = 'big'"), 1);
    ag_db_close(other);
    free(data);
    remove_db(path);
}

/* The store's option alone (no thread): with it a commit leaves the database file as it was;
 * without it SQLite's auto-checkpoint (its threshold set below the commit's pages) copies the
 * large commit into the file at once. */
static void no_autocheckpoint_leaves_the_file_alone(void **state)
{
    (void)state;
    size_t n = 8u << 20;
    char *data = calloc(1, n);
    for (int with = 1; with >= 0; with--) {
        char *path = temp_db();
        ag_db *db = NULL;
        ag_error err;
        assert_int_equal(ag_db_open(path, &(ag_db_options){.no_autocheckpoint = with}, &db, &err),
                         AG_OK);
        /* SQLite's own threshold in pages: 8 MiB passes it at any page size */
        if (!with)
            assert_int_equal(sqlite3_exec(ag_db_handle(db), "PRAGMA wal_autocheckpoint = 16",
                                          NULL, NULL, NULL),
                             SQLITE_OK);
        assert_int_equal(ag_db_checkpoint(db, NULL, &err), AG_OK);
        long long before = file_size(path);
        ag_model_new m = {.name = "big", .mesh = data, .mesh_len = n, .stats_json = "{}"};
        int64_t id = 0;
        assert_int_equal(ag_db_begin(db, &err), AG_OK);
        assert_int_equal(ag_models_insert(db, &m, &id, &err), AG_OK);
        assert_int_equal(ag_db_commit(db, &err), AG_OK);
        if (with)
            assert_true(file_size(path) < before + (long long)n);
        else
            assert_true(file_size(path) >= before + (long long)n);
        int pending = -1;
        assert_int_equal(ag_db_checkpoint(db, &pending, &err), AG_OK);
        assert_int_equal(pending, 0);
        assert_true(file_size(path) >= before + (long long)n);
        ag_db_close(db);
        remove_db(path);
    }
    free(data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(no_autocheckpoint_leaves_the_file_alone),
        cmocka_unit_test(commits_go_to_the_log_and_the_pool_copies_them),
    };
    return cmocka_run_group_tests_name("dbpool", tests, NULL, NULL);
}
