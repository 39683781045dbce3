/* GET /api/v1/health and GET /api/v1/openapi.json. */
#include <stdlib.h>
#include <string.h>

#include "../embedded.h"
#include "routes.h"

enum MHD_Result ag_api_health(ag_request *r)
{
    ag_error err;
    ag_db *db = ag_app_db(r->cfg->app, &err);
    if (!db)
        return ag_reply_problem(r, err.code, &err);
    json_t *body = json_pack("{s:s, s:s, s:{s:s, s:i}, s:i, s:i}", "status", "ok", "version",
                             AG_VERSION, "db", "path", ag_db_path(db), "schema_version",
                             ag_db_schema_version(db), "ws_port", r->cfg->ws_port, "workers",
                             ag_app_workers(r->cfg->app));
    return ag_reply_json(r, 200, body, NULL);
}

enum MHD_Result ag_api_openapi(ag_request *r)
{
    size_t n = strlen(ag_openapi_json);
    char *copy = malloc(n + 1);
    if (!copy)
        return MHD_NO;
    memcpy(copy, ag_openapi_json, n + 1);
    return ag_reply_bytes(r, 200, "application/json", copy, n, NULL);
}
