#include "predicates.h"

#include <float.h>
#include <math.h>

/* --- expansion arithmetic (Shewchuk 1997) --------------------------------------------------
 * An expansion is a sum of doubles ordered by magnitude whose nonzero components do not
 * overlap; its sign is the sign of its largest component. */

/* a + b = x + y exactly, x = fl(a + b). */
static inline void two_sum(double a, double b, double *x, double *y)
{
    double s = a + b, bv = s - a, av = s - bv;
    *x = s;
    *y = (a - av) + (b - bv);
}

/* a * b = x + y exactly (fma computes the rounding error of the product). */
static inline void two_product(double a, double b, double *x, double *y)
{
    double p = a * b;
    *x = p;
    *y = fma(a, b, -p);
}

/* h = e + b (e an expansion of n components, h gets n + 1). */
static int grow_expansion(int n, const double *e, double b, double *h)
{
    double q = b;
    for (int i = 0; i < n; i++) {
        double s, t;
        two_sum(q, e[i], &s, &t);
        h[i] = t;
        q = s;
    }
    h[n] = q;
    return n + 1;
}

static int expansion_sign(int n, const double *e)
{
    for (int i = n - 1; i >= 0; i--)
        if (e[i] != 0)
            return e[i] > 0 ? 1 : -1;
    return 0;
}

/* Exact sign of p1 q1 - p2 q2 + p3 q3 - ... given as products of pairs (sign +/- each). */
static int exact_sign(const double *f, const int *sg, int nprod)
{
    double e[32], h[32];
    int n = 0;
    for (int k = 0; k < nprod; k++) {
        double x, y;
        two_product(f[2 * k], f[2 * k + 1], &x, &y);
        if (sg[k] < 0) {
            x = -x;
            y = -y;
        }
        n = grow_expansion(n, e, y, h);
        for (int i = 0; i < n; i++)
            e[i] = h[i];
        n = grow_expansion(n, e, x, h);
        for (int i = 0; i < n; i++)
            e[i] = h[i];
    }
    return expansion_sign(n, e);
}

/* Relative error bound of the double evaluation of a 2 x 2 determinant of differences
 * (Shewchuk's ccwerrboundA = (3 + 16 eps) eps, eps = 2^-53). */
#define CCW_ERRBOUND ((3.0 + 16.0 * (DBL_EPSILON / 2)) * (DBL_EPSILON / 2))

double ag_pred_orient2d(const double *a, const double *b, const double *c)
{
    double detleft = (a[0] - c[0]) * (b[1] - c[1]);
    double detright = (a[1] - c[1]) * (b[0] - c[0]);
    double det = detleft - detright;
    double bound = CCW_ERRBOUND * (fabs(detleft) + fabs(detright));
    if (det > bound || -det > bound)
        return det;
    /* (ax - cx)(by - cy) - (ay - cy)(bx - cx) expanded: the cx cy terms cancel */
    const double f[12] = {a[0], b[1], a[0], c[1], c[0], b[1],
                          a[1], b[0], a[1], c[0], c[1], b[0]};
    const int sg[6] = {1, -1, -1, -1, 1, 1};
    int s = exact_sign(f, sg, 6);
    if (s == 0)
        return 0;
    /* the sign is exact; keep a magnitude that is not smaller than rounding noise */
    double mag = fmax(fabs(det), DBL_MIN);
    return s > 0 ? mag : -mag;
}

int ag_pred_cross_sign(double ux, double uy, double vx, double vy)
{
    double l = ux * vy, r = uy * vx, d = l - r;
    double bound = 2 * DBL_EPSILON * (fabs(l) + fabs(r));
    if (d > bound)
        return 1;
    if (-d > bound)
        return -1;
    const double f[4] = {ux, vy, uy, vx};
    const int sg[2] = {1, -1};
    return exact_sign(f, sg, 2);
}

static int sign_of(double v)
{
    return v > 0 ? 1 : v < 0 ? -1 : 0;
}

/* Is p, collinear with segment ab, within its bounding box? */
static int on_segment(const double *a, const double *b, const double *p)
{
    return p[0] >= fmin(a[0], b[0]) && p[0] <= fmax(a[0], b[0]) && p[1] >= fmin(a[1], b[1]) &&
           p[1] <= fmax(a[1], b[1]);
}

int ag_pred_segments_touch(const double *a, const double *b, const double *c, const double *d)
{
    int o1 = sign_of(ag_pred_orient2d(a, b, c)), o2 = sign_of(ag_pred_orient2d(a, b, d));
    int o3 = sign_of(ag_pred_orient2d(c, d, a)), o4 = sign_of(ag_pred_orient2d(c, d, b));
    if (o1 * o2 < 0 && o3 * o4 < 0)
        return 1;
    return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
           (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

int ag_pred_segments_cross(const double *a, const double *b, const double *c, const double *d)
{
    int o1 = sign_of(ag_pred_orient2d(a, b, c)), o2 = sign_of(ag_pred_orient2d(a, b, d));
    int o3 = sign_of(ag_pred_orient2d(c, d, a)), o4 = sign_of(ag_pred_orient2d(c, d, b));
    return o1 * o2 < 0 && o3 * o4 < 0;
}

int ag_pred_point_in_polygon(const double *xy, size_t n, double px, double py)
{
    int in = 0;
    const double p[2] = {px, py};
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double *a = &xy[2 * j], *b = &xy[2 * i];
        if ((b[1] > py) != (a[1] > py)) {
            /* p is left of the upward edge (or right of the downward one): the ray to +x
             * crosses it; exact through the orientation of (lower, upper, p) */
            const double *lo = a[1] < b[1] ? a : b, *hi = a[1] < b[1] ? b : a;
            if (ag_pred_orient2d(lo, hi, p) > 0)
                in = !in;
        }
    }
    return in;
}

double ag_pred_segment_dist(const double *p, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
}
