/* The stages of the point pipeline that the service runs on point cloud models through the
 * same routes and jobs as meshes, where they exist. A stage that is not built yet is NULL:
 * the REST call that would start it answers AG_ERR_NOT_AVAILABLE (422 not-available) naming
 * what is missing, before anything is queued, and a job that meets one anyway fails the same
 * way. Wiring a stage in is setting its pointer (app/cloud_pipeline.c).
 *
 *   proceduralize   segments, labels and consensus terminals → split tree → grammar with PLY
 *                   terminals (app/usecase_points.h), over a workspace whose model is a cloud
 *                   (POST …/proceduralize; a segmentation it has is not used: the pipeline
 *                   segments with its repetition stages together) */
#ifndef AG_CLOUD_PIPELINE_H
#define AG_CLOUD_PIPELINE_H

#include <stdint.h>

#include "../core/status.h"
#include "workspace.h"

/* options: the job's point cloud options (app/points_proc_options.h) as JSON text, or NULL */
typedef ag_status (*ag_cloud_proceduralize_fn)(ag_workspace *ws, const char *options,
                                               ag_error *err);
extern const ag_cloud_proceduralize_fn ag_cloud_pipeline_proceduralize;

/* The point cloud options of a proceduralization, checked (AG_ERR_INVALID naming the member;
 * for a model that is not a cloud, naming the first member) and as the job's text (*text,
 * malloc'd). */
#include <jansson.h>
ag_status ag_cloud_pipeline_check_options(int64_t model, int cloud, const json_t *options,
                                          char **text, ag_error *err);

/* The problem of a stage that is not there: AG_ERR_NOT_AVAILABLE naming the model, the step
 * ("proceduralize") and what it needs. */
ag_status ag_cloud_pipeline_missing(int64_t model, const char *step, ag_error *err);

/* Whether model is a point cloud (*cloud), AG_ERR_NOT_FOUND when there is no such model. */
struct ag_db;
ag_status ag_cloud_pipeline_is_cloud(struct ag_db *db, int64_t model, int *cloud, ag_error *err);

#endif
