/* GET /api/v1/health and GET /api/v1/openapi.json. */
#include <stdlib.h>
#include <string.h>

#include "../app/app_query.h"
#include "../embedded.h"
#include "connguard.h"
#include "routes.h"

enum MHD_Result ag_api_health(ag_request *r)
{
    ag_error err;
    json_t *body = ag_app_query_health(r->cfg->app, r->cfg->ws_port, &err);
    if (!body)
        return ag_reply_problem(r, err.code, &err);
    /* the HTTP side: open connections, slow ones cut, requests whose client left first */
    json_object_set_new(body, "http",
                        json_pack("{s:I, s:I, s:I}", "connections",
                                  (json_int_t)ag_connguard_open(r->cfg->guard), "slow_cut",
                                  (json_int_t)ag_connguard_cut(r->cfg->guard), "abandoned",
                                  (json_int_t)atomic_load(r->cfg->abandoned)));
    /* the web client asks for a token only when there are accounts */
    json_object_set_new(body, "auth", json_boolean(!r->cfg->no_auth));
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
