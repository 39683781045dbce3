/* POST /api/v1/extrusions/preview: one building description in, the extruded shell out as
 * GLB (app/app_query.h). Nothing is stored and no job is made: the web editors call it while
 * someone drags a corner or a profile point. The extrusion runs on a task worker under the
 * preview budget (archgramd --preview-seconds), never on an HTTP thread, and is dropped when
 * the client goes away. An invalid plan (parse, validation or sweep failure) is a 422 problem
 * naming the reason. */
#include <stdio.h>

#include "../app/app_query.h"
#include "defer.h"
#include "routes.h"

static void extrude_preview(ag_request *r, ag_task_budget *budget)
{
    ag_error err;
    ag_error_clear(&err);
    ag_app_bytes glb;
    size_t failing = 0;
    ag_status s = ag_app_query_extrusion_preview_budgeted(r->body, r->body_len, budget, &glb,
                                                          &failing, &err);
    if (s != AG_OK)
        return ag_defer_answer_problem(r, s, &err);
    /* A shell that is not watertight is still shown; the header tells the editor so. */
    if (failing) {
        char n[32];
        snprintf(n, sizeof n, "%zu", failing);
        ag_reply_header(r, "X-Archgram-Failing-Faces", n);
    }
    ag_defer_answer_bytes(r, 200, "model/gltf-binary", glb.data, glb.len, NULL);
}

enum MHD_Result ag_api_extrusions_preview(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    if (!r->body || r->body_len == 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0, "a building description (plan JSON) is required");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    return ag_defer_run(r, AG_TASK_PREVIEW, 0, extrude_preview);
}
