/* A level-of-detail order of a point cloud: a permutation of its points such that every
 * prefix is an even subsample of the whole cloud, so that a viewer asking for N points gets
 * the first N of one stored order instead of a subsample computed per request.
 *
 * The cloud's bounding cube is divided into a hierarchy of cells (level L: 2^L cells per
 * axis). Every point draws a seeded random key; a point's level is the coarsest level at
 * which it has the smallest key of its cell. The order is by level, then key: a prefix holds
 * one point of every occupied cell of the levels it completes and a random share of the next
 * level, so sparse parts of a cloud are not thinned more than dense ones until the cells get
 * as fine as the points. Deterministic for a seed; O(n log n). Core: no I/O. */
#ifndef AG_POINTS_LOD_H
#define AG_POINTS_LOD_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"

/* Writes the c->n point indices in level-of-detail order to order (c->n entries). seed 0
 * means a fixed default. AG_ERR_TOO_LARGE for clouds of 2^32 points or more, AG_ERR_NOMEM. */
ag_status ag_lod_order(const ag_cloud *c, uint64_t seed, uint32_t *order, ag_error *err);

#endif
