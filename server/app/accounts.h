/* Accounts and their API tokens: made at archgramd's first start, by its command line
 * (--create-user, --create-token) and by admins over REST; listed and revoked over REST. A
 * token is shown once, in the answer that makes it: only its hash is kept (store/tokens.h). */
#ifndef AG_ACCOUNTS_H
#define AG_ACCOUNTS_H

#include <jansson.h>
#include <stdint.h>

#include "../store/db.h"
#include "../store/tokens.h"
#include "../store/users.h"
#include "app.h"
#include "auth.h"

/* The admin account a first start makes. */
#define AG_ACCOUNTS_ADMIN "admin"
/* The label of the admin token read from --admin-token-file. */
#define AG_ACCOUNTS_FILE_LABEL "admin-token-file"

/* At start-up. Without chosen: when the database has no account, makes the admin account
 * "admin" with a new token: *made = 1 and token (AG_TOKEN_TEXT_MAX + 1 bytes) holds it, to be
 * shown once. With chosen (a token from --admin-token-file): the account "admin" (made when
 * missing) has that token, and earlier tokens from the file are revoked; nothing to show. */
ag_status ag_accounts_bootstrap(ag_db *db, const char *chosen, char *token, int *made,
                                ag_error *err);

/* A new account (role as in store/users.h) with a first token: *view gets
 * {"user": {name, role, created_at}, "token", "token_id", "label"}. AG_ERR_CONFLICT when the
 * name is taken. */
ag_status ag_accounts_create_in(ag_db *db, const char *name, ag_account_role role,
                                const char *label, json_t **view, ag_error *err);
/* Another token of the account name: *view gets {"user", "token", "token_id", "label"}. */
ag_status ag_accounts_new_token_in(ag_db *db, const char *name, const char *label,
                                   json_t **view, ag_error *err);

/* The same on the calling thread's connection of app, for the REST layer. */
ag_status ag_accounts_create(ag_app *app, const char *name, ag_account_role role,
                             const char *label, json_t **view, ag_error *err);
ag_status ag_accounts_new_token(ag_app *app, const char *name, const char *label,
                                json_t **view, ag_error *err);
/* {"name", "role", "created_at"} of who's account ("auth": false for the local identity). */
ag_status ag_accounts_me(ag_app *app, const ag_identity *who, json_t **view, ag_error *err);
/* Every account (at most 10,000), oldest first. */
ag_status ag_accounts_list(ag_app *app, json_t **items, ag_error *err);
/* An account's tokens, without their secrets: [{"id", "label", "created_at", "current"}]
 * (current: the token this request came with). */
ag_status ag_accounts_tokens(ag_app *app, const ag_identity *who, json_t **items,
                             ag_error *err);
/* Revokes one of who's tokens. */
ag_status ag_accounts_revoke(ag_app *app, const ag_identity *who, int64_t token,
                             ag_error *err);

#endif
