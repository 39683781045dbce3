/* Schema migrations: an ordered list of SQL scripts; PRAGMA user_version counts how many
 * have been applied. Each script runs in its own BEGIN IMMEDIATE transaction together with
 * the user_version bump, so a failing script leaves the database as it was. */
#ifndef AG_MIGRATE_H
#define AG_MIGRATE_H

#include <stddef.h>
#include <sqlite3.h>

#include "../core/status.h"
#include "../embedded.h"

/* Applies list[user_version .. n-1]. A database whose user_version is larger than n was
 * written by a newer archgram: AG_ERR_DB_TOO_NEW, nothing touched. */
ag_status ag_migrate(sqlite3 *db, const struct ag_migration *list, size_t n, ag_error *err);
int ag_migrate_user_version(sqlite3 *db);

#endif
