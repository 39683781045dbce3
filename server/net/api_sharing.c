/* Who may use a model: GET …/members, PUT and DELETE …/members/{name}, PUT …/public. The
 * route table lets only owners change it; each answers the model's sharing as it is then. */
#include "../app/sharing.h"
#include "routes.h"

static enum MHD_Result reply(ag_request *r, ag_status s, json_t *doc, const ag_error *err)
{
    return s == AG_OK ? ag_reply_json(r, 200, doc, NULL) : ag_reply_problem(r, s, err);
}

enum MHD_Result ag_api_model_members(ag_request *r)
{
    ag_error err;
    json_t *doc;
    ag_status s = ag_sharing_get(r->cfg->app, r->ids[0], &doc, &err);
    return reply(r, s, doc, &err);
}

/* The body's one member `name` of the given JSON type; answers the request itself and
 * returns NULL when the body is anything else. */
static json_t *only_member(ag_request *r, const char *name, json_type type, const char *shape,
                           json_t **body, enum MHD_Result *rc)
{
    ag_error err;
    ag_status s = ag_request_json(r, body, &err);
    json_t *v = s == AG_OK ? json_object_get(*body, name) : NULL;
    if (s == AG_OK && (!v || json_typeof(v) != type || json_object_size(*body) != 1))
        s = ag_error_set(&err, AG_ERR_INVALID, 0, "the body is %s", shape);
    if (s == AG_OK)
        return v;
    json_decref(*body);
    *body = NULL;
    *rc = ag_reply_problem(r, s, &err);
    return NULL;
}

enum MHD_Result ag_api_model_member_put(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc = MHD_NO;
    json_t *body, *doc = NULL;
    json_t *role = only_member(r, "role", JSON_STRING,
                               "{\"role\": \"owner\" | \"editor\" | \"viewer\"}", &body, &rc);
    if (!role)
        return rc;
    ag_status s = ag_sharing_put(r->cfg->app, r->ids[0], r->name, json_string_value(role), &doc,
                                 &err);
    json_decref(body);
    return reply(r, s, doc, &err);
}

enum MHD_Result ag_api_model_member_delete(ag_request *r)
{
    ag_error err;
    json_t *doc;
    ag_status s = ag_sharing_remove(r->cfg->app, r->ids[0], r->name, &doc, &err);
    return reply(r, s, doc, &err);
}

enum MHD_Result ag_api_model_public_put(ag_request *r)
{
    ag_error err;
    json_t *body = NULL, *doc = NULL, *on = NULL;
    ag_status s = ag_request_json(r, &body, &err);
    if (s == AG_OK && (!json_is_boolean(on = json_object_get(body, "public_read")) ||
                       json_object_size(body) != 1))
        s = ag_error_set(&err, AG_ERR_INVALID, 0, "the body is {\"public_read\": true | false}");
    if (s == AG_OK)
        s = ag_sharing_set_public(r->cfg->app, r->ids[0], json_is_true(on), &doc, &err);
    json_decref(body);
    return reply(r, s, doc, &err);
}
