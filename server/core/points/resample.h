/* Density-preserving resampling: how archgram keeps a point model at the sampling density of
 * its input through consensus, stretching and pasting (§4.1, §5.1).
 *
 * The paper uses edge-aware resampling (EAR, Huang et al.); archgram uses three simpler,
 * deterministic steps with the same aim, each measured by the tests in points per square
 * metre:
 *
 * - Thinning (consensus models): the merged members are k times denser than one member. They
 *   are thinned by a disk rule: in a fixed order (the base's points first), a point is kept
 *   when no point kept before it lies within a radius r (input points are kept, so edges and
 *   corners are not rounded off), r found by bisection so that the count matches the target:
 *   the base's count times the merged surface's area over the base's (areas measured as
 *   occupied cells of four point spacings, the pool's at one member's density). A disk rule
 *   gives the same density wherever the pool is dense enough, whether three members or thirty
 *   sampled a part and however thick their registration left the surface (a grid of cells,
 *   tried first, gives thick parts more cells). Where the base was sampled its points stay;
 *   what the other members add (an occluded part) comes at that density too.
 * - Stretch compensation (a placement scaled by an edit): a point of a surface with normal n
 *   under the linear map A covers |cof(A) n| times its former area (cof(A) = det(A) A^-T), so
 *   it is emitted that many times on average (the whole part, and one more with the fraction as
 *   probability); the extra copies are spread over a disk of half a spacing in the point's
 *   tangent plane before the map, so they fill its stretched cell. A squeezed point (factor
 *   below 1) is kept with that probability. Random choices hash (seed, point, copy): the same
 *   model always gives the same cloud.
 * - Seams (placements that overlap after an edit: copies side by side, a paste over a wall):
 *   in the overlap of two placements' boxes, grown by two spacings, a point of the later one
 *   closer than a third of a spacing to a point of the earlier one is dropped, so overlapping
 *   copies do not double the density there. Gaps are not filled (nothing says what was
 *   there). */
#ifndef AG_RESAMPLE_H
#define AG_RESAMPLE_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

/* Cells of size h (a grid anchored at origin) occupied by the points idx[0..n) of xyz (all
 * of the first n points when idx is NULL). */
ag_status ag_resample_occupied(const double *xyz, const uint32_t *idx, size_t n, double h,
                               const double origin[3], size_t *count, ag_error *err);

/* Thins the first n points of xyz to about target (within 2 %, or the closest the bisection
 * reaches) as above, preferring earlier points; keep (n entries) receives the kept points'
 * indices, ascending, *nkeep their count and *cell (optional) the disk radius used. n <= target keeps every point. */
ag_status ag_resample_thin(const double *xyz, size_t n, size_t target, uint32_t *keep,
                           size_t *nkeep, double *cell, ag_error *err);

/* The area factor |cof(A) n| of a unit normal n under A (3x3, row-major). */
double ag_resample_area_factor(const double A[3][3], const float n[3]);

/* How many copies point i of a placement with area factor f emits (see above). */
unsigned ag_resample_copies(double f, uint64_t seed, uint64_t i);

/* Offset d of copy `copy` (>= 1) of point i: uniform in the disk of the given radius in the
 * plane normal to n. */
void ag_resample_jitter(const float n[3], double radius, uint64_t seed, uint64_t i,
                        unsigned copy, double d[3]);

/* drop[j] = 1 for each point b[j] within r of some point a[k] (indices into xyz). */
ag_status ag_resample_dedupe(const double *xyz, const uint32_t *a, size_t na,
                             const uint32_t *b, size_t nb, double r, uint8_t *drop,
                             ag_error *err);

#endif
