/* One SQLite connection per thread for one database file. A thread's first call opens its
 * connection (the schema as it is: only the first opener, ag_dbpool_create, migrates it);
 * later calls on that thread return the same one. Connections are closed by ag_dbpool_free:
 * threads are few and long-lived (request threads, workers), so keeping them costs little.
 *
 * A commit on a pool connection does not checkpoint (store/db.h no_autocheckpoint): the
 * pool's own thread copies the write-ahead log into the database file a few times a second,
 * so a writer's change is acknowledged as soon as it is in the log (durable: SQLite replays
 * the log after a crash). */
#ifndef AG_DBPOOL_H
#define AG_DBPOOL_H

#include "../core/status.h"
#include "../store/db.h"

typedef struct ag_dbpool ag_dbpool;

/* Creates and migrates the database at path (the first connection, closed again). */
ag_status ag_dbpool_create(const char *path, ag_dbpool **out, ag_error *err);
/* The same, every connection limited to max_bytes of database (0: none; store/db.h). */
ag_status ag_dbpool_create_ex(const char *path, size_t max_bytes, ag_dbpool **out,
                              ag_error *err);
void ag_dbpool_free(ag_dbpool *p);

/* This thread's connection; NULL with err filled when it cannot be opened. */
ag_db *ag_dbpool_get(ag_dbpool *p, ag_error *err);
const char *ag_dbpool_path(const ag_dbpool *p);

#endif
