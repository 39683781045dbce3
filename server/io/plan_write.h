/* ag_plan → building description JSON (schema/plan.md), the inverse of io/plan_json.h:
 * reading the output back gives the same profiles (points, tag, priority, segment
 * priorities), loops, meshes, anchors (with their meshes), natural and forced steps,
 * profile offset events, cap height and priority scheme (numbers are written with full
 * precision, so the values come back bit for bit). */
#ifndef AG_PLAN_WRITE_H
#define AG_PLAN_WRITE_H

#include <jansson.h>

#include "../core/extrude/plan.h"
#include "../core/status.h"
#include "obj.h"

/* Where a plan mesh is read from: a plan keeps the geometry, not the file it came from. */
typedef struct {
    const char *path; /* written as given; the reader resolves it against the plan's folder */
    ag_up_axis up;    /* the file's up axis (AG_UP_DEFAULT = y) */
} ag_plan_mesh_file;

typedef struct {
    /* p->nmeshes entries, in the order of p->meshes; NULL is fine for a plan without meshes
     * (a plan with meshes then fails rather than name files that may not exist). */
    const ag_plan_mesh_file *mesh_files;
} ag_plan_write_options;

/* *out is a new reference. AG_ERR_INVALID when two profiles share a name (JSON names them),
 * a profile, loop edge, step or offset names no profile, an anchor no mesh, a mesh has no
 * file, a number is NaN/inf or a name is not UTF-8; AG_ERR_NOMEM. opt may be NULL. */
ag_status ag_plan_write_json_opts(const ag_plan *p, const ag_plan_write_options *opt,
                                  json_t **out, ag_error *err);
/* ag_plan_write_json_opts without options. */
ag_status ag_plan_write_json(const ag_plan *p, json_t **out, ag_error *err);

#endif
