/* The check every extruded building passes before it counts as built: on its triangles
 * (what a user gets), not on the shell's own bookkeeping.
 *
 * A building is good when its triangles, with vertices welded at the plan's point
 * tolerance,
 *   - form a closed 2-manifold: every directed edge is used exactly once and its reverse
 *     exactly once (so no edge is shared by more than two triangles), and no two
 *     triangles use the same three vertices (a zero-area, double-sided sliver passes the
 *     edge count but not this);
 *   - have no fold: no upward and downward horizontal triangles of one height overlap (two
 *     faces back to back with the solid on neither side; their edges pair and they add no
 *     volume, and a probe behind a face finds them only where it happens to fall in them);
 *   - bound their solid once: just inside each face (a hair behind its centre) the
 *     shell winds exactly once, counted along rays — not twice (two parts swept through
 *     each other, which the edge counts cannot see) nor zero (a fold or fin turned inside
 *     out);
 *   - stay within reach of the plan: every vertex within `reach` of the footprint (inside
 *     it or that close to its boundary), where reach is how far the plan's profiles,
 *     offset events and steps may lead outwards, plus a tolerance; forced steps' polygons
 *     count as footprint; and no higher than the plan's profiles can rise over its size.
 * A roof whose corner ran away (missed events make corners fly off at kilometres) or
 * whose faces overlap fails here, whatever the sweep believed. */
#ifndef AG_EXTRUDE_VERIFY_H
#define AG_EXTRUDE_VERIFY_H

#include <stddef.h>

#include "../mesh.h"
#include "plan.h"

/* How far outwards a validated plan may lead (m) and how high it may rise (m). */
void ag_verify_reach(const ag_plan *plan, double *outwards, double *height);

/* Checks triangles [t0, t1) of m as the building extruded from the validated plan.
 * Returns 1 when good; else 0 and the first defect in why (may be NULL). */
int ag_verify_building(const ag_mesh *m, size_t t0, size_t t1, const ag_plan *plan, char *why,
                       size_t nwhy);

#endif
