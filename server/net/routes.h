/* The REST route table: one static list that the dispatcher, the 405 answers and the
 * OpenAPI consistency test all read. Patterns use {id} for a positive integer segment. */
#ifndef AG_ROUTES_H
#define AG_ROUTES_H

#include <stddef.h>

#include "request.h"

typedef enum {
    AG_BODY_NONE = 0,
    AG_BODY_JSON,   /* buffered up to cfg->max_json */
    AG_BODY_UPLOAD, /* spooled to a file up to cfg->max_body */
} ag_body_kind;

enum {
    AG_ROUTE_SUBMITS_JOB = 1u << 0, /* counted against the job-submission rate limit */
};

typedef struct ag_route {
    const char *method;
    const char *pattern;
    ag_handler handler;
    ag_body_kind body;
    unsigned flags;
} ag_route;

extern const ag_route ag_routes[];
extern const size_t ag_routes_count;

typedef enum { AG_MATCH_NONE, AG_MATCH_PATH_ONLY, AG_MATCH_OK } ag_match;

/* Finds the route for method and path; on AG_MATCH_OK *route and ids are set; on
 * AG_MATCH_PATH_ONLY allow gets the comma-separated methods the path accepts. */
ag_match ag_routes_match(const char *method, const char *path, const ag_route **route,
                         int64_t ids[2], char *allow, size_t allow_len);

/* Handlers (api_*.c). */
enum MHD_Result ag_api_health(ag_request *r);
enum MHD_Result ag_api_openapi(ag_request *r);
enum MHD_Result ag_api_models_list(ag_request *r);
enum MHD_Result ag_api_models_create(ag_request *r);
enum MHD_Result ag_api_model_get(ag_request *r);
enum MHD_Result ag_api_model_patch(ag_request *r);
enum MHD_Result ag_api_model_delete(ag_request *r);
enum MHD_Result ag_api_model_ops_list(ag_request *r);
enum MHD_Result ag_api_model_ops_create(ag_request *r);
enum MHD_Result ag_api_model_mesh_glb(ag_request *r);
enum MHD_Result ag_api_model_proceduralize(ag_request *r);
enum MHD_Result ag_api_model_tree(ag_request *r);
enum MHD_Result ag_api_model_grammar_get(ag_request *r);
enum MHD_Result ag_api_model_grammar_put(ag_request *r);
enum MHD_Result ag_api_extrusions_create(ag_request *r);
enum MHD_Result ag_api_extrusions_preview(ag_request *r);
enum MHD_Result ag_api_model_plan(ag_request *r);
enum MHD_Result ag_api_job_get(ag_request *r);
enum MHD_Result ag_api_job_cancel(ag_request *r);

/* Shared by the handlers (api_models.c): a model's view with its ETag; the If-Match version
 * of a change ("*" = the current one; not required: 0 when absent). */
enum MHD_Result ag_api_reply_model(ag_request *r, int64_t id, unsigned status);
/* The same as the answer of deferred work (net/defer.h). */
void ag_api_answer_model(ag_request *r, int64_t id, unsigned status);
ag_status ag_api_precondition(ag_request *r, int required, int64_t *version, ag_error *err);

#endif
