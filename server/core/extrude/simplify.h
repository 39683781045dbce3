/* Footprint simplification for retrying a building whose extrusion was not good: corners
 * are removed smallest first by the area of the triangle they make with their neighbours
 * (Visvalingam–Whyatt), so digitising noise, slivers and spikes go before any real
 * feature; how far the boundary moved is measured and reported. */
#ifndef AG_EXTRUDE_SIMPLIFY_H
#define AG_EXTRUDE_SIMPLIFY_H

#include <stddef.h>

#include "../status.h"

/* Simplifies each loop (xy pairs) in place: corners whose triangle with their current
 * neighbours has less than `area` m² are removed, smallest first, while the loop keeps
 * at least 3 corners. sizes[] is updated; *moved gets the largest distance of a removed
 * corner from the simplified boundary (m); *removed how many corners went. */
ag_status ag_simplify_loops(double *const *loops, size_t *sizes, size_t nloops, double area,
                            double *moved, size_t *removed);

#endif
