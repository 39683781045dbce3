/* Proceduralization over REST: POST …/proceduralize (a job), GET …/tree, GET and PUT
 * …/grammar. (mesh.glb, with each component's label and split-tree node: api_models.c.) */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../app/app_change.h"
#include "../app/app_jobs.h"
#include "../app/app_query.h"
#include "../app/problem.h"
#include "defer.h"
#include "routes.h"
#include "upload.h"

/* The If-Match version of a change to the model at `current` (AG_ERR_STALE otherwise); with
 * required = 0 an absent header is fine (*version = 0). */
static ag_status if_match(ag_request *r, int required, int64_t current, int64_t *version,
                          ag_error *err)
{
    *version = 0;
    if (!required && !ag_request_header(r, MHD_HTTP_HEADER_IF_MATCH))
        return AG_OK;
    ag_if_match m;
    ag_status s = ag_request_if_match(r, &m, err);
    return s != AG_OK ? s
                      : ag_request_if_match_check(&m, "model", r->ids[0], current, version, err);
}

enum MHD_Result ag_api_model_proceduralize(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    /* an empty body, {} or a mesh's {"exact": true|false, "unit": "mm"}; any other member
     * goes to the app, which knows a point cloud's options (app/points_proc_options.h) */
    ag_app_mesh_proc_options mesh = {0};
    json_t *cloud = NULL, *body = NULL;
    if (r->body_len) {
        ag_status s = ag_request_json(r, &body, &err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &err);
        const char *key = NULL;
        json_t *v;
        json_object_foreach(body, key, v) {
            if (!strcmp(key, "exact")) {
                if (!json_is_boolean(v)) {
                    ag_error_set(&err, AG_ERR_INVALID, 0, "\"exact\" takes true or false");
                    break;
                }
                mesh.exact = json_is_true(v);
            } else if (!strcmp(key, "unit")) {
                /* not a string: no unit's name, which the app refuses naming the units */
                mesh.unit = json_is_string(v) ? json_string_value(v) : "";
            } else {
                if (!cloud)
                    cloud = json_object();
                json_object_set(cloud, key, v);
            }
        }
        if (err.code != AG_OK) {
            json_decref(cloud);
            json_decref(body);
            return ag_reply_problem(r, AG_ERR_INVALID, &err);
        }
    }
    int64_t current, base;
    ag_status s = ag_app_query_version(r->cfg->app, r->ids[0], &current, &err);
    if (s == AG_OK)
        s = if_match(r, 0, current, &base, &err);
    int64_t job = 0;
    if (s == AG_OK)
        s = ag_app_jobs_proceduralize(r->cfg->app, &r->who, r->ids[0], &current, &mesh, cloud,
                                      &job, &err);
    json_decref(cloud);
    json_decref(body); /* after the job took mesh.unit */
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_new_job(r, s, job, &err);
}

enum MHD_Result ag_api_model_tree(ag_request *r)
{
    ag_error err;
    char *json;
    size_t len;
    int64_t version;
    ag_status s = ag_app_query_tree(r->cfg->app, r->ids[0], &json, &len, &version, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)version);
    return ag_reply_bytes(r, 200, "application/json", json, len, etag);
}

enum MHD_Result ag_api_model_grammar_get(ag_request *r)
{
    ag_error err;
    char *text;
    size_t len;
    int64_t version;
    ag_status s = ag_app_query_grammar(r->cfg->app, r->ids[0], &text, &len, &version, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)version);
    return ag_reply_bytes(r, 200, "text/plain; charset=utf-8", text, len, etag);
}

/* A parse problem with "line" and "column" as members, and in the detail. */
static void answer_parse_problem(ag_request *r, ag_error *err, long col)
{
    long line = err->element > 0 ? err->element : 1;
    if (col < 1)
        col = 1;
    char msg[AG_ERROR_TEXT];
    snprintf(msg, sizeof msg, "%s", err->text);
    ag_error_set(err, AG_ERR_PARSE, line, "line %ld, column %ld: %s", line, col, msg);
    json_t *p = ag_problem_json(AG_ERR_PARSE, err);
    if (p) {
        json_object_set_new(p, "line", json_integer(line));
        json_object_set_new(p, "column", json_integer(col));
    }
    char *body = p ? json_dumps(p, JSON_COMPACT) : NULL;
    json_decref(p);
    if (!body)
        return ag_defer_answer_problem(r, AG_ERR_PARSE, err);
    ag_defer_answer_bytes(r, 422, "application/problem+json", body, strlen(body), NULL);
}

/* What PUT …/grammar checked before its work. */
typedef struct {
    char *text;
    size_t len;
    int64_t base;
} grammar_put;

static void grammar_put_free(void *p)
{
    grammar_put *g = p;
    if (g)
        free(g->text);
    free(g);
}

static void put_grammar(ag_request *r, ag_task_budget *budget)
{
    grammar_put *g = r->work_input;
    ag_error err;
    ag_error_clear(&err);
    char cid[64];
    ag_request_fresh_cid("grammar", cid, sizeof cid);
    int64_t version;
    long col = 0;
    ag_status s = ag_app_change_grammar(r->cfg->app, r->ids[0], g->base, ag_request_author(r),
                                        cid, g->text, g->len, budget, &version, &err, &col);
    if (s == AG_ERR_PARSE)
        return answer_parse_problem(r, &err, col);
    if (s != AG_OK)
        return ag_defer_answer_problem(r, s, &err);
    ag_api_answer_model(r, r->ids[0], 200);
}

enum MHD_Result ag_api_model_grammar_put(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    int64_t current, base;
    ag_status s = ag_app_query_version(r->cfg->app, r->ids[0], &current, &err);
    if (s == AG_OK)
        s = if_match(r, 1, current, &base, &err);
    grammar_put *g = NULL;
    if (s == AG_OK && !(g = calloc(1, sizeof *g)))
        s = ag_error_set(&err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK)
        s = ag_upload_read_all(r, ag_app_change_grammar_max(), "grammar text", &g->text,
                               &g->len, &err);
    if (s != AG_OK) {
        grammar_put_free(g);
        return ag_reply_problem(r, s, &err);
    }
    g->base = base;
    r->work_input = g;
    r->work_input_free = grammar_put_free;
    /* parsing, deriving and proceduralizing the text may take long: the model's task lane */
    return ag_defer_run(r, AG_TASK_OP, r->ids[0], put_grammar);
}
