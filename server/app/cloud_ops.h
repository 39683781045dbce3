/* Ops on point cloud models (schema/edit_ops.md, schema/websocket.md): their rows of the op
 * table (app/optable.h).
 *
 *   {"kind":"segment_roi","box":[x0,y0,z0,x1,y1,z1], "threshold"?, "coarse_threshold"?,
 *    "cluster_tolerance"?}
 *       the points inside the box segmented again, finer (app/usecase_segment.h); box in
 *       model coordinates (those of points.ply and points.glb), thresholds fractions of the
 *       diagonal of the points inside
 *   {"kind":"mark_template","segment":S,"box":[x0,y0,z0,x1,y1,z1]}
 *       the points of segment S inside the box marked as a template, its copies found and
 *       labelled with it (app/usecase_mark_template.h)
 *
 * Both are structural (computed off the commit lock, on the fast lane when they come over a
 * websocket), undoable by their author, logged with the server's "report". A model that is
 * not a point cloud or not segmented refuses them (AG_ERR_CONFLICT). */
#ifndef AG_CLOUD_OPS_H
#define AG_CLOUD_OPS_H

#include <jansson.h>
#include <stdint.h>

#include "optable.h"
#include "store_env.h"

ag_status ag_cloud_ops_validate_roi(const json_t *op, ag_error *err);
ag_status ag_cloud_ops_validate_template(const json_t *op, ag_error *err);
ag_status ag_cloud_ops_run(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
                           int *duplicate, ag_error *err);

#endif
