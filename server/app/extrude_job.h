/* The extrude job (POST /api/v1/extrusions), off the request thread, with the params of
 * app/job_params.h (ag_extrude_job: the upload, name, format or sniffed, style, height
 * property, seed, lon/lat), registered with the store services (app/store_env.h).
 *
 * The upload is one building description (plan JSON, schema/plan.md), a list of them
 * ({"buildings": [{"id", "plan"}]}, as GET …/plan gives for a batch) or a GeoJSON
 * FeatureCollection of footprints turned into plans by the style. Each building is extruded
 * on its own (progress per building, stage "extrude"); a building that fails is reported with
 * its id and the reason and the batch goes on. On success, in one transaction: a model of kind
 * "extrusion" (one group and component per building with geometry, named by its id), its
 * buildings' plans, meshes and outcomes (store/extrusions.h), and the job's result
 * {"model", "href", "report": {"footprints", "succeeded", "failed": [{"id", "reason"}],
 * "not_watertight", "not_watertight_items", "triangles", "seconds", "skipped_features"}}.
 * A body that cannot be read, a single plan that fails, or a batch where every building fails
 * fails the job with the reason and stores nothing. */
#ifndef AG_EXTRUDE_JOB_H
#define AG_EXTRUDE_JOB_H

#include "jobqueue.h"

extern const ag_job_kind ag_extrude_job_kind;

#endif
