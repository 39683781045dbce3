/* The users table: accounts, each with a unique name and an account role (what it may do
 * outside any one model; its role on a model is in store/members.h). */
#ifndef AG_USERS_H
#define AG_USERS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

#define AG_USER_NAME_MAX 64

typedef enum {
    AG_ACCOUNT_VIEWER = 1, /* reads what is shared with it */
    AG_ACCOUNT_EDITOR = 2, /* also creates models and writes the shared parts library */
    AG_ACCOUNT_ADMIN = 3,  /* everything: every model, the accounts */
} ag_account_role;

typedef struct {
    int64_t id;
    char name[AG_USER_NAME_MAX + 1];
    ag_account_role role;
    char created_at[32];
} ag_user_row;

/* "viewer", "editor", "admin". */
const char *ag_users_role_name(ag_account_role role);
ag_status ag_users_role_parse(const char *text, ag_account_role *role, ag_error *err);

/* An account name: 1..64 characters of A-Z a-z 0-9 . _ - beginning with a letter or a digit
 * (names appear in URL paths and as op authors). */
ag_status ag_users_check_name(const char *name, ag_error *err);

/* Inside the caller's transaction; AG_ERR_CONFLICT when the name is taken. */
ag_status ag_users_insert(ag_db *db, const char *name, ag_account_role role, int64_t *id,
                          ag_error *err);
ag_status ag_users_get(ag_db *db, int64_t id, ag_user_row *row, ag_error *err);
/* AG_ERR_NOT_FOUND "there is no account NAME". */
ag_status ag_users_find(ag_db *db, const char *name, ag_user_row *row, ag_error *err);
/* Accounts with id > after, ascending, at most limit; *rows is malloc'd. */
ag_status ag_users_list(ag_db *db, int64_t after, size_t limit, ag_user_row **rows,
                        size_t *count, ag_error *err);
/* How many accounts there are; -1 when it cannot be read. */
int64_t ag_users_count(ag_db *db);

#endif
