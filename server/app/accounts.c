#include "accounts.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sodium.h>

#define LIST_MAX 10000

static json_t *user_view(const ag_user_row *u)
{
    return json_pack("{s:s, s:s, s:s}", "name", u->name, "role", ag_users_role_name(u->role),
                     "created_at", u->created_at);
}

static json_t *token_view(const ag_user_row *u, const char *token, int64_t id,
                          const char *label)
{
    return json_pack("{s:o, s:s, s:I, s:s}", "user", user_view(u), "token", token, "token_id",
                     (json_int_t)id, "label", label ? label : "");
}

static ag_status commit_or_rollback(ag_db *db, ag_status s, ag_error *err)
{
    return s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
}

ag_status ag_accounts_bootstrap(ag_db *db, const char *chosen, char *token, int *made,
                                ag_error *err)
{
    *made = 0;
    token[0] = '\0';
    if (chosen && ag_tokens_check_text(chosen, err) != AG_OK)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "the admin token file must hold one token of 32 to %d characters "
                            "of A-Z a-z 0-9 . _ ~ + -",
                            AG_TOKEN_TEXT_MAX);
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    int64_t accounts = ag_users_count(db);
    if (accounts < 0)
        s = ag_db_fail(db, err, "counting accounts");
    if (s != AG_OK || (!chosen && accounts > 0)) {
        ag_db_rollback(db);
        return s;
    }
    ag_user_row admin;
    s = ag_users_find(db, AG_ACCOUNTS_ADMIN, &admin, err);
    if (s == AG_ERR_NOT_FOUND &&
        (s = ag_users_insert(db, AG_ACCOUNTS_ADMIN, AG_ACCOUNT_ADMIN, &admin.id, err)) == AG_OK)
        s = ag_users_get(db, admin.id, &admin, err);
    if (s == AG_OK && admin.role != AG_ACCOUNT_ADMIN)
        s = ag_error_set(err, AG_ERR_CONFLICT, 0, "the account %s is not an admin",
                         AG_ACCOUNTS_ADMIN);
    int64_t id = 0;
    if (s == AG_OK && !chosen) {
        s = ag_tokens_create(db, admin.id, "first start", token, &id, err);
        *made = s == AG_OK;
    } else if (s == AG_OK) {
        int64_t owner = 0;
        int removed = 0;
        if (ag_tokens_verify(db, chosen, &owner, &id, NULL, NULL) != AG_OK)
            s = ag_tokens_add(db, admin.id, chosen, AG_ACCOUNTS_FILE_LABEL, &id, err);
        else if (owner != admin.id)
            s = ag_error_set(err, AG_ERR_CONFLICT, 0,
                             "the admin token file holds a token of another account");
        if (s == AG_OK)
            s = ag_tokens_delete_label(db, admin.id, AG_ACCOUNTS_FILE_LABEL, id, &removed, err);
    }
    s = commit_or_rollback(db, s, err);
    if (s != AG_OK) {
        *made = 0;
        token[0] = '\0';
    }
    return s;
}

/* In one transaction: the account name (made first when make) gets a new token; *view the
 * answer that shows it. */
static ag_status token_for(ag_db *db, const char *name, int make, ag_account_role role,
                           const char *label, json_t **view, ag_error *err)
{
    *view = NULL;
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    int64_t user = 0, id = 0;
    char token[AG_TOKEN_TEXT_MAX + 1] = "";
    ag_user_row row;
    if (make)
        s = ag_users_insert(db, name, role, &user, err);
    if (s == AG_OK)
        s = ag_users_find(db, name, &row, err);
    if (s == AG_OK)
        s = ag_tokens_create(db, row.id, label, token, &id, err);
    if (s == AG_OK && !(*view = token_view(&row, token, id, label)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    s = commit_or_rollback(db, s, err);
    if (s != AG_OK) {
        json_decref(*view);
        *view = NULL;
    }
    sodium_memzero(token, sizeof token);
    return s;
}

ag_status ag_accounts_create_in(ag_db *db, const char *name, ag_account_role role,
                                const char *label, json_t **view, ag_error *err)
{
    return token_for(db, name, 1, role, label, view, err);
}

ag_status ag_accounts_new_token_in(ag_db *db, const char *name, const char *label,
                                   json_t **view, ag_error *err)
{
    return token_for(db, name, 0, AG_ACCOUNT_VIEWER, label, view, err);
}

#define DB_OR_RETURN(db, app, err)                                                              \
    ag_db *db = ag_app_db(app, err);                                                           \
    if (!db)                                                                                   \
    return err ? err->code : AG_ERR_DB

ag_status ag_accounts_create(ag_app *app, const char *name, ag_account_role role,
                             const char *label, json_t **view, ag_error *err)
{
    *view = NULL;
    DB_OR_RETURN(db, app, err);
    return ag_accounts_create_in(db, name, role, label, view, err);
}

ag_status ag_accounts_new_token(ag_app *app, const char *name, const char *label,
                                json_t **view, ag_error *err)
{
    *view = NULL;
    DB_OR_RETURN(db, app, err);
    return ag_accounts_new_token_in(db, name, label, view, err);
}

ag_status ag_accounts_me(ag_app *app, const ag_identity *who, json_t **view, ag_error *err)
{
    *view = NULL;
    if (!who->user) {
        *view = json_pack("{s:s, s:s, s:b}", "name", who->name, "role",
                          ag_users_role_name(who->role), "auth", 0);
        return *view ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    DB_OR_RETURN(db, app, err);
    ag_user_row row;
    ag_status s = ag_users_get(db, who->user, &row, err);
    if (s != AG_OK)
        return s;
    *view = user_view(&row);
    if (*view)
        json_object_set_new(*view, "auth", json_true());
    return *view ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

ag_status ag_accounts_list(ag_app *app, json_t **items, ag_error *err)
{
    *items = NULL;
    DB_OR_RETURN(db, app, err);
    ag_user_row *rows;
    size_t n;
    ag_status s = ag_users_list(db, 0, LIST_MAX, &rows, &n, err);
    if (s != AG_OK)
        return s;
    json_t *list = json_array();
    for (size_t i = 0; list && i < n; i++)
        json_array_append_new(list, user_view(&rows[i]));
    free(rows);
    *items = list;
    return list ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

ag_status ag_accounts_tokens(ag_app *app, const ag_identity *who, json_t **items,
                             ag_error *err)
{
    *items = NULL;
    DB_OR_RETURN(db, app, err);
    ag_token_row *rows;
    size_t n;
    ag_status s = ag_tokens_list(db, who->user, LIST_MAX, &rows, &n, err);
    if (s != AG_OK)
        return s;
    json_t *list = json_array();
    for (size_t i = 0; list && i < n; i++)
        json_array_append_new(list, json_pack("{s:I, s:s, s:s, s:b}", "id", (json_int_t)rows[i].id,
                                              "label", rows[i].label, "created_at",
                                              rows[i].created_at, "current",
                                              rows[i].id == who->token));
    free(rows);
    *items = list;
    return list ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

ag_status ag_accounts_revoke(ag_app *app, const ag_identity *who, int64_t token, ag_error *err)
{
    DB_OR_RETURN(db, app, err);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK)
        s = commit_or_rollback(db, ag_tokens_delete(db, who->user, token, err), err);
    if (s == AG_OK)
        ag_auth_forget(app); /* a revoked token signs nobody in from now on */
    return s;
}
