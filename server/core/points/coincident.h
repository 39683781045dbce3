/* Coincident points: points closer than a tolerance are one point.
 *
 * A cloud merged from two passes of one scan, or written twice over, holds each point more
 * than once. Copies carry no geometry, yet they change what a kNN neighbourhood sees (half of
 * a point's k neighbours are itself, and the nearest-neighbour spacing becomes 0), so the
 * segmentation runs on the distinct points and gives each copy its original's answer. */
#ifndef AG_POINTS_COINCIDENT_H
#define AG_POINTS_COINCIDENT_H

#include <stddef.h>
#include <stdint.h>

#include "../base/kdtree.h"
#include "../status.h"

/* Points in a cloud's own units this close are one: far below any scanner's resolution
 * (LAS files store millimetres or tenths of them), far above rounding at UTM offsets. */
#define AG_COINCIDENT_TOLERANCE 1e-5

/* For the n points of tree (built over xyz[3*i..3*i+2], i in [0, n)): rep[i] is the smallest
 * point that i is joined to, through points within tol of each other. Each query stops after
 * AG_COINCIDENT_MAX_VISIT neighbours, so a dense pile costs O(n) and is joined through its
 * members' own queries. *ndistinct (optional) counts the points with rep[i] == i.
 * AG_ERR_NOMEM. */
#define AG_COINCIDENT_MAX_VISIT 64
ag_status ag_coincident_points(const ag_kdtree *tree, const double *xyz, size_t n, double tol,
                               uint32_t *rep, size_t *ndistinct, ag_error *err);

#endif
