/* Welding of points closer than a tolerance (a sweep along sorted x, union-find of
 * core/base/uf.h), shared by the shell's linking and the building check.
 *
 * Why this is not core/proc/weld.c's ag__weld: that one quantizes to a grid (points in one
 * hash cell get one id), which is what segmentation wants — cheap, one pass, and two points
 * either side of a cell border stay apart. The extrusion checks must join every pair within
 * the tolerance, transitively, wherever the cell borders fall (a closed shell whose corners
 * straddle a border would otherwise be reported open), and must not join farther points; the
 * sweep does exactly that at O(n log n). One helper for both would change one of their
 * answers. */
#ifndef AG_EXTRUDE_WELD_H
#define AG_EXTRUDE_WELD_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "keysort.h"

/* order holds n entries (ag_keysort_double(x of the vertex), vertex) for the vertices to
 * weld (a vertex may be listed more than once); pos holds x, y, z per vertex. Afterwards
 * par[v] is the smallest vertex v is welded to, for every vertex listed: points within tol,
 * transitively. order is sorted in place. AG_ERR_NOMEM, AG_ERR_TOO_LARGE. */
ag_status ag_weld_points(const double *pos, ag_keyed *order, size_t n, double tol,
                         uint32_t *par);

#endif
