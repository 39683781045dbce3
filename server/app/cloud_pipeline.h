/* The stages of the point pipeline that the service runs on point cloud models through the
 * same routes and jobs as meshes, where they exist. A stage that is not built yet is NULL:
 * the REST call that would start it answers AG_ERR_NOT_AVAILABLE (422 not-available) naming
 * what is missing, before anything is queued, and a job that meets one anyway fails the same
 * way. Wiring a stage in is setting its pointer (app/cloud_pipeline.c).
 *
 *   proceduralize   segments, labels and consensus terminals → split tree → grammar, over a
 *                   workspace whose model is a segmented cloud (POST …/proceduralize) */
#ifndef AG_CLOUD_PIPELINE_H
#define AG_CLOUD_PIPELINE_H

#include <stdint.h>

#include "../core/status.h"
#include "workspace.h"

typedef ag_status (*ag_cloud_proceduralize_fn)(ag_workspace *ws, ag_error *err);
extern const ag_cloud_proceduralize_fn ag_cloud_pipeline_proceduralize;

/* The problem of a stage that is not there: AG_ERR_NOT_AVAILABLE naming the model, the step
 * ("proceduralize") and what it needs. */
ag_status ag_cloud_pipeline_missing(int64_t model, const char *step, ag_error *err);

/* Whether model is a point cloud (*cloud), AG_ERR_NOT_FOUND when there is no such model. */
struct ag_db;
ag_status ag_cloud_pipeline_is_cloud(struct ag_db *db, int64_t model, int *cloud, ag_error *err);

#endif
