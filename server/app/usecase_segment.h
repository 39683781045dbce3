/* Segmenting a point cloud model, over a workspace (app/workspace.h): the whole cloud into
 * planes and clusters (§3.1 of the point cloud paper, core/points/segment_cloud.h: the
 * segment job), or a region of interest again at a finer granularity, replacing only the
 * segments inside it (§3, Fig. 2: the segment_roi op). The segmentation is saved through the
 * workspace with a report of what was found; the normals a cloud without computes are kept
 * with it.
 *
 * Progress of a whole run (to the workspace): the core's stages (index, normals, coarse,
 * refine, components, cluster, label) between 0.05 and 0.95, then "store"; a cancellation is
 * honoured inside every stage. */
#ifndef AG_USECASE_SEGMENT_H
#define AG_USECASE_SEGMENT_H

#include <jansson.h>

#include "workspace.h"

typedef struct {
    double threshold;         /* the refinement threshold, a fraction of the diagonal; 0: 0.01 */
    double coarse_threshold;  /* the first pass's; 0: 0.025 */
    double cluster_tolerance; /* T_C; 0: 0.01 */
    int recompute_normals;    /* kNN normals even when the cloud has its own */
} ag_usecase_segment_params;

/* Segments the whole cloud (p may be NULL: the defaults). *report (may be NULL) gets the
 * saved report, a new reference. AG_ERR_TOO_LARGE past AG_CLOUD_MAX_SEGMENT_POINTS. */
ag_status ag_usecase_segment_run(ag_workspace *ws, const ag_usecase_segment_params *p,
                                 json_t **report, ag_error *err);

/* Segments the points inside box [x0, y0, z0, x1, y1, z1] (model coordinates: the cloud's
 * local ones, those of points.ply and points.glb) again, thresholds relative to their own
 * diagonal. A cloud that is not segmented is refused (AG_ERR_CONFLICT), a box with no point
 * inside is AG_ERR_INVALID. */
ag_status ag_usecase_segment_roi(ag_workspace *ws, const double box[6],
                                 const ag_usecase_segment_params *p, json_t **report,
                                 ag_error *err);

#endif
