/* Template marking on a segmented point cloud model, over a workspace (app/workspace.h): a
 * person marks the points of a segment inside a box as a template; its copies along the
 * segment, found by the label rule (core/points/template_mark.h), become segments of their
 * own with the template's new label. The segmentation is saved through the workspace with a
 * report: the template's points and segment, the label, the copies (count and bounds). */
#ifndef AG_USECASE_MARK_TEMPLATE_H
#define AG_USECASE_MARK_TEMPLATE_H

#include <jansson.h>
#include <stdint.h>

#include "workspace.h"

/* box: [x0, y0, z0, x1, y1, z1] in model coordinates. AG_ERR_CONFLICT for a cloud that is
 * not segmented, AG_ERR_INVALID for a segment that is not there or a box with too few of its
 * points. *report (may be NULL) gets the saved report, a new reference. */
ag_status ag_usecase_mark_template(ag_workspace *ws, int32_t segment, const double box[6],
                                   json_t **report, ag_error *err);

#endif
