#include "dbpool.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* How often the log is copied into the database, and the log size past which the copy waits
 * for writers to let it finish (a log that writers keep ahead of the copy would otherwise
 * never start over). */
#define CHECKPOINT_EVERY_MS 100
#define CHECKPOINT_RESTART_BYTES ((long long)256 << 20)

struct ag_dbpool {
    char *path;
    size_t max_bytes;
    pthread_key_t key;
    pthread_mutex_t lock;
    ag_db **conns; /* every connection opened, closed at free */
    size_t n, cap;
    /* the checkpoint thread and its connection */
    pthread_t checkpointer;
    int has_checkpointer, stop;
    pthread_cond_t wake;
    ag_db *checkpoint_db;
};

static void *checkpoint_loop(void *arg)
{
    ag_dbpool *p = arg;
    long long page = 4096;
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(ag_db_handle(p->checkpoint_db), "PRAGMA page_size", -1, &st, NULL) ==
            SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW && sqlite3_column_int64(st, 0) > 0)
        page = sqlite3_column_int64(st, 0);
    sqlite3_finalize(st);
    pthread_mutex_lock(&p->lock);
    while (!p->stop) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += CHECKPOINT_EVERY_MS * 1000000L;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec++;
            until.tv_nsec -= 1000000000L;
        }
        int rc = 0;
        while (!p->stop && rc != ETIMEDOUT)
            rc = pthread_cond_timedwait(&p->wake, &p->lock, &until);
        if (p->stop)
            break;
        pthread_mutex_unlock(&p->lock);
        int pending = 0;
        ag_db_checkpoint(p->checkpoint_db, &pending, NULL); /* a failure is tried again */
        if ((long long)pending * page > CHECKPOINT_RESTART_BYTES)
            sqlite3_wal_checkpoint_v2(ag_db_handle(p->checkpoint_db), NULL,
                                      SQLITE_CHECKPOINT_RESTART, NULL, NULL);
        pthread_mutex_lock(&p->lock);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

static void forget_thread_db(void *db)
{
    (void)db; /* connections belong to the pool's list; nothing to do at thread exit */
}

ag_status ag_dbpool_create(const char *path, ag_dbpool **out, ag_error *err)
{
    return ag_dbpool_create_ex(path, 0, out, err);
}

ag_status ag_dbpool_create_ex(const char *path, size_t max_bytes, ag_dbpool **out,
                              ag_error *err)
{
    *out = NULL;
    ag_dbpool *p = calloc(1, sizeof *p);
    if (!p || !(p->path = strdup(path))) {
        free(p);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    p->max_bytes = max_bytes;
    /* The first connection creates and migrates the schema; the others only open it. */
    ag_db *db = NULL;
    ag_status s = ag_db_open(path, &(ag_db_options){.max_bytes = max_bytes}, &db, err);
    if (s != AG_OK) {
        free(p->path);
        free(p);
        return s;
    }
    ag_db_close(db);
    pthread_key_create(&p->key, forget_thread_db);
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->wake, NULL);
    if ((s = ag_db_open(path, &(ag_db_options){.no_migrate = 1, .no_autocheckpoint = 1},
                        &p->checkpoint_db, err)) != AG_OK) {
        ag_dbpool_free(p);
        return s;
    }
    p->has_checkpointer = pthread_create(&p->checkpointer, NULL, checkpoint_loop, p) == 0;
    if (!p->has_checkpointer) {
        ag_dbpool_free(p);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "cannot start the checkpoint thread");
    }
    *out = p;
    return AG_OK;
}

ag_db *ag_dbpool_get(ag_dbpool *p, ag_error *err)
{
    ag_db *db = pthread_getspecific(p->key);
    if (db)
        return db;
    if (ag_db_open(p->path,
                   &(ag_db_options){.no_migrate = 1, .max_bytes = p->max_bytes,
                                    .no_autocheckpoint = 1},
                   &db, err) != AG_OK)
        return NULL;
    pthread_mutex_lock(&p->lock);
    if (p->n == p->cap) {
        size_t cap = p->cap ? p->cap * 2 : 16;
        ag_db **grown = realloc(p->conns, cap * sizeof *grown);
        if (!grown) {
            pthread_mutex_unlock(&p->lock);
            ag_db_close(db);
            ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory opening a connection");
            return NULL;
        }
        p->conns = grown;
        p->cap = cap;
    }
    p->conns[p->n++] = db;
    pthread_mutex_unlock(&p->lock);
    pthread_setspecific(p->key, db);
    return db;
}

const char *ag_dbpool_path(const ag_dbpool *p) { return p->path; }

void ag_dbpool_free(ag_dbpool *p)
{
    if (!p)
        return;
    if (p->has_checkpointer) {
        pthread_mutex_lock(&p->lock);
        p->stop = 1;
        pthread_cond_signal(&p->wake);
        pthread_mutex_unlock(&p->lock);
        pthread_join(p->checkpointer, NULL);
    }
    ag_db_close(p->checkpoint_db); /* the last of the connections closed below copies what is
                                    * left in the log */
    pthread_cond_destroy(&p->wake);
    for (size_t i = 0; i < p->n; i++)
        ag_db_close(p->conns[i]);
    free(p->conns);
    pthread_key_delete(p->key);
    pthread_mutex_destroy(&p->lock);
    free(p->path);
    free(p);
}
