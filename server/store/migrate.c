#include "migrate.h"

#include <stdio.h>

int ag_migrate_user_version(sqlite3 *db)
{
    sqlite3_stmt *st = NULL;
    int v = -1;
    if (sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        v = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    return v;
}

static ag_status apply_one(sqlite3 *db, const struct ag_migration *m, size_t index, ag_error *err)
{
    char *msg = NULL;
    if (sqlite3_exec(db, "BEGIN IMMEDIATE", NULL, NULL, &msg) != SQLITE_OK)
        goto fail;
    /* Re-read inside the write lock: another process may have migrated meanwhile. */
    if ((size_t)ag_migrate_user_version(db) != index) {
        sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
        return AG_OK;
    }
    if (sqlite3_exec(db, m->sql, NULL, NULL, &msg) != SQLITE_OK)
        goto fail_tx;
    char bump[64];
    snprintf(bump, sizeof bump, "PRAGMA user_version = %zu", index + 1);
    if (sqlite3_exec(db, bump, NULL, NULL, &msg) != SQLITE_OK ||
        sqlite3_exec(db, "COMMIT", NULL, NULL, &msg) != SQLITE_OK)
        goto fail_tx;
    return AG_OK;
fail_tx:
    sqlite3_exec(db, "ROLLBACK", NULL, NULL, NULL);
fail:
    ag_error_set(err, AG_ERR_DB, (long)index + 1, "migration %s failed: %s", m->name,
                 msg ? msg : sqlite3_errmsg(db));
    sqlite3_free(msg);
    return AG_ERR_DB;
}

ag_status ag_migrate(sqlite3 *db, const struct ag_migration *list, size_t n, ag_error *err)
{
    int have = ag_migrate_user_version(db);
    if (have < 0)
        return ag_error_set(err, AG_ERR_DB, 0, "cannot read the schema version: %s",
                            sqlite3_errmsg(db));
    if ((size_t)have > n)
        return ag_error_set(err, AG_ERR_DB_TOO_NEW, have,
                            "the database has schema version %d but this archgram knows only "
                            "%zu; use a newer archgram",
                            have, n);
    for (size_t i = (size_t)have; i < n; i++) {
        ag_status s = apply_one(db, &list[i], i, err);
        if (s != AG_OK)
            return s;
    }
    return AG_OK;
}
