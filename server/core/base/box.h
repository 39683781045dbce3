/* Axis-aligned boxes: the bounds of meshes, split-tree nodes and edit targets.
 *
 * A box has six coordinates, numbered 0..2 for min x, y, z and 3..5 for max x, y, z (the
 * numbering attachment equations use). The empty box has min = +inf and max = -inf on every
 * axis, so extending it by a point or a box gives exactly that point or box. Tolerances are
 * absolute (metres): a test "within eps" treats boxes grown by eps on every side. */
#ifndef AG_BOX_H
#define AG_BOX_H

#include <math.h>

typedef struct {
    double min[3];
    double max[3];
} ag_box;

static inline ag_box ag_box_empty(void)
{
    return (ag_box){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
}

/* Non-zero when min <= max fails on some axis (the empty box, or a NaN). */
static inline int ag_box_is_empty(const ag_box *b)
{
    for (int a = 0; a < 3; a++)
        if (!(b->min[a] <= b->max[a]))
            return 1;
    return 0;
}

static inline void ag_box_extend_point(ag_box *b, const double p[3])
{
    for (int a = 0; a < 3; a++) {
        if (p[a] < b->min[a])
            b->min[a] = p[a];
        if (p[a] > b->max[a])
            b->max[a] = p[a];
    }
}

static inline void ag_box_extend_box(ag_box *b, const ag_box *o)
{
    for (int a = 0; a < 3; a++) {
        if (o->min[a] < b->min[a])
            b->min[a] = o->min[a];
        if (o->max[a] > b->max[a])
            b->max[a] = o->max[a];
    }
}

/* max - min on one axis (negative for an empty box). */
static inline double ag_box_extent(const ag_box *b, int axis)
{
    return b->max[axis] - b->min[axis];
}

static inline void ag_box_extents(const ag_box *b, double e[3])
{
    for (int a = 0; a < 3; a++)
        e[a] = b->max[a] - b->min[a];
}

static inline double ag_box_centre_axis(const ag_box *b, int axis)
{
    return 0.5 * (b->min[axis] + b->max[axis]);
}

static inline void ag_box_centre(const ag_box *b, double c[3])
{
    for (int a = 0; a < 3; a++)
        c[a] = 0.5 * (b->min[a] + b->max[a]);
}

/* Coordinate c in 0..5 (min x, y, z, max x, y, z). */
static inline double ag_box_coord(const ag_box *b, int c)
{
    return (c < 3 ? b->min : b->max)[c % 3];
}

static inline void ag_box_set_coord(ag_box *b, int c, double v)
{
    (c < 3 ? b->min : b->max)[c % 3] = v;
}

/* Length of the diagonal; 0 for an empty box. */
double ag_box_diagonal(const ag_box *b);

/* Product of the extents; 0 for an empty box. */
double ag_box_volume(const ag_box *b);

/* Product of the extents, each raised to at least min_extent: orders flat boxes by area. */
static inline double ag_box_volume_floor(const ag_box *b, double min_extent)
{
    double v = 1;
    for (int a = 0; a < 3; a++) {
        double d = b->max[a] - b->min[a];
        v *= d > min_extent ? d : min_extent;
    }
    return v;
}

/* Non-zero when inner lies within outer grown by eps. */
static inline int ag_box_contains(const ag_box *outer, const ag_box *inner, double eps)
{
    for (int a = 0; a < 3; a++)
        if (inner->min[a] < outer->min[a] - eps || inner->max[a] > outer->max[a] + eps)
            return 0;
    return 1;
}

/* Non-zero when p lies within b grown by eps. */
int ag_box_contains_point(const ag_box *b, const double p[3], double eps);

/* Non-zero when a and b overlap or touch within eps on every axis / on one axis. */
static inline int ag_box_meets(const ag_box *a, const ag_box *b, double eps)
{
    for (int k = 0; k < 3; k++)
        if (a->min[k] > b->max[k] + eps || b->min[k] > a->max[k] + eps)
            return 0;
    return 1;
}

static inline int ag_box_meets_axis(const ag_box *a, const ag_box *b, int axis, double eps)
{
    return a->min[axis] <= b->max[axis] + eps && b->min[axis] <= a->max[axis] + eps;
}

/* Length of the overlap of a and b on one axis: negative for the gap between them. */
static inline double ag_box_overlap_axis(const ag_box *a, const ag_box *b, int axis)
{
    double lo = a->min[axis] > b->min[axis] ? a->min[axis] : b->min[axis];
    double hi = a->max[axis] < b->max[axis] ? a->max[axis] : b->max[axis];
    return hi - lo;
}

/* The common part of a and b (an empty box when they are disjoint). */
ag_box ag_box_intersect(const ag_box *a, const ag_box *b);
/* Cuts b down to outer (a window kept inside its wall); an axis where nothing is left
 * collapses to zero length at its cut-down min (max = min), so b stays a valid box. */
void ag_box_clamp(ag_box *b, const ag_box *outer);

#endif
