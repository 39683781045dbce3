#include "routes.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NONE AG_BODY_NONE
#define JSON AG_BODY_JSON
#define UPLOAD AG_BODY_UPLOAD
#define JOB AG_ROUTE_SUBMITS_JOB

const ag_route ag_routes[] = {
    /* method  pattern  handler  body  need  flags */
    {"GET", "/api/v1/health", ag_api_health, NONE, AG_NEED_NOTHING, 0},
    {"GET", "/api/v1/openapi.json", ag_api_openapi, NONE, AG_NEED_NOTHING, 0},
    /* the models the caller may see */
    {"GET", "/api/v1/models", ag_api_models_list, NONE, AG_NEED_ACCOUNT, 0},
    {"POST", "/api/v1/models", ag_api_models_create, UPLOAD, AG_NEED_EDITOR, JOB},
    {"GET", "/api/v1/models/{id}", ag_api_model_get, NONE, AG_NEED_MODEL_VIEWER, 0},
    {"PATCH", "/api/v1/models/{id}", ag_api_model_patch, JSON, AG_NEED_MODEL_EDITOR, 0},
    {"DELETE", "/api/v1/models/{id}", ag_api_model_delete, NONE, AG_NEED_MODEL_OWNER, 0},
    /* label and split-tree node per component once the model is proceduralized */
    {"GET", "/api/v1/models/{id}/mesh.glb", ag_api_model_mesh_glb, NONE, AG_NEED_MODEL_VIEWER, 0},
    {"GET", "/api/v1/models/{id}/ops", ag_api_model_ops_list, NONE, AG_NEED_MODEL_VIEWER, 0},
    {"POST", "/api/v1/models/{id}/ops", ag_api_model_ops_create, JSON, AG_NEED_MODEL_EDITOR, 0},
    {"POST", "/api/v1/models/{id}/proceduralize", ag_api_model_proceduralize, JSON,
     AG_NEED_MODEL_EDITOR, JOB},
    {"GET", "/api/v1/models/{id}/tree", ag_api_model_tree, NONE, AG_NEED_MODEL_VIEWER, 0},
    /* point cloud models (api_points.c): their points, a budget of them to view, segmenting */
    {"GET", "/api/v1/models/{id}/points.ply", ag_api_model_points_ply, NONE, AG_NEED_MODEL_VIEWER,
     0},
    {"GET", "/api/v1/models/{id}/points.glb", ag_api_model_points_glb, NONE, AG_NEED_MODEL_VIEWER,
     0},
    {"POST", "/api/v1/models/{id}/segment", ag_api_model_segment, JSON, AG_NEED_MODEL_EDITOR, JOB},
    /* the cloud a proceduralized cloud's grammar derives, as edited */
    {"GET", "/api/v1/models/{id}/derived.ply", ag_api_model_derived_ply, NONE,
     AG_NEED_MODEL_VIEWER, 0},
    {"GET", "/api/v1/models/{id}/grammar", ag_api_model_grammar_get, NONE, AG_NEED_MODEL_VIEWER, 0},
    /* spooled like an upload; api_grammar.c takes at most 8 MiB of it */
    {"PUT", "/api/v1/models/{id}/grammar", ag_api_model_grammar_put, UPLOAD,
     AG_NEED_MODEL_EDITOR, 0},
    /* who may use the model */
    {"GET", "/api/v1/models/{id}/members", ag_api_model_members, NONE, AG_NEED_MODEL_VIEWER, 0},
    {"PUT", "/api/v1/models/{id}/members/{name}", ag_api_model_member_put, JSON,
     AG_NEED_MODEL_OWNER, 0},
    {"DELETE", "/api/v1/models/{id}/members/{name}", ag_api_model_member_delete, NONE,
     AG_NEED_MODEL_OWNER, 0},
    {"PUT", "/api/v1/models/{id}/public", ag_api_model_public_put, JSON, AG_NEED_MODEL_OWNER, 0},
    /* a building description or GeoJSON footprints, spooled like model uploads */
    {"POST", "/api/v1/extrusions", ag_api_extrusions_create, UPLOAD, AG_NEED_EDITOR, JOB},
    /* stores nothing: editors of a shared extrusion model preview their plan edits */
    {"POST", "/api/v1/extrusions/preview", ag_api_extrusions_preview, JSON, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/models/{id}/plan", ag_api_model_plan, NONE, AG_NEED_MODEL_VIEWER, 0},
    /* what the client needs to select and compose (api_parts.c); composing is an op */
    {"GET", "/api/v1/models/{id}/selection", ag_api_model_selection, NONE, AG_NEED_MODEL_VIEWER, 0},
    {"POST", "/api/v1/models/{id}/compose-preview", ag_api_model_compose_preview, JSON,
     AG_NEED_MODEL_EDITOR, 0},
    /* the shared parts library: every account reads it, editors write it; bundles are spooled
     * like uploads */
    {"GET", "/api/v1/parts", ag_api_parts_list, NONE, AG_NEED_ACCOUNT, 0},
    {"POST", "/api/v1/parts", ag_api_parts_create, JSON, AG_NEED_EDITOR, 0},
    {"POST", "/api/v1/parts:import", ag_api_parts_import, UPLOAD, AG_NEED_EDITOR, 0},
    {"GET", "/api/v1/parts:export", ag_api_parts_export, NONE, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/parts/{id}", ag_api_part_get, NONE, AG_NEED_ACCOUNT, 0},
    {"DELETE", "/api/v1/parts/{id}", ag_api_part_delete, NONE, AG_NEED_EDITOR, 0},
    {"POST", "/api/v1/parts/{id}/versions", ag_api_part_versions_create, JSON, AG_NEED_EDITOR, 0},
    {"GET", "/api/v1/parts/{id}/thumbnail.png", ag_api_part_thumbnail, NONE, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/parts/{id}/mesh.glb", ag_api_part_mesh_glb, NONE, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/parts/{id}/bundle", ag_api_part_bundle, NONE, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/jobs/{id}", ag_api_job_get, NONE, AG_NEED_JOB, 0},
    {"DELETE", "/api/v1/jobs/{id}", ag_api_job_cancel, NONE, AG_NEED_JOB, 0},
    /* the caller's own account and tokens */
    {"GET", "/api/v1/me", ag_api_me, NONE, AG_NEED_ACCOUNT, 0},
    {"GET", "/api/v1/me/tokens", ag_api_me_tokens_list, NONE, AG_NEED_ACCOUNT, 0},
    {"POST", "/api/v1/me/tokens", ag_api_me_tokens_create, JSON, AG_NEED_ACCOUNT, 0},
    {"DELETE", "/api/v1/me/tokens/{id}", ag_api_me_token_delete, NONE, AG_NEED_ACCOUNT, 0},
    /* accounts, for admins */
    {"GET", "/api/v1/users", ag_api_users_list, NONE, AG_NEED_ADMIN, 0},
    {"POST", "/api/v1/users", ag_api_users_create, JSON, AG_NEED_ADMIN, 0},
    {"POST", "/api/v1/users/{name}/tokens", ag_api_user_tokens_create, JSON, AG_NEED_ADMIN, 0},
};
const size_t ag_routes_count = sizeof ag_routes / sizeof ag_routes[0];

static int name_char(char c, int first)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           (!first && (c == '.' || c == '_' || c == '-'));
}

/* Segment by segment; {id} takes 1..18 digits without a leading zero, {name} an account
 * name. */
static int path_matches(const char *pattern, const char *path, int64_t ids[2], char *name)
{
    int nid = 0;
    while (*pattern && *path) {
        if (strncmp(pattern, "{id}", 4) == 0) {
            const char *start = path;
            while (*path >= '0' && *path <= '9')
                path++;
            size_t n = (size_t)(path - start);
            if (n == 0 || n > 18 || *start == '0' || nid >= 2)
                return 0;
            ids[nid++] = strtoll(start, NULL, 10);
            pattern += 4;
            continue;
        }
        if (strncmp(pattern, "{name}", 6) == 0) {
            const char *start = path;
            while (name_char(*path, path == start))
                path++;
            size_t n = (size_t)(path - start);
            if (n == 0 || n > AG_USER_NAME_MAX)
                return 0;
            memcpy(name, start, n);
            name[n] = '\0';
            pattern += 6;
            continue;
        }
        if (*pattern != *path)
            return 0;
        pattern++;
        path++;
    }
    return *pattern == '\0' && *path == '\0';
}

ag_match ag_routes_find(const char *method, const char *path, const ag_route **route,
                        int64_t ids[2], char *name, char *allow, size_t allow_len)
{
    ag_match found = AG_MATCH_NONE;
    if (allow_len)
        allow[0] = '\0';
    name[0] = '\0';
    for (size_t i = 0; i < ag_routes_count; i++) {
        int64_t tmp[2] = {0, 0};
        char seg[AG_USER_NAME_MAX + 1] = "";
        if (!path_matches(ag_routes[i].pattern, path, tmp, seg))
            continue;
        if (strcmp(ag_routes[i].method, method) == 0) {
            *route = &ag_routes[i];
            ids[0] = tmp[0];
            ids[1] = tmp[1];
            memcpy(name, seg, sizeof seg);
            return AG_MATCH_OK;
        }
        found = AG_MATCH_PATH_ONLY;
        size_t used = strlen(allow);
        snprintf(allow + used, allow_len - used, "%s%s", used ? ", " : "", ag_routes[i].method);
    }
    return found;
}

ag_match ag_routes_match(const char *method, const char *path, const ag_route **route,
                         int64_t ids[2], char *allow, size_t allow_len)
{
    char name[AG_USER_NAME_MAX + 1];
    return ag_routes_find(method, path, route, ids, name, allow, allow_len);
}
