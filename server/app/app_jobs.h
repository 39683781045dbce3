/* The jobs the REST layer asks for, with typed parameters (app/job_params.h), checked before
 * they are queued; and cancelling them. */
#ifndef AG_APP_JOBS_H
#define AG_APP_JOBS_H

#include <jansson.h>
#include <stdint.h>

#include "app.h"
#include "auth.h"
#include "job_params.h"

/* An import of an uploaded file: the name, format ("obj", …, or NULL) and up axis ("y", "z"
 * or NULL) are checked. The upload is removed when the job cannot be queued. */
/* The checks ag_app_jobs_import and _extrude make, for a caller that checks before it takes
 * the upload. */
ag_status ag_app_jobs_check_import(const ag_import_job *p, ag_error *err);
ag_status ag_app_jobs_check_extrude(const ag_extrude_job *p, ag_error *err);

/* who asks for the job: it may read and cancel it and owns the model it makes. */
ag_status ag_app_jobs_import(ag_app *app, const ag_identity *who, const ag_import_job *p,
                             int64_t *job, ag_error *err);
/* Proceduralizing a model at its current version, the op authored by who; if_match (NULL:
 * none; -1: any) must be the current version (AG_ERR_STALE otherwise); mesh: a mesh's
 * options (terminals shared by exact copies only, the length unit; refused for a cloud);
 * cloud: a point cloud's options (app/points_proc_options.h; NULL: none; refused for a
 * mesh). */
typedef struct {
    int exact;
    const char *unit; /* core/proc/units.h ag_units_named; NULL: decided from the content */
} ag_app_mesh_proc_options;

ag_status ag_app_jobs_proceduralize(ag_app *app, const ag_identity *who, int64_t model,
                                    const int64_t *if_match, const ag_app_mesh_proc_options *mesh,
                                    const json_t *cloud, int64_t *job, ag_error *err);
/* Segmenting a point cloud model at its current version (app/usecase_segment.h), the op
 * authored by who; body: {"threshold", "coarse_threshold", "cluster_tolerance": fractions of
 * the diagonal, "recompute_normals": bool}, each optional (AG_ERR_INVALID naming a bad or
 * unknown member). if_match as for proceduralize. AG_ERR_CONFLICT for a model that is not a
 * point cloud, AG_ERR_TOO_LARGE past AG_CLOUD_MAX_SEGMENT_POINTS. */
ag_status ag_app_jobs_segment(ag_app *app, const ag_identity *who, int64_t model,
                              const int64_t *if_match, const json_t *body, int64_t *job,
                              ag_error *err);
/* An extrusion of an uploaded description or GeoJSON: the name, format and style are checked.
 * The upload is removed when the job cannot be queued. */
ag_status ag_app_jobs_extrude(ag_app *app, const ag_identity *who, const ag_extrude_job *p,
                              int64_t *job, ag_error *err);
ag_status ag_app_jobs_cancel(ag_app *app, int64_t job, ag_error *err);

#endif
