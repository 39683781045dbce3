#include "box.h"

int ag_box_is_empty(const ag_box *b)
{
    for (int a = 0; a < 3; a++)
        if (!(b->min[a] <= b->max[a]))
            return 1;
    return 0;
}

double ag_box_diagonal(const ag_box *b)
{
    if (ag_box_is_empty(b))
        return 0.0;
    double dx = b->max[0] - b->min[0], dy = b->max[1] - b->min[1], dz = b->max[2] - b->min[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

double ag_box_volume(const ag_box *b)
{
    if (ag_box_is_empty(b))
        return 0.0;
    return (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]) * (b->max[2] - b->min[2]);
}

double ag_box_volume_floor(const ag_box *b, double min_extent)
{
    double v = 1;
    for (int a = 0; a < 3; a++) {
        double d = b->max[a] - b->min[a];
        v *= d > min_extent ? d : min_extent;
    }
    return v;
}

int ag_box_contains(const ag_box *outer, const ag_box *inner, double eps)
{
    for (int a = 0; a < 3; a++)
        if (inner->min[a] < outer->min[a] - eps || inner->max[a] > outer->max[a] + eps)
            return 0;
    return 1;
}

int ag_box_contains_point(const ag_box *b, const double p[3], double eps)
{
    for (int a = 0; a < 3; a++)
        if (p[a] < b->min[a] - eps || p[a] > b->max[a] + eps)
            return 0;
    return 1;
}

int ag_box_meets_axis(const ag_box *a, const ag_box *b, int axis, double eps)
{
    return a->min[axis] <= b->max[axis] + eps && b->min[axis] <= a->max[axis] + eps;
}

int ag_box_meets(const ag_box *a, const ag_box *b, double eps)
{
    for (int k = 0; k < 3; k++)
        if (a->min[k] > b->max[k] + eps || b->min[k] > a->max[k] + eps)
            return 0;
    return 1;
}

double ag_box_overlap_axis(const ag_box *a, const ag_box *b, int axis)
{
    double lo = a->min[axis] > b->min[axis] ? a->min[axis] : b->min[axis];
    double hi = a->max[axis] < b->max[axis] ? a->max[axis] : b->max[axis];
    return hi - lo;
}

ag_box ag_box_intersect(const ag_box *a, const ag_box *b)
{
    ag_box r;
    for (int k = 0; k < 3; k++) {
        r.min[k] = a->min[k] > b->min[k] ? a->min[k] : b->min[k];
        r.max[k] = a->max[k] < b->max[k] ? a->max[k] : b->max[k];
    }
    if (ag_box_is_empty(&r))
        return ag_box_empty();
    return r;
}

void ag_box_clamp(ag_box *b, const ag_box *outer)
{
    for (int a = 0; a < 3; a++) {
        if (b->min[a] < outer->min[a])
            b->min[a] = outer->min[a];
        if (b->max[a] > outer->max[a])
            b->max[a] = outer->max[a];
        if (b->max[a] < b->min[a])
            b->max[a] = b->min[a];
    }
}
