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
    ag_status s = ag_request_if_match(r, version, err);
    if (s != AG_OK)
        return s;
    if (*version == -1)
        *version = current;
    if (*version != current)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "model %lld is at version %lld, not %lld", (long long)r->ids[0],
                            (long long)current, (long long)*version);
    return AG_OK;
}

enum MHD_Result ag_api_model_proceduralize(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    /* an empty body, {} or {"exact": true|false} */
    int exact = 0;
    if (r->body_len) {
        json_t *body;
        ag_status s = ag_request_json(r, &body, &err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &err);
        const char *key = NULL, *bad = NULL;
        json_t *v;
        json_object_foreach(body, key, v) {
            if (!strcmp(key, "exact") && json_is_boolean(v)) {
                exact = json_is_true(v);
            } else {
                bad = key;
                break;
            }
        }
        if (bad && !strcmp(bad, "exact"))
            ag_error_set(&err, AG_ERR_INVALID, 0, "\"exact\" takes true or false");
        else if (bad)
            ag_error_set(&err, AG_ERR_INVALID, 0, "\"%s\" is not an option of proceduralize",
                         bad);
        if (bad) {
            json_decref(body);
            return ag_reply_problem(r, AG_ERR_INVALID, &err);
        }
        json_decref(body);
    }
    int64_t current, base;
    ag_status s = ag_app_query_version(r->cfg->app, r->ids[0], &current, &err);
    if (s == AG_OK)
        s = if_match(r, 0, current, &base, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    int64_t job = 0;
    s = ag_app_jobs_proceduralize(r->cfg->app, &r->who, r->ids[0], &current, exact, &job, &err);
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
static enum MHD_Result reply_parse_problem(ag_request *r, ag_error *err, long col)
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
        return ag_reply_problem(r, AG_ERR_PARSE, err);
    return ag_reply_bytes(r, 422, "application/problem+json", body, strlen(body), NULL);
}

enum MHD_Result ag_api_model_grammar_put(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    int64_t current, base;
    ag_status s = ag_app_query_version(r->cfg->app, r->ids[0], &current, &err);
    if (s == AG_OK)
        s = if_match(r, 1, current, &base, &err);
    char *text = NULL;
    size_t len = 0;
    if (s == AG_OK)
        s = ag_upload_read_all(r, ag_app_change_grammar_max(), "grammar text", &text, &len,
                               &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char cid[64];
    ag_request_fresh_cid("grammar", cid, sizeof cid);
    int64_t version;
    long col = 0;
    s = ag_app_change_grammar(r->cfg->app, r->ids[0], base, ag_request_author(r), cid, text, len,
                              &version, &err, &col);
    free(text);
    if (s == AG_ERR_PARSE)
        return reply_parse_problem(r, &err, col);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_api_reply_model(r, r->ids[0], 200);
}
