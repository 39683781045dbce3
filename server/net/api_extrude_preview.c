/* POST /api/v1/extrusions/preview: one building description in, the extruded shell out as
 * GLB. Nothing is stored and no job is made: the web editors call it while someone drags a
 * corner or a profile point, so it answers on the request thread. An invalid plan (parse,
 * validation or sweep failure) is a 422 problem naming the reason. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "../core/extrude/extrude.h"
#include "../io/glb.h"
#include "../io/plan_json.h"
#include "routes.h"

/* Everything but out-of-memory is the plan's fault: report it as unprocessable input. */
static ag_status as_plan_problem(ag_status s, ag_error *err)
{
    if (s == AG_ERR_NOMEM || s == AG_OK)
        return s;
    if (err)
        err->code = AG_ERR_PARSE;
    return AG_ERR_PARSE;
}

enum MHD_Result ag_api_extrusions_preview(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    if (!r->body || r->body_len == 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0, "a building description (plan JSON) is required");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    ag_plan *plan = NULL;
    ag_status s = ag_plan_json_read_buffer(r->body, r->body_len, &plan, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, as_plan_problem(s, &err), &err);

    ag_mesh *m = ag_mesh_create();
    if (!m) {
        ag_plan_free(plan);
        ag_error_set(&err, AG_ERR_NOMEM, 0, "out of memory");
        return ag_reply_problem(r, AG_ERR_NOMEM, &err);
    }
    ag_extrude_result res;
    s = ag_extrude_plan(plan, m, -1, &res, NULL, &err);
    ag_plan_free(plan);
    if (s != AG_OK) {
        ag_mesh_free(m);
        return ag_reply_problem(r, as_plan_problem(s, &err), &err);
    }
    uint8_t *glb = NULL;
    size_t len = 0;
    s = ag_glb_write(m, &glb, &len, &err);
    ag_mesh_free(m);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* A shell that is not watertight is still shown; the header tells the editor so. */
    if (res.failing_faces) {
        char n[32];
        snprintf(n, sizeof n, "%zu", res.failing_faces);
        ag_reply_header(r, "X-Archgram-Failing-Faces", n);
    }
    return ag_reply_bytes(r, 200, "model/gltf-binary", glb, len, NULL);
}
