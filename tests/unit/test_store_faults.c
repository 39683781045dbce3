/* SQLite faults: writes that fail with an I/O error (a VFS that forwards to the real one and
 * fails writes, syncs and truncations on demand) and a database that is full (its size
 * capped by ag_db_options.max_bytes, PRAGMA max_page_count) give AG_ERR_STORE_UNAVAILABLE
 * (503) and AG_ERR_STORAGE_FULL (507), leave nothing half-written — every committed model is
 * there and whole, the failed one is not, PRAGMA integrity_check says ok — and the store works
 * again once the fault is gone. */
#include <sys/stat.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <sqlite3.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/store_ws.h"
#include "core/demo_building.h"
#include "store/db.h"
#include "store/models.h"

/* --- a VFS whose writes fail on demand ------------------------------------------------------ */

static sqlite3_vfs *real_vfs;
static sqlite3_vfs faulty_vfs;
static sqlite3_io_methods faulty_io;
static const sqlite3_io_methods *real_io;
static atomic_int failing;

typedef struct {
    sqlite3_file base;
    sqlite3_file *real;
} faulty_file;

#define REAL(f) (((faulty_file *)(f))->real)

static int f_close(sqlite3_file *f) { return REAL(f)->pMethods->xClose(REAL(f)); }
static int f_read(sqlite3_file *f, void *b, int n, sqlite3_int64 o)
{
    return REAL(f)->pMethods->xRead(REAL(f), b, n, o);
}
static int f_write(sqlite3_file *f, const void *b, int n, sqlite3_int64 o)
{
    return atomic_load(&failing) ? SQLITE_IOERR_WRITE : REAL(f)->pMethods->xWrite(REAL(f), b, n, o);
}
static int f_truncate(sqlite3_file *f, sqlite3_int64 s)
{
    return atomic_load(&failing) ? SQLITE_IOERR_TRUNCATE : REAL(f)->pMethods->xTruncate(REAL(f), s);
}
static int f_sync(sqlite3_file *f, int flags)
{
    return atomic_load(&failing) ? SQLITE_IOERR_FSYNC : REAL(f)->pMethods->xSync(REAL(f), flags);
}
static int f_size(sqlite3_file *f, sqlite3_int64 *s) { return REAL(f)->pMethods->xFileSize(REAL(f), s); }
static int f_lock(sqlite3_file *f, int l) { return REAL(f)->pMethods->xLock(REAL(f), l); }
static int f_unlock(sqlite3_file *f, int l) { return REAL(f)->pMethods->xUnlock(REAL(f), l); }
static int f_reserved(sqlite3_file *f, int *r)
{
    return REAL(f)->pMethods->xCheckReservedLock(REAL(f), r);
}
static int f_control(sqlite3_file *f, int op, void *a)
{
    return REAL(f)->pMethods->xFileControl(REAL(f), op, a);
}
static int f_sector(sqlite3_file *f) { return REAL(f)->pMethods->xSectorSize(REAL(f)); }
static int f_device(sqlite3_file *f) { return REAL(f)->pMethods->xDeviceCharacteristics(REAL(f)); }
static int f_shm_map(sqlite3_file *f, int pg, int sz, int extend, void volatile **p)
{
    return REAL(f)->pMethods->xShmMap(REAL(f), pg, sz, extend, p);
}
static int f_shm_lock(sqlite3_file *f, int off, int n, int flags)
{
    return REAL(f)->pMethods->xShmLock(REAL(f), off, n, flags);
}
static void f_shm_barrier(sqlite3_file *f) { REAL(f)->pMethods->xShmBarrier(REAL(f)); }
static int f_shm_unmap(sqlite3_file *f, int del) { return REAL(f)->pMethods->xShmUnmap(REAL(f), del); }

static int f_open(sqlite3_vfs *vfs, const char *name, sqlite3_file *file, int flags, int *out)
{
    (void)vfs;
    faulty_file *f = (faulty_file *)file;
    f->real = (sqlite3_file *)(f + 1);
    int rc = real_vfs->xOpen(real_vfs, name, f->real, flags, out);
    if (rc != SQLITE_OK || !f->real->pMethods) {
        f->base.pMethods = NULL;
        return rc;
    }
    if (!real_io) {
        real_io = f->real->pMethods;
        faulty_io = (sqlite3_io_methods){.iVersion = 2 /* no memory-mapped fetches */,
                                         .xClose = f_close, .xRead = f_read, .xWrite = f_write,
                                         .xTruncate = f_truncate, .xSync = f_sync,
                                         .xFileSize = f_size, .xLock = f_lock,
                                         .xUnlock = f_unlock, .xCheckReservedLock = f_reserved,
                                         .xFileControl = f_control, .xSectorSize = f_sector,
                                         .xDeviceCharacteristics = f_device, .xShmMap = f_shm_map,
                                         .xShmLock = f_shm_lock, .xShmBarrier = f_shm_barrier,
                                         .xShmUnmap = f_shm_unmap};
    }
    f->base.pMethods = &faulty_io;
    return SQLITE_OK;
}

static void install_faulty_vfs(void)
{
    real_vfs = sqlite3_vfs_find(NULL);
    faulty_vfs = *real_vfs;
    faulty_vfs.zName = "archgram-faulty";
    faulty_vfs.szOsFile = (int)sizeof(faulty_file) + real_vfs->szOsFile;
    faulty_vfs.xOpen = f_open;
    assert_int_equal(sqlite3_vfs_register(&faulty_vfs, 1), SQLITE_OK);
}

/* --- the store ------------------------------------------------------------------------------ */

static char dir[64], path[128];

static ag_status insert_one(ag_db *db, const char *name, int64_t *id, ag_error *err)
{
    ag_mesh *m = ag_demo_building(1);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK)
        s = ag_store_ws_insert_model(db, name, m, "source bytes", 12, "obj", id, err);
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    ag_mesh_free(m);
    return s;
}

static int64_t count_models(ag_db *db)
{
    sqlite3_stmt *st = NULL;
    assert_int_equal(sqlite3_prepare_v2(ag_db_handle(db), "SELECT count(*) FROM models", -1, &st,
                                        NULL),
                     SQLITE_OK);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    int64_t n = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    return n;
}

static void assert_intact(ag_db *db)
{
    sqlite3_stmt *st = NULL;
    assert_int_equal(sqlite3_prepare_v2(ag_db_handle(db), "PRAGMA integrity_check", -1, &st, NULL),
                     SQLITE_OK);
    assert_int_equal(sqlite3_step(st), SQLITE_ROW);
    assert_string_equal((const char *)sqlite3_column_text(st, 0), "ok");
    sqlite3_finalize(st);
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/archgram-faults-XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/t.db", dir);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd);
}

static void io_errors_are_503_and_leave_the_store_whole(void **state)
{
    (void)state;
    ag_db *db = NULL;
    ag_error err;
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    int64_t id = 0;
    assert_int_equal(insert_one(db, "before", &id, &err), AG_OK);
    /* every write fails: the change is refused as the store's trouble, not the client's */
    atomic_store(&failing, 1);
    ag_status s = insert_one(db, "during", &id, &err);
    atomic_store(&failing, 0);
    assert_int_equal(s, AG_ERR_STORE_UNAVAILABLE);
    assert_int_equal(ag_status_http(s), 503);
    assert_non_null(strstr(err.text, "I/O") ? err.text : strstr(err.text, "disk"));
    /* nothing half-written, and it works again */
    assert_intact(db);
    assert_int_equal(count_models(db), 1);
    assert_int_equal(insert_one(db, "after", &id, &err), AG_OK);
    assert_int_equal(count_models(db), 2);
    ag_db_close(db);
    /* and a fresh connection sees the same */
    assert_int_equal(ag_db_open(path, NULL, &db, &err), AG_OK);
    assert_intact(db);
    assert_int_equal(count_models(db), 2);
    ag_model_row row;
    assert_int_equal(ag_models_get(db, id, &row, &err), AG_OK);
    assert_string_equal(row.name, "after");
    ag_models_row_clear(&row);
    ag_db_close(db);
}

static void a_full_database_is_507_and_keeps_what_it_had(void **state)
{
    (void)state;
    char full[160];
    snprintf(full, sizeof full, "%s/full.db", dir);
    ag_db *db = NULL;
    ag_error err;
    /* the cap leaves room for some models above what the schema itself takes, however many
     * migrations there are */
    assert_int_equal(ag_db_open(full, NULL, &db, &err), AG_OK);
    ag_db_close(db);
    struct stat st;
    assert_int_equal(stat(full, &st), 0);
    size_t cap = (size_t)st.st_size + (128 << 10);
    assert_int_equal(ag_db_open(full, &(ag_db_options){.max_bytes = cap}, &db, &err), AG_OK);
    int64_t id = 0, n = 0;
    ag_status s = AG_OK;
    for (int i = 0; i < 1000 && s == AG_OK; i++) {
        char name[32];
        snprintf(name, sizeof name, "model %d", i);
        if ((s = insert_one(db, name, &id, &err)) == AG_OK)
            n++;
    }
    assert_int_equal(s, AG_ERR_STORAGE_FULL);
    assert_int_equal(ag_status_http(s), 507);
    assert_true(n > 0);
    assert_intact(db);
    assert_int_equal(count_models(db), n);
    /* every model stored before is whole */
    ag_model_row row;
    assert_int_equal(ag_models_get(db, id, &row, &err), AG_OK);
    ag_models_row_clear(&row);
    ag_db_close(db);
    /* with room again (no cap), the same database takes more */
    assert_int_equal(ag_db_open(full, NULL, &db, &err), AG_OK);
    assert_int_equal(insert_one(db, "with room", &id, &err), AG_OK);
    assert_int_equal(count_models(db), n + 1);
    assert_intact(db);
    ag_db_close(db);
}

int main(void)
{
    install_faulty_vfs();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(io_errors_are_503_and_leave_the_store_whole),
        cmocka_unit_test(a_full_database_is_507_and_keeps_what_it_had),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
