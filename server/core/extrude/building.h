/* One footprint of a batch made into a building that is good, or honestly reported.
 *
 * The footprint is styled into a plan and extruded under the options' budget; the result
 * counts only when ag_extrude_result_ok() (closed 2-manifold within reach of its
 * footprint). Otherwise, in order, until one is good:
 *   1. the footprint simplified (ag_simplify_loops, growing thresholds) and styled again;
 *   2. a flat roof: walls to the height, closed flat (on the footprint, else the
 *      simplified one);
 *   3. a block: the convex hull of the footprint's outer rings, walls to the height.
 * Each building records what was built, why the style's own building was not used, and
 * how far a simplification moved the boundary. A footprint that validation refuses (it
 * crosses itself, has no area) is not built at all: refused, with the validation's
 * message. */
#ifndef AG_EXTRUDE_BUILDING_H
#define AG_EXTRUDE_BUILDING_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "extrude.h"
#include "style.h"

typedef enum {
    AG_BUILT_STYLED = 0, /* the style's building */
    AG_BUILT_SIMPLIFIED, /* the style's building on a simplified footprint */
    AG_BUILT_FLAT,       /* walls and a flat roof */
    AG_BUILT_BLOCK,      /* the convex hull as a block */
    AG_BUILT_NONE,       /* refused by validation, or nothing could be built */
} ag_built;

/* "styled", "simplified", "flat", "block", "none" */
const char *ag_built_name(ag_built b);

typedef struct {
    ag_built built;
    char reason[AG_ERROR_TEXT]; /* why not as styled, or why refused; empty for AG_BUILT_STYLED */
    double moved;       /* a simplified footprint's boundary moved up to this far (m) */
    size_t triangles;
    size_t events;      /* events the extrusions of this building took */
    double seconds;
    size_t nfixes;      /* corners and loops validation cleaned */
    char fixes[240];    /* the first of them, "loop L corner C: reason; ..." */
} ag_building_result;

/* Builds footprint `index` (loops of xy pairs; height <= 0: the style's) into m as one
 * component of `group`. Returns AG_OK whatever was built (see out->built), AG_ERR_NOMEM,
 * or AG_ERR_CANCELLED when the budget's callback stopped it (then nothing is added). */
ag_status ag_building_extrude(const ag_style *style, const double *const *loops,
                              const size_t *sizes, size_t nloops, double height, size_t index,
                              const ag_extrude_options *opt, ag_mesh *m, int32_t group,
                              ag_building_result *out, ag_error *err);

/* The same for a building description: the plan as it is (validated and cleaned in
 * place, its anchors located); when that building is not good (or runs out of its
 * budget), a flat roof on the plan's cleaned loops at its wall height
 * (ag_building_plan_height), then a block. A plan is not simplified: its profiles
 * belong to its edges. Refused by validation: nothing built (AG_BUILT_NONE) with the
 * validation's message. Returns AG_OK whatever was built, AG_ERR_NOMEM, or
 * AG_ERR_CANCELLED (nothing added). */
ag_status ag_building_extrude_plan(ag_plan *plan, const ag_extrude_options *opt, ag_mesh *m,
                                   int32_t group, ag_building_result *out, ag_error *err);

/* The wall height of a plan for its flat fallback: the cap height when the plan has one,
 * else the highest eave (where an edge's profile first leaves the vertical), else the
 * top of the highest profile; AG_BUILDING_FLAT_HEIGHT when no profile rises at all. */
double ag_building_plan_height(const ag_plan *plan);
#define AG_BUILDING_FLAT_HEIGHT 3.0

#endif
