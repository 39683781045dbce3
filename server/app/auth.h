/* Who is asking and what they may do: the identity an API token stands for, an account's role
 * on a model, and the one access check that REST routes (by the need their row in the route
 * table declares) and the live layer (hello, ops, previews, watched jobs) go through.
 *
 * Roles: an admin account may do everything everywhere; on a model, an account has the role
 * it was given (store/members.h: the account that made a model owns it), else viewer when the
 * model is public-read, else none. A model or job someone may not see is answered as if it did
 * not exist (AG_ERR_NOT_FOUND); one they see but may not change is AG_ERR_FORBIDDEN. */
#ifndef AG_AUTH_H
#define AG_AUTH_H

#include <stdint.h>

#include "../store/members.h"
#include "../store/users.h"
#include "app.h"

typedef struct {
    int64_t user;  /* the account's id; 0 when no account stands behind it (--no-auth) */
    int64_t token; /* the id of the token it signed in with; 0 when none */
    char name[AG_USER_NAME_MAX + 1]; /* op author, presence name */
    ag_account_role role;
} ag_identity;

/* What a REST route or a live message needs of its caller. 0, a route row that declares
 * nothing, is for admins only, so a route cannot be opened up by forgetting to say. */
typedef enum {
    AG_NEED_UNDECLARED = 0,
    AG_NEED_NOTHING,      /* anyone, no token: the health check, the API document */
    AG_NEED_ACCOUNT,      /* any account (what it is shown is filtered for it) */
    AG_NEED_EDITOR,       /* an account whose role is editor or admin: creates models, writes
                             the shared parts library */
    AG_NEED_MODEL_VIEWER, /* a role on the model of the first {id} */
    AG_NEED_MODEL_EDITOR,
    AG_NEED_MODEL_OWNER,
    AG_NEED_JOB,          /* the account that asked for the job of the first {id} */
    AG_NEED_ADMIN,
} ag_need;

/* The identity of everyone when archgramd runs without accounts (--no-auth, loopback only):
 * a local admin named "local". */
void ag_auth_local(ag_identity *who);

/* The account a token stands for. AG_ERR_UNAUTHORIZED when no account has this token.
 *
 * What a check finds is remembered for AG_AUTH_REMEMBER_S seconds — a token's account (by the
 * token's hash, compared in constant time) and an account's role on a model — so most requests
 * cost a hash and no query (a query is about a third of what GET /api/v1/models/{id} costs:
 * bench/auth.c). ag_auth_forget drops it all: this process calls it after every revocation,
 * sharing change and deletion, so they count at once; a change another process makes to the
 * database (none but archgramd's own change these tables) counts within those seconds. */
#define AG_AUTH_REMEMBER_S 5
ag_status ag_auth_token(ag_app *app, const char *token, ag_identity *who, ag_error *err);
void ag_auth_forget(ag_app *app);

/* What ag_auth_token remembers, one per app (app.c makes it). */
typedef struct ag_auth_cache ag_auth_cache;
ag_auth_cache *ag_auth_cache_create(void);
void ag_auth_cache_free(ag_auth_cache *cache);

/* Checks need for who on the model or job id (ignored by needs without one); *role (may be
 * NULL) gets who's role on the model for the model needs (owner for admins). */
ag_status ag_auth_check(ag_app *app, const ag_identity *who, ag_need need, int64_t id,
                        ag_model_role *role, ag_error *err);

/* The role rule itself, for a caller that read the model's membership already. */
ag_model_role ag_auth_role(const ag_identity *who, ag_model_role member, int public_read);

/* The names of roles as the API spells them ("owner", "editor", "viewer"; "admin" ...), for the
 * layers above the store. */
const char *ag_auth_model_role_name(ag_model_role role);
ag_status ag_auth_account_role_parse(const char *text, ag_account_role *role, ag_error *err);

#endif
