/* Geometric predicates for the extrusion sweep, evaluated in long double so that the
 * sign of nearly-degenerate configurations is right far more often than in double. */
#ifndef AG_EXTRUDE_PREDICATES_H
#define AG_EXTRUDE_PREDICATES_H

/* Twice the signed area of triangle abc: > 0 when a, b, c turn left. */
static inline double ag_pred_orient2d(const double *a, const double *b, const double *c)
{
    long double abx = (long double)b[0] - a[0], aby = (long double)b[1] - a[1];
    long double acx = (long double)c[0] - a[0], acy = (long double)c[1] - a[1];
    return (double)(abx * acy - aby * acx);
}

/* Do the closed segments ab and cd share a point? `eps` is an area tolerance below
 * which three points count as collinear. */
int ag_pred_segments_touch(const double *a, const double *b, const double *c, const double *d,
                           double eps);

/* Is p inside the polygon (n corners, xy pairs)? Even-odd rule; points on the boundary
 * may go either way. */
int ag_pred_point_in_polygon(const double *xy, size_t n, double px, double py);

#endif
