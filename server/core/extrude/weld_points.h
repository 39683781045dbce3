/* Welding of points closer than a tolerance (a sweep along sorted x, union-find), shared by
 * the shell's linking and the building check. */
#ifndef AG_EXTRUDE_WELD_H
#define AG_EXTRUDE_WELD_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "keysort.h"

/* order holds n entries (ag_keysort_double(x of the vertex), vertex) for the vertices to
 * weld (a vertex may be listed more than once); pos holds x, y, z per vertex; par[v] must
 * be v for every vertex listed. Afterwards par[v] is the smallest vertex it is welded to:
 * points within tol, transitively. order is sorted in place. */
ag_status ag_weld_points(const double *pos, ag_keyed *order, size_t n, double tol,
                         uint32_t *par);

#endif
