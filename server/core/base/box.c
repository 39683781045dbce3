#include "box.h"

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

int ag_box_contains_point(const ag_box *b, const double p[3], double eps)
{
    for (int a = 0; a < 3; a++)
        if (p[a] < b->min[a] - eps || p[a] > b->max[a] + eps)
            return 0;
    return 1;
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
