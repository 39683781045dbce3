/* The horizontal faces of a shell at one height rebuilt from their winding.
 *
 * Where edges moving inwards (a terrace) and edges moving outwards (a soffit) make their
 * horizontal faces at the same height, the swept faces fold over each other around the
 * corners between them: an upward face and a downward face cover the same triangle, which
 * lies in neither the plan below nor the plan above. What the shell needs there is the
 * difference of the two plans: upward faces over the region in the plan below and not in
 * the plan above, downward faces over the region in the plan above and not below. Counted
 * as seen from above, the boundaries of all horizontal faces at that height (upward faces
 * counter-clockwise, downward ones clockwise) wind exactly +1 over the first region, -1
 * over the second and 0 elsewhere, whatever the sweep did in between. So the faces are cut
 * at every crossing and every corner lying on them, opposite pieces cancel, and the pieces
 * left are given to one upward face (winding +1 on their left) and one downward face
 * (winding -1 on their right). The other faces' edges at that height (the walls' tops and
 * bottoms) are cut at the same points so that they meet the new faces edge to edge.
 *
 * A height with faces of one kind only (terraces meeting, soffits meeting) keeps its faces:
 * there every edge at that height is only cut at the corners lying on it (a corner of one
 * face on another's edge left the shell open there).
 *
 * Levels whose winding is not within -1..1, or is not consistent across a piece (rounding
 * at a degenerate contact), are left as they were: the shell check then reports them. */
#ifndef AG_EXTRUDE_FLATS_H
#define AG_EXTRUDE_FLATS_H

#include <stddef.h>

#include "../status.h"
#include "shell.h"

/* Runs on a shell whose vertices have been welded (segments refer to the representative
 * vertices) and before its segments are linked (ag_shell_finish calls it). tol: points
 * closer than this are one point, a corner closer than this to an edge lies on it.
 * Adds vertices and segments; the faces' segments it replaces are made zero-length (the
 * linking drops them); counts the heights in s->flat_levels, s->flat_rebuilt and
 * s->flat_left. AG_ERR_NOMEM only. */
ag_status ag_flats_rebuild(ag_shell *s, double tol);

#endif
