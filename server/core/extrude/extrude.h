/* One plan in, one mesh component out: validate, sweep, check, triangulate. */
#ifndef AG_EXTRUDE_EXTRUDE_H
#define AG_EXTRUDE_EXTRUDE_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "plan.h"
#include "shell.h"
#include "skeleton.h"

#define AG_EXTRUDE_MAX_PROBLEMS 8

typedef struct {
    size_t triangles;
    size_t faces;            /* shell faces with a boundary */
    size_t failing_faces;    /* faces that break closure/2-manifoldness */
    ag_shell_problem problems[AG_EXTRUDE_MAX_PROBLEMS]; /* the first ones */
    size_t nfixes;           /* corners/loops validation cleaned */
    double top;              /* highest point of the shell */
    double volume;
    ag_skeleton_stats stats;
} ag_extrude_result;

/* Validates (and cleans) plan, extrudes it and appends the triangles to m as one new
 * component of `group` (-1 for none); the plan's anchors are located (found, pos, ...). A plan that fails validation or the sweep leaves
 * m unchanged and returns the error. A shell that is not watertight is still added:
 * its failing faces are listed in res. `keep_shell` (may be NULL) receives the shell. */
ag_status ag_extrude_plan(ag_plan *plan, ag_mesh *m, int32_t group, ag_extrude_result *res,
                          ag_shell **keep_shell, ag_error *err);

/* Places the mesh of every anchor that has one and was found (after ag_extrude_plan) into
 * m, one new component of `group` each; *placed (may be NULL) gets how many. The mesh's
 * own frame is mapped to the anchor's: x along the active edge, z up the face (in its
 * plane, perpendicular to the edge), -y out of the face, origin at the anchor's point;
 * so a mesh modelled z-up against the front (facing -y) of a wall along +x appears as
 * modelled on every wall and tilts with a roof face. */
ag_status ag_extrude_place_meshes(const ag_plan *plan, ag_mesh *m, int32_t group, size_t *placed,
                                  ag_error *err);

#endif
