/* POST /api/v1/extrusions/preview: one building description in, the extruded shell out as
 * GLB (app/app_query.h). Nothing is stored and no job is made: the web editors call it while
 * someone drags a corner or a profile point, so it answers on the request thread. An invalid
 * plan (parse, validation or sweep failure) is a 422 problem naming the reason. */
#include <stdio.h>

#include "../app/app_query.h"
#include "routes.h"

enum MHD_Result ag_api_extrusions_preview(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    if (!r->body || r->body_len == 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0, "a building description (plan JSON) is required");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    ag_app_bytes glb;
    size_t failing = 0;
    ag_status s = ag_app_query_extrusion_preview(r->body, r->body_len, &glb, &failing, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* A shell that is not watertight is still shown; the header tells the editor so. */
    if (failing) {
        char n[32];
        snprintf(n, sizeof n, "%zu", failing);
        ag_reply_header(r, "X-Archgram-Failing-Faces", n);
    }
    return ag_reply_bytes(r, 200, "model/gltf-binary", glb.data, glb.len, NULL);
}
