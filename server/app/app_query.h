/* What the REST and live layers read, finished: JSON views and bytes, each read on the
 * calling thread's connection. Versions come back for ETags. */
#ifndef AG_APP_QUERY_H
#define AG_APP_QUERY_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "auth.h"

/* The models who may see with id > after, ascending, at most limit, each with
 * "proceduralized" and who's "role" on it (app/auth.h); *more says whether another page
 * follows (its token is the last item's id). */
ag_status ag_app_query_models(ag_app *app, const ag_identity *who, int64_t after, size_t limit,
                              json_t **items, int *more, ag_error *err);
/* One model's view (with "proceduralized") and its version. */
ag_status ag_app_query_model(ag_app *app, int64_t id, json_t **view, int64_t *version,
                             ag_error *err);
ag_status ag_app_query_version(ag_app *app, int64_t id, int64_t *version, ag_error *err);
/* The ops with version > since, oldest first, at most limit (0 = all), each
 * {"version","author","cid","op","at"}, and the model's version. */
ag_status ag_app_query_ops(ag_app *app, int64_t id, int64_t since, int64_t limit,
                           json_t **items, int64_t *version, ag_error *err);
/* A job's view; *finished is set when it succeeded, failed or was cancelled (may be NULL). */
ag_status ag_app_query_job(ag_app *app, int64_t job, json_t **view, int *finished,
                           ag_error *err);

/* GET …/tree: {"model","version","summary", and the tree of app/model_tree.h} as text. */
ag_status ag_app_query_tree(ag_app *app, int64_t id, char **json, size_t *len,
                            int64_t *version, ag_error *err);
/* GET …/grammar: the text and the model's version. */
ag_status ag_app_query_grammar(ag_app *app, int64_t id, char **text, size_t *len,
                               int64_t *version, ag_error *err);
/* GET …/plan: one plan as stored, or a batch as {"buildings": [...]} with its metadata. */
ag_status ag_app_query_plan(ag_app *app, int64_t id, json_t **doc, int64_t *version,
                            ag_error *err);

/* mesh.glb: binary glTF of the model's mesh (a proceduralized model's components carry their
 * label and tree node; a point cloud model's points, as app/app_points.h serves them). etag is a strong validator of the geometry; when fresh(user, etag)
 * says the client has it, nothing is built and data stays NULL. */
typedef struct {
    uint8_t *data; /* malloc'd */
    size_t len;
    char etag[48];
} ag_app_bytes;
ag_status ag_app_query_glb(ag_app *app, int64_t id, int (*fresh)(void *user, const char *etag),
                           void *user, ag_app_bytes *out, ag_error *err);

/* POST /api/v1/extrusions/preview: one building description (plan JSON) extruded, as GLB;
 * nothing is stored. Anything but running out of memory is the plan's fault (AG_ERR_PARSE);
 * *failing_faces counts faces of a shell that is not watertight. */
ag_status ag_app_query_extrusion_preview(const char *plan_json, size_t len, ag_app_bytes *out,
                                         size_t *failing_faces, ag_error *err);
/* The same under a task budget (run it as an AG_TASK_PREVIEW, app.h): the sweep stops when
 * the budget runs out (AG_ERR_DEADLINE), the asker goes away or the service stops
 * (AG_ERR_CANCELLED), and does not start when it is already spent. */
ag_status ag_app_query_extrusion_preview_budgeted(const char *plan_json, size_t len,
                                                  ag_task_budget *budget, ag_app_bytes *out,
                                                  size_t *failing_faces, ag_error *err);

/* GET /api/v1/health. */
json_t *ag_app_query_health(ag_app *app, int ws_port, ag_error *err);

#endif
