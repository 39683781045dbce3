#include "users.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const role_names[] = {NULL, "viewer", "editor", "admin"};

const char *ag_users_role_name(ag_account_role role)
{
    return role >= AG_ACCOUNT_VIEWER && role <= AG_ACCOUNT_ADMIN ? role_names[role] : "viewer";
}

ag_status ag_users_role_parse(const char *text, ag_account_role *role, ag_error *err)
{
    for (int r = AG_ACCOUNT_VIEWER; text && r <= AG_ACCOUNT_ADMIN; r++)
        if (strcmp(text, role_names[r]) == 0) {
            *role = (ag_account_role)r;
            return AG_OK;
        }
    return ag_error_set(err, AG_ERR_INVALID, 0,
                        "an account's role is \"admin\", \"editor\" or \"viewer\"");
}

static int name_char(char c, int first)
{
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))
        return 1;
    return !first && (c == '.' || c == '_' || c == '-');
}

ag_status ag_users_check_name(const char *name, ag_error *err)
{
    if (!name || !*name)
        return ag_error_set(err, AG_ERR_INVALID, 0, "an account needs a name");
    size_t n = strlen(name);
    if (n > AG_USER_NAME_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "an account name has at most %d characters", AG_USER_NAME_MAX);
    for (size_t i = 0; i < n; i++)
        if (!name_char(name[i], i == 0))
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "an account name holds letters, digits, '.', '_' and '-' and "
                                "begins with a letter or a digit");
    return AG_OK;
}

ag_status ag_users_insert(ag_db *db, const char *name, ag_account_role role, int64_t *id,
                          ag_error *err)
{
    ag_status s = ag_users_check_name(name, err);
    if (s != AG_OK)
        return s;
    ag_user_row existing;
    if (ag_users_find(db, name, &existing, NULL) == AG_OK)
        return ag_error_set(err, AG_ERR_CONFLICT, 0, "there is an account %s already", name);
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st, "INSERT INTO users (name, role) VALUES (?, ?)", err)) !=
        AG_OK)
        return s;
    sqlite3_bind_text(st, 1, name, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, ag_users_role_name(role), -1, SQLITE_STATIC);
    if ((s = ag_db_step_done(db, st, "creating an account", err)) != AG_OK)
        return s;
    *id = sqlite3_last_insert_rowid(ag_db_handle(db));
    return AG_OK;
}

#define USER_COLUMNS "id, name, role, created_at"

static void read_row(sqlite3_stmt *st, ag_user_row *row)
{
    memset(row, 0, sizeof *row);
    row->id = sqlite3_column_int64(st, 0);
    ag_db_column_copy(st, 1, row->name, sizeof row->name);
    const char *role = (const char *)sqlite3_column_text(st, 2);
    if (ag_users_role_parse(role, &row->role, NULL) != AG_OK)
        row->role = AG_ACCOUNT_VIEWER; /* the schema allows no other value; be strict anyway */
    ag_db_column_copy(st, 3, row->created_at, sizeof row->created_at);
}

static ag_status get_one(ag_db *db, sqlite3_stmt *st, ag_user_row *row, const char *missing,
                         ag_error *err)
{
    int rc = sqlite3_step(st);
    ag_status s = AG_OK;
    if (rc == SQLITE_ROW)
        read_row(st, row);
    else if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no account %s", missing);
    else
        s = ag_db_fail(db, err, "reading an account");
    sqlite3_reset(st);
    return s;
}

ag_status ag_users_get(ag_db *db, int64_t id, ag_user_row *row, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "SELECT " USER_COLUMNS " FROM users WHERE id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    char missing[32];
    snprintf(missing, sizeof missing, "#%lld", (long long)id);
    return get_one(db, st, row, missing, err);
}

ag_status ag_users_find(ag_db *db, const char *name, ag_user_row *row, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s =
        ag_db_prepared(db, &st, "SELECT " USER_COLUMNS " FROM users WHERE name = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
    char missing[AG_USER_NAME_MAX + 1];
    snprintf(missing, sizeof missing, "%s", name);
    return get_one(db, st, row, missing, err);
}

ag_status ag_users_list(ag_db *db, int64_t after, size_t limit, ag_user_row **rows,
                        size_t *count, ag_error *err)
{
    *rows = NULL;
    *count = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "SELECT " USER_COLUMNS " FROM users WHERE id > ? ORDER BY id LIMIT ?", err);
    if (s != AG_OK)
        return s;
    ag_user_row *out = calloc(limit ? limit : 1, sizeof *out);
    if (!out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory listing accounts");
    sqlite3_bind_int64(st, 1, after);
    sqlite3_bind_int64(st, 2, (sqlite3_int64)limit);
    size_t n = 0;
    int rc = SQLITE_DONE;
    while (n < limit && (rc = sqlite3_step(st)) == SQLITE_ROW)
        read_row(st, &out[n++]);
    if (n < limit && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "listing accounts");
    sqlite3_reset(st);
    if (s != AG_OK) {
        free(out);
        return s;
    }
    *rows = out;
    *count = n;
    return AG_OK;
}

int64_t ag_users_count(ag_db *db)
{
    sqlite3_stmt *st = ag_db_prepare(db, "SELECT count(*) FROM users", NULL);
    int64_t n = -1;
    if (st && sqlite3_step(st) == SQLITE_ROW)
        n = sqlite3_column_int64(st, 0);
    if (st)
        sqlite3_reset(st);
    return n;
}
