/* The options of proceduralizing a point cloud in the service (POST …/proceduralize of a
 * model of kind pointcloud), checked at the request and carried by the job as JSON text:
 *
 *   "templates": [[x0,y0,z0,x1,y1,z1], ...]   boxes around one element each (a window): its
 *                                             copies get its label (repetition by template
 *                                             matching), in the cloud's coordinates (RD
 *                                             New, UTM: those of the tree's boxes), at most 64
 *   "rois": [[x0,y0,z0,x1,y1,z1], ...]        regions segmented again, finer, at most 64
 *   "auto": true | false                      automatic repetition (default true)
 *
 * Problems name the member and the box (AG_ERR_INVALID). */
#ifndef AG_POINTS_PROC_OPTIONS_H
#define AG_POINTS_PROC_OPTIONS_H

#include <jansson.h>

#include "../core/base/box.h"
#include "../core/status.h"
#include "usecase_points.h"

#define AG_POINTS_PROC_OPTIONS_MAX_BOXES 64

/* Whether key is one of the point options above. */
int ag_points_proc_options_is_key(const char *key);

/* The options in obj (an object holding only these keys; NULL: none) as use case params
 * (p->options.templates and rois point into *boxes, malloc'd, the caller's to free; boxes in
 * the input's coordinates, p->boxes_in_input set). */
ag_status ag_points_proc_options_read(const json_t *obj, ag_usecase_points_proceduralize_params *p,
                                      ag_box **boxes, ag_error *err);

#endif
