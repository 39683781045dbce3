/* Geometric predicates of the extrusion code, exact in their sign.
 *
 * ag_pred_orient2d is filtered-then-exact in the style of Shewchuk's adaptive predicates:
 * the determinant is evaluated in double with a forward error bound; only when its
 * magnitude is below the bound is it recomputed exactly, as a sum of the six products of
 * the expanded determinant, each split exactly into two doubles with fma(), added up as a
 * non-overlapping expansion. Nothing in Debian offers such predicates to a C library
 * without C++ (CGAL's are C++ templates; Shewchuk's predicates.c is not packaged), so they
 * are written here; they need only libm.
 *
 * Every decision built on them (two segments cross, a point is inside a polygon, three
 * corners turn left, two directions are ordered around a point) is then exact for the
 * doubles given: a plan's validity does not depend on rounding. */
#ifndef AG_EXTRUDE_PREDICATES_H
#define AG_EXTRUDE_PREDICATES_H

#include <stddef.h>

/* Twice the signed area of triangle abc: > 0 when a, b, c turn left, < 0 right, 0 exactly
 * when they are collinear. The sign is exact; the magnitude is a double approximation. */
double ag_pred_orient2d(const double *a, const double *b, const double *c);

/* The sign (-1, 0, 1) of the cross product u x v of two vectors given by their
 * components (exact: the same expansion arithmetic). */
int ag_pred_cross_sign(double ux, double uy, double vx, double vy);

/* Do the closed segments ab and cd share a point? Exact. */
int ag_pred_segments_touch(const double *a, const double *b, const double *c, const double *d);

/* Do the segments ab and cd cross properly (their interiors meet in one point, no
 * endpoint on the other segment)? Exact. */
int ag_pred_segments_cross(const double *a, const double *b, const double *c, const double *d);

/* Is p inside the polygon (n corners, xy pairs)? Even-odd rule, exact; points on the
 * boundary may go either way. */
int ag_pred_point_in_polygon(const double *xy, size_t n, double px, double py);

/* Distance of p from the closed segment ab (a double approximation, not exact; a
 * degenerate segment is its point a). */
double ag_pred_segment_dist(const double *p, const double *a, const double *b);

#endif
