/* The REST route table: one static list that the dispatcher, the 405 answers, the access
 * checks and the OpenAPI consistency test all read. Patterns use {id} for a positive integer
 * segment and {name} for an account name (A-Z a-z 0-9 . _ -, 1..64, beginning with a letter
 * or a digit). Each row declares what its caller needs (app/auth.h); http.c checks it before
 * the body is read, so a row that says nothing is for admins only. */
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
    ag_need need; /* of the caller: a token, an account role, a role on the model of {id} */
    unsigned flags;
} ag_route;

extern const ag_route ag_routes[];
extern const size_t ag_routes_count;

typedef enum { AG_MATCH_NONE, AG_MATCH_PATH_ONLY, AG_MATCH_OK } ag_match;

/* Finds the route for method and path; on AG_MATCH_OK *route and ids are set; on
 * AG_MATCH_PATH_ONLY allow gets the comma-separated methods the path accepts. */
ag_match ag_routes_match(const char *method, const char *path, const ag_route **route,
                         int64_t ids[2], char *allow, size_t allow_len);
/* The same, also giving the {name} segment (name: AG_USER_NAME_MAX + 1 bytes; "" when the
 * pattern has none). */
ag_match ag_routes_find(const char *method, const char *path, const ag_route **route,
                        int64_t ids[2], char *name, char *allow, size_t allow_len);

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
enum MHD_Result ag_api_model_points_ply(ag_request *r);
enum MHD_Result ag_api_model_derived_ply(ag_request *r);
enum MHD_Result ag_api_model_points_glb(ag_request *r);
enum MHD_Result ag_api_model_segment(ag_request *r);
enum MHD_Result ag_api_model_grammar_get(ag_request *r);
enum MHD_Result ag_api_model_grammar_put(ag_request *r);
enum MHD_Result ag_api_extrusions_create(ag_request *r);
enum MHD_Result ag_api_extrusions_preview(ag_request *r);
enum MHD_Result ag_api_model_plan(ag_request *r);
enum MHD_Result ag_api_model_selection(ag_request *r);
enum MHD_Result ag_api_model_compose_preview(ag_request *r);
enum MHD_Result ag_api_parts_list(ag_request *r);
enum MHD_Result ag_api_parts_create(ag_request *r);
enum MHD_Result ag_api_parts_import(ag_request *r);
enum MHD_Result ag_api_parts_export(ag_request *r);
enum MHD_Result ag_api_part_get(ag_request *r);
enum MHD_Result ag_api_part_delete(ag_request *r);
enum MHD_Result ag_api_part_versions_create(ag_request *r);
enum MHD_Result ag_api_part_thumbnail(ag_request *r);
enum MHD_Result ag_api_part_mesh_glb(ag_request *r);
enum MHD_Result ag_api_part_bundle(ag_request *r);
enum MHD_Result ag_api_job_get(ag_request *r);
enum MHD_Result ag_api_job_cancel(ag_request *r);
/* accounts and tokens (api_accounts.c), sharing (api_sharing.c) */
enum MHD_Result ag_api_me(ag_request *r);
enum MHD_Result ag_api_me_tokens_list(ag_request *r);
enum MHD_Result ag_api_me_tokens_create(ag_request *r);
enum MHD_Result ag_api_me_token_delete(ag_request *r);
enum MHD_Result ag_api_users_list(ag_request *r);
enum MHD_Result ag_api_users_create(ag_request *r);
enum MHD_Result ag_api_user_tokens_create(ag_request *r);
enum MHD_Result ag_api_model_members(ag_request *r);
enum MHD_Result ag_api_model_member_put(ag_request *r);
enum MHD_Result ag_api_model_member_delete(ag_request *r);
enum MHD_Result ag_api_model_public_put(ag_request *r);

/* Shared by the handlers (api_models.c): a model's view with its ETag; the If-Match version
 * of a change ("*" = the current one; not required: 0 when absent). */
enum MHD_Result ag_api_reply_model(ag_request *r, int64_t id, unsigned status);
/* The same as the answer of deferred work (net/defer.h). */
void ag_api_answer_model(ag_request *r, int64_t id, unsigned status);
ag_status ag_api_precondition(ag_request *r, int required, int64_t *version, ag_error *err);

#endif
