#include "routes.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const ag_route ag_routes[] = {
    {"GET", "/api/v1/health", ag_api_health, AG_BODY_NONE, 0},
    {"GET", "/api/v1/openapi.json", ag_api_openapi, AG_BODY_NONE, 0},
    {"GET", "/api/v1/models", ag_api_models_list, AG_BODY_NONE, 0},
    {"POST", "/api/v1/models", ag_api_models_create, AG_BODY_UPLOAD, AG_ROUTE_SUBMITS_JOB},
    {"GET", "/api/v1/models/{id}", ag_api_model_get, AG_BODY_NONE, 0},
    {"PATCH", "/api/v1/models/{id}", ag_api_model_patch, AG_BODY_JSON, 0},
    {"DELETE", "/api/v1/models/{id}", ag_api_model_delete, AG_BODY_NONE, 0},
    /* label and split-tree node per component once the model is proceduralized */
    {"GET", "/api/v1/models/{id}/mesh.glb", ag_api_model_mesh_glb, AG_BODY_NONE, 0},
    {"GET", "/api/v1/models/{id}/ops", ag_api_model_ops_list, AG_BODY_NONE, 0},
    {"POST", "/api/v1/models/{id}/ops", ag_api_model_ops_create, AG_BODY_JSON, 0},
    {"POST", "/api/v1/models/{id}/proceduralize", ag_api_model_proceduralize, AG_BODY_JSON,
     AG_ROUTE_SUBMITS_JOB},
    {"GET", "/api/v1/models/{id}/tree", ag_api_model_tree, AG_BODY_NONE, 0},
    {"GET", "/api/v1/models/{id}/grammar", ag_api_model_grammar_get, AG_BODY_NONE, 0},
    /* spooled like an upload; api_grammar.c takes at most 8 MiB of it */
    {"PUT", "/api/v1/models/{id}/grammar", ag_api_model_grammar_put, AG_BODY_UPLOAD, 0},
    /* a building description or GeoJSON footprints, spooled like model uploads */
    {"POST", "/api/v1/extrusions", ag_api_extrusions_create, AG_BODY_UPLOAD, AG_ROUTE_SUBMITS_JOB},
    {"POST", "/api/v1/extrusions/preview", ag_api_extrusions_preview, AG_BODY_JSON, 0},
    {"GET", "/api/v1/models/{id}/plan", ag_api_model_plan, AG_BODY_NONE, 0},
    {"GET", "/api/v1/jobs/{id}", ag_api_job_get, AG_BODY_NONE, 0},
    {"DELETE", "/api/v1/jobs/{id}", ag_api_job_cancel, AG_BODY_NONE, 0},
};
const size_t ag_routes_count = sizeof ag_routes / sizeof ag_routes[0];

/* Segment by segment; {id} takes 1..18 digits without a leading zero. */
static int path_matches(const char *pattern, const char *path, int64_t ids[2])
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
        if (*pattern != *path)
            return 0;
        pattern++;
        path++;
    }
    return *pattern == '\0' && *path == '\0';
}

ag_match ag_routes_match(const char *method, const char *path, const ag_route **route,
                         int64_t ids[2], char *allow, size_t allow_len)
{
    ag_match found = AG_MATCH_NONE;
    if (allow_len)
        allow[0] = '\0';
    for (size_t i = 0; i < ag_routes_count; i++) {
        int64_t tmp[2] = {0, 0};
        if (!path_matches(ag_routes[i].pattern, path, tmp))
            continue;
        if (strcmp(ag_routes[i].method, method) == 0) {
            *route = &ag_routes[i];
            ids[0] = tmp[0];
            ids[1] = tmp[1];
            return AG_MATCH_OK;
        }
        found = AG_MATCH_PATH_ONLY;
        size_t used = strlen(allow);
        snprintf(allow + used, allow_len - used, "%s%s", used ? ", " : "", ag_routes[i].method);
    }
    return found;
}
