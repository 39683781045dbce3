#include <stddef.h>

#include "predicates.h"

static int on_segment(const double *a, const double *b, const double *p)
{
    double minx = a[0] < b[0] ? a[0] : b[0], maxx = a[0] < b[0] ? b[0] : a[0];
    double miny = a[1] < b[1] ? a[1] : b[1], maxy = a[1] < b[1] ? b[1] : a[1];
    return p[0] >= minx && p[0] <= maxx && p[1] >= miny && p[1] <= maxy;
}

static int sgn(double v, double eps)
{
    return v > eps ? 1 : (v < -eps ? -1 : 0);
}

int ag_pred_segments_touch(const double *a, const double *b, const double *c, const double *d,
                           double eps)
{
    int o1 = sgn(ag_pred_orient2d(a, b, c), eps), o2 = sgn(ag_pred_orient2d(a, b, d), eps);
    int o3 = sgn(ag_pred_orient2d(c, d, a), eps), o4 = sgn(ag_pred_orient2d(c, d, b), eps);
    if (o1 * o2 < 0 && o3 * o4 < 0)
        return 1;
    if (o1 == 0 && on_segment(a, b, c))
        return 1;
    if (o2 == 0 && on_segment(a, b, d))
        return 1;
    if (o3 == 0 && on_segment(c, d, a))
        return 1;
    if (o4 == 0 && on_segment(c, d, b))
        return 1;
    return 0;
}

int ag_pred_point_in_polygon(const double *xy, size_t n, double px, double py)
{
    int in = 0;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        double xi = xy[2 * i], yi = xy[2 * i + 1], xj = xy[2 * j], yj = xy[2 * j + 1];
        if ((yi > py) != (yj > py)) {
            double x = xj + (py - yj) * (xi - xj) / (yi - yj);
            if (px < x)
                in = !in;
        }
    }
    return in;
}
