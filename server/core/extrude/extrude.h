/* One plan in, one mesh component out: validate, sweep, check, triangulate. */
#ifndef AG_EXTRUDE_EXTRUDE_H
#define AG_EXTRUDE_EXTRUDE_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "budget.h"
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
    double seconds;          /* wall-clock time of the whole extrusion */
    /* why the building's triangles fail ag_verify_building; empty when they pass */
    char defect[160];
} ag_extrude_result;

/* The building was made and is good: no failing shell face, no defect. */
int ag_extrude_result_ok(const ag_extrude_result *res);

/* How one extrusion runs. Zero-initialised: the default budget (events and memory in
 * proportion to the plan, no time limit, no cancel callback). */
typedef struct {
    ag_extrude_budget budget;
    /* receives what validation changed (may be NULL; free with ag_plan_fixes_free) */
    ag_plan_fixes *fixes;
    /* 1: no post inter-chain repair by the winding rule (to compare with it) */
    int no_winding_repair;
} ag_extrude_options;

/* Validates (and cleans) plan, extrudes it and appends the triangles to m as one new
 * component of `group` (-1 for none); the plan's anchors are located (found, pos, ...).
 * A plan that fails validation or the sweep, or runs out of its budget (AG_ERR_TOO_LARGE,
 * AG_ERR_CANCELLED, see budget.h), leaves m unchanged and returns the error. A building
 * that is added but is not good is reported in res: failing_faces counts the faces the
 * shell's own check refused (open, not planar), and `defect` says why its triangles fail
 * ag_verify_building (not a closed 2-manifold, reaching outside its footprint: e.g. a
 * corner that ran away). Only ag_extrude_result_ok() is a success. `keep_shell` (may be
 * NULL) receives the shell. opt may be NULL (defaults). */
ag_status ag_extrude_plan_with(ag_plan *plan, const ag_extrude_options *opt, ag_mesh *m,
                               int32_t group, ag_extrude_result *res, ag_shell **keep_shell,
                               ag_error *err);
/* ag_extrude_plan_with with the default options. */
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
