/* Point cloud models over REST: POST …/segment (a job), GET …/points.ply,
 * …/points.glb?budget=N and, once proceduralized, …/derived.ply[?budget=N]. Uploads are POST /api/v1/models (api_models.c); ROI refinement and
 * template marking are ops (POST …/ops). */
#include <stdlib.h>

#include "../app/app_jobs.h"
#include "../app/app_points.h"
#include "routes.h"

#define BUDGET_MAX 100000000LL

enum MHD_Result ag_api_model_segment(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    json_t *body = NULL;
    ag_status s = r->body_len ? ag_request_json(r, &body, &err) : AG_OK;
    if (s == AG_OK && !body && !(body = json_object()))
        s = ag_error_set(&err, AG_ERR_NOMEM, 0, "out of memory");
    int64_t version = 0;
    if (s == AG_OK)
        s = ag_api_precondition(r, 0, &version, &err);
    int64_t job = 0;
    if (s == AG_OK)
        s = ag_app_jobs_segment(r->cfg->app, &r->who, r->ids[0], version ? &version : NULL, body,
                                &job, &err);
    json_decref(body);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_new_job(r, s, job, &err);
}

static int client_has(void *user, const char *etag)
{
    return ag_request_none_match(user, etag);
}

static enum MHD_Result reply(ag_request *r, ag_status s, ag_app_bytes *b, const char *type,
                             ag_error *err)
{
    if (s != AG_OK)
        return ag_reply_problem(r, s, err);
    if (!b->data)
        return ag_reply_empty(r, 304, b->etag);
    return ag_reply_bytes(r, 200, type, b->data, b->len, b->etag);
}

enum MHD_Result ag_api_model_points_ply(ag_request *r)
{
    ag_error err;
    ag_app_bytes b;
    ag_status s = ag_app_points_ply(r->cfg->app, r->ids[0], client_has, r, &b, &err);
    return reply(r, s, &b, "application/x-ply", &err);
}

enum MHD_Result ag_api_model_derived_ply(ag_request *r)
{
    ag_error err;
    ag_app_bytes b = {0};
    long long budget = 0; /* 0: every point */
    ag_status s = ag_request_query_int(r, "budget", 0, BUDGET_MAX, 0, &budget, &err);
    if (s == AG_OK)
        s = ag_app_points_derived_ply(r->cfg->app, r->ids[0], (size_t)budget, client_has, r,
                                      &b, &err);
    return reply(r, s, &b, "application/x-ply", &err);
}

enum MHD_Result ag_api_model_points_glb(ag_request *r)
{
    ag_error err;
    long long budget = 0;
    ag_app_bytes b = {0};
    ag_status s = ag_request_query_int(r, "budget", 1, BUDGET_MAX,
                                       (long long)AG_POINTS_GLB_DEFAULT_BUDGET, &budget, &err);
    if (s == AG_OK)
        s = ag_app_points_glb(r->cfg->app, r->ids[0], (size_t)budget, client_has, r, &b, &err);
    return reply(r, s, &b, "model/gltf-binary", &err);
}
