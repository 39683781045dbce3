/* Accounts and tokens over REST: /api/v1/me (the caller's account and tokens) and
 * /api/v1/users (accounts, for admins). A token is in the answer that makes it, and nowhere
 * else ever again. */
#include <string.h>

#include "../app/accounts.h"
#include "routes.h"

/* The body as an object with only the given members (NULL-terminated); an empty body is {}
 * when optional. Answers the request itself and returns 0 when it is not. */
static int body_object(ag_request *r, int optional, const char *const *allowed, json_t **body,
                       enum MHD_Result *rc)
{
    ag_error err;
    *body = NULL;
    if (optional && r->body_len == 0) {
        *body = json_object();
        return 1;
    }
    ag_status s = ag_request_json(r, body, &err);
    const char *key;
    json_t *value;
    if (s == AG_OK)
        json_object_foreach(*body, key, value) {
            int known = 0;
            for (const char *const *a = allowed; *a; a++)
                known |= strcmp(*a, key) == 0;
            if (!known) {
                s = ag_error_set(&err, AG_ERR_INVALID, 0, "\"%.100s\" is not a member here", key);
                break;
            }
        }
    if (s == AG_OK)
        return 1;
    json_decref(*body);
    *body = NULL;
    *rc = ag_reply_problem(r, s, &err);
    return 0;
}

/* A string member or NULL; *bad when it is there but not a string. */
static const char *string_member(json_t *body, const char *name, int *bad)
{
    json_t *v = json_object_get(body, name);
    if (v && !json_is_string(v))
        *bad = 1;
    return json_string_value(v);
}

static enum MHD_Result reply(ag_request *r, ag_status s, json_t *view, unsigned status,
                             const ag_error *err)
{
    return s == AG_OK ? ag_reply_json(r, status, view, NULL) : ag_reply_problem(r, s, err);
}

enum MHD_Result ag_api_me(ag_request *r)
{
    ag_error err;
    json_t *view;
    ag_status s = ag_accounts_me(r->cfg->app, &r->who, &view, &err);
    return reply(r, s, view, 200, &err);
}

enum MHD_Result ag_api_me_tokens_list(ag_request *r)
{
    ag_error err;
    json_t *items;
    ag_status s = ag_accounts_tokens(r->cfg->app, &r->who, &items, &err);
    return reply(r, s, s == AG_OK ? json_pack("{s:o}", "items", items) : NULL, 200, &err);
}

/* POST …/tokens {"label"?}: a token of the account name. */
static enum MHD_Result new_token(ag_request *r, const char *name)
{
    static const char *const allowed[] = {"label", NULL};
    ag_error err;
    enum MHD_Result rc;
    json_t *body;
    if (!body_object(r, 1, allowed, &body, &rc))
        return rc;
    int bad = 0;
    const char *label = string_member(body, "label", &bad);
    json_t *view = NULL;
    ag_status s = bad ? ag_error_set(&err, AG_ERR_INVALID, 0, "\"label\" must be a string")
                      : ag_accounts_new_token(r->cfg->app, name, label, &view, &err);
    json_decref(body);
    return reply(r, s, view, 201, &err);
}

enum MHD_Result ag_api_me_tokens_create(ag_request *r)
{
    if (!r->who.user) {
        ag_error err;
        ag_error_set(&err, AG_ERR_CONFLICT, 0,
                     "archgramd runs without accounts (--no-auth): there are no tokens to make");
        return ag_reply_problem(r, AG_ERR_CONFLICT, &err);
    }
    return new_token(r, r->who.name);
}

enum MHD_Result ag_api_me_token_delete(ag_request *r)
{
    ag_error err;
    ag_status s = ag_accounts_revoke(r->cfg->app, &r->who, r->ids[0], &err);
    return s == AG_OK ? ag_reply_empty(r, 204, NULL) : ag_reply_problem(r, s, &err);
}

enum MHD_Result ag_api_users_list(ag_request *r)
{
    ag_error err;
    json_t *items;
    ag_status s = ag_accounts_list(r->cfg->app, &items, &err);
    return reply(r, s, s == AG_OK ? json_pack("{s:o}", "items", items) : NULL, 200, &err);
}

enum MHD_Result ag_api_users_create(ag_request *r)
{
    static const char *const allowed[] = {"name", "role", "label", NULL};
    ag_error err;
    enum MHD_Result rc;
    json_t *body;
    if (!body_object(r, 0, allowed, &body, &rc))
        return rc;
    int bad = 0;
    const char *name = string_member(body, "name", &bad);
    const char *role_text = string_member(body, "role", &bad);
    const char *label = string_member(body, "label", &bad);
    ag_account_role role = AG_ACCOUNT_EDITOR;
    json_t *view = NULL;
    ag_status s = AG_OK;
    if (bad || !name)
        s = ag_error_set(&err, AG_ERR_INVALID, 0,
                         "the body is {\"name\": …, \"role\"?: …, \"label\"?: …} with strings");
    else if (role_text)
        s = ag_auth_account_role_parse(role_text, &role, &err);
    if (s == AG_OK)
        s = ag_accounts_create(r->cfg->app, name, role, label, &view, &err);
    json_decref(body);
    return reply(r, s, view, 201, &err);
}

enum MHD_Result ag_api_user_tokens_create(ag_request *r)
{
    return new_token(r, r->name);
}
