/* /api/v1/models: list, upload (as an import job), read, rename, delete, geometry, op log. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/app_change.h"
#include "../app/app_jobs.h"
#include "../app/app_query.h"
#include "defer.h"
#include "routes.h"
#include "upload.h"

#define AG_PAGE_DEFAULT 50
#define AG_PAGE_MAX 200
#define AG_OPS_LIST_MAX 10000

static void version_etag(char *buf, size_t len, int64_t version)
{
    snprintf(buf, len, "\"%lld\"", (long long)version);
}

enum MHD_Result ag_api_models_list(ag_request *r)
{
    ag_error err;
    long long size;
    ag_status s = ag_request_query_int(r, "page_size", 1, AG_PAGE_MAX, AG_PAGE_DEFAULT, &size, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* Page tokens are "m" + the last id seen: opaque to clients, cheap to check. */
    long long after = 0;
    const char *token = ag_request_query(r, "page_token");
    if (token) {
        char *end;
        after = token[0] == 'm' ? strtoll(token + 1, &end, 10) : -1;
        if (token[0] != 'm' || !token[1] || *end || after < 0)
            return ag_reply_problem(r, AG_ERR_INVALID,
                                    (ag_error_set(&err, AG_ERR_INVALID, 0,
                                                  "page_token is not one this server gave out"),
                                     &err));
    }
    json_t *items;
    int more;
    if ((s = ag_app_query_models(r->cfg->app, &r->who, after, (size_t)size, &items, &more,
                                   &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *next = json_null();
    size_t n = json_array_size(items);
    if (more && n) {
        char buf[32];
        snprintf(buf, sizeof buf, "m%lld",
                 (long long)json_integer_value(json_object_get(json_array_get(items, n - 1), "id")));
        next = json_string(buf);
    }
    return ag_reply_json(r, 200, json_pack("{s:o, s:o}", "items", items, "next_page_token", next),
                         NULL);
}

enum MHD_Result ag_api_models_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    char name[1024];
    ag_upload_name(r, "model", name, sizeof name);
    ag_import_job p = {.name = name,
                       .format = (char *)ag_request_query(r, "format"),
                       .up = (char *)ag_request_query(r, "up"),
                       .filename = (char *)ag_upload_filename(r->upload)};
    ag_status s = ag_app_jobs_check_import(&p, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    if (ag_upload_bytes(r->upload) == 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0,
                     "the request has no file: send it as the body (or a multipart \"file\" part)");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    p.upload = (char *)ag_upload_take_path(r->upload);
    int64_t job = 0;
    s = ag_app_jobs_import(r->cfg->app, &r->who, &p, &job, &err);
    return ag_reply_new_job(r, s, job, &err);
}

enum MHD_Result ag_api_reply_model(ag_request *r, int64_t id, unsigned status)
{
    ag_error err;
    json_t *body;
    int64_t version;
    ag_status s = ag_app_query_model(r->cfg->app, id, &body, &version, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* the caller's role, found by the route's access check */
    json_object_set_new(body, "role", json_string(ag_auth_model_role_name(r->model_role)));
    char etag[32];
    version_etag(etag, sizeof etag, version);
    return ag_reply_json(r, status, body, etag);
}

void ag_api_answer_model(ag_request *r, int64_t id, unsigned status)
{
    ag_error err;
    json_t *body;
    int64_t version;
    ag_status s = ag_app_query_model(r->cfg->app, id, &body, &version, &err);
    if (s != AG_OK)
        return ag_defer_answer_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, version);
    ag_defer_answer_json(r, status, body, etag);
}

enum MHD_Result ag_api_model_get(ag_request *r)
{
    return ag_api_reply_model(r, r->ids[0], 200);
}

ag_status ag_api_precondition(ag_request *r, int required, int64_t *version, ag_error *err)
{
    *version = 0;
    if (!required && !ag_request_header(r, MHD_HTTP_HEADER_IF_MATCH))
        return AG_OK;
    ag_if_match m;
    ag_status s = ag_request_if_match(r, &m, err);
    if (s != AG_OK)
        return s;
    /* one version named: the change itself checks it, atomically */
    if (!m.any && m.n == 1 && m.tags == 1) {
        *version = m.versions[0];
        return AG_OK;
    }
    int64_t current;
    if ((s = ag_app_query_version(r->cfg->app, r->ids[0], &current, err)) != AG_OK)
        return s;
    return ag_request_if_match_check(&m, "model", r->ids[0], current, version, err);
}

/* What every change needs: the JSON body and the If-Match version. Returns 0 after answering
 * the request itself when one is missing. */
static int change_request(ag_request *r, json_t **body, int64_t *base, enum MHD_Result *rc)
{
    ag_error err;
    *body = NULL;
    ag_status s = ag_request_json(r, body, &err);
    if (s == AG_OK && (s = ag_api_precondition(r, 1, base, &err)) != AG_OK) {
        json_decref(*body);
        *body = NULL;
    }
    if (s != AG_OK) {
        *rc = ag_reply_problem(r, s, &err);
        return 0;
    }
    return 1;
}

enum MHD_Result ag_api_model_patch(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    json_t *body;
    int64_t base;
    if (!change_request(r, &body, &base, &rc))
        return rc;
    const char *key;
    json_t *value;
    json_object_foreach(body, key, value) {
        if (strcmp(key, "name") != 0) {
            json_decref(body);
            ag_error_set(&err, AG_ERR_INVALID, 0, "\"%s\" cannot be changed; only \"name\"", key);
            return ag_reply_problem(r, AG_ERR_INVALID, &err);
        }
    }
    const char *name = json_string_value(json_object_get(body, "name"));
    if (!name) {
        json_decref(body);
        ag_error_set(&err, AG_ERR_INVALID, 0, "the body needs a string \"name\"");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    json_t *op = json_pack("{s:s, s:s}", "kind", "rename", "name", name);
    json_decref(body);
    char cid[64];
    ag_request_fresh_cid("rest", cid, sizeof cid);
    int64_t version;
    int dup;
    ag_op_request rq = {.model = r->ids[0], .base = base, .author = ag_request_author(r),
                        .cid = cid, .op = op};
    ag_status s = ag_app_change_op(r->cfg->app, &rq, &version, &dup, &err);
    json_decref(op);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_api_reply_model(r, r->ids[0], 200);
}

enum MHD_Result ag_api_model_delete(ag_request *r)
{
    ag_error err;
    int64_t version;
    ag_status s = ag_api_precondition(r, 1, &version, &err);
    if (s == AG_OK)
        s = ag_app_change_delete(r->cfg->app, r->ids[0], version, &err);
    return s == AG_OK ? ag_reply_empty(r, 204, NULL) : ag_reply_problem(r, s, &err);
}

static int client_has(void *user, const char *etag)
{
    return ag_request_none_match(user, etag);
}

/* mesh.glb: a proceduralized model's components also carry their label and tree node. */
enum MHD_Result ag_api_model_mesh_glb(ag_request *r)
{
    ag_error err;
    ag_app_bytes glb;
    ag_status s = ag_app_query_glb(r->cfg->app, r->ids[0], client_has, r, &glb, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    if (!glb.data)
        return ag_reply_empty(r, 304, glb.etag);
    return ag_reply_bytes(r, 200, "model/gltf-binary", glb.data, glb.len, glb.etag);
}

enum MHD_Result ag_api_model_ops_list(ag_request *r)
{
    ag_error err;
    long long since;
    ag_status s = ag_request_query_int(r, "since", 0, (long long)1 << 62, 0, &since, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *items;
    int64_t version;
    if ((s = ag_app_query_ops(r->cfg->app, r->ids[0], since, AG_OPS_LIST_MAX, &items, &version,
                              &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, version);
    return ag_reply_json(r, 200, json_pack("{s:o}", "items", items), etag);
}

/* POST …/ops: the op applied (on a task worker for structural kinds). */
static void apply_op(ag_request *r, ag_task_budget *budget)
{
    ag_error err;
    ag_error_clear(&err);
    json_t *body = NULL;
    int64_t base;
    ag_status s = ag_request_json(r, &body, &err);
    if (s == AG_OK)
        s = ag_api_precondition(r, 1, &base, &err);
    if (s != AG_OK) {
        json_decref(body);
        return ag_defer_answer_problem(r, s, &err);
    }
    char generated[64];
    const char *cid = json_string_value(json_object_get(body, "cid"));
    if (!cid) {
        ag_request_fresh_cid("rest", generated, sizeof generated);
        cid = generated;
    }
    int64_t version;
    int dup;
    ag_op_request rq = {.model = r->ids[0], .base = base, .author = ag_request_author(r),
                        .cid = cid, .op = json_object_get(body, "op"), .budget = budget};
    s = ag_app_change_op(r->cfg->app, &rq, &version, &dup, &err);
    json_decref(body);
    if (s != AG_OK)
        return ag_defer_answer_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, version);
    ag_defer_answer_json(r, 200, json_pack("{s:I, s:b}", "version", (json_int_t)version,
                                           "duplicate", dup),
                         etag);
}

enum MHD_Result ag_api_model_ops_create(ag_request *r)
{
    enum MHD_Result rc;
    json_t *body;
    int64_t base;
    if (!change_request(r, &body, &base, &rc))
        return rc;
    /* what may take long runs on the model's task lane, the rest here */
    const ag_op_kind *row = ag_optable_find(
        json_string_value(json_object_get(json_object_get(body, "op"), "kind")));
    int structural = row && row->lane == AG_OP_STRUCTURAL && (row->flags & AG_OP_CLIENT);
    json_decref(body);
    return structural ? ag_defer_run(r, AG_TASK_OP, r->ids[0], apply_op)
                      : ag_defer_inline(r, apply_op);
}
