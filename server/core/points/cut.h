/* Cutting a LiDAR tile into one cloud per building footprint.
 *
 * A point belongs to the footprint it lies in; a point in no footprint but within the
 * buffer of one or more belongs to the nearest (so row houses sharing a wall do not share
 * points). When the tile classifies buildings (ASPRS class 6), the buffer only takes class 6
 * points: it is there for walls and eaves just outside the footprint, not for the hedge
 * along them. Ground is then removed from each building: by classification 2 (ASPRS ground)
 * when the tile has a classification with ground in it, else by a ground plane fitted to
 * the lowest points of a ring around the footprint, removing what lies less than
 * `ground_height` above it. Footprint loops are in the cloud's local frame (x y pairs;
 * holes are loops too: a point is inside when it is inside an odd number of loops). */
#ifndef AG_CUT_H
#define AG_CUT_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"

typedef struct {
    size_t nloops;
    const size_t *sizes;          /* corners per loop */
    const double *const *loops;   /* x y pairs per loop, cloud-local metres */
} ag_cut_footprint;

typedef enum {
    AG_CUT_GROUND_AUTO = 0, /* classification 2 when present, else a plane */
    AG_CUT_GROUND_CLASS,
    AG_CUT_GROUND_PLANE,
    AG_CUT_GROUND_NONE,
} ag_cut_ground;

typedef struct {
    double buffer;        /* metres around each footprint; 0 = 0.5; < 0 none */
    ag_cut_ground ground;
    double ground_height; /* plane method: points less than this above the plane are ground;
                           * 0 = 0.5 metres */
} ag_cut_options;

typedef struct {
    size_t inside;         /* points inside the footprint */
    size_t buffered;       /* points taken from its buffer */
    size_t ground;         /* of these, removed as ground */
    size_t kept;           /* inside + buffered - ground */
    int by_class;          /* ground removed by classification (else by plane, or none) */
    double ground_z;       /* plane method: the plane's height at the footprint's centre */
} ag_cut_stats;

/* The method AG_CUT_GROUND_AUTO stands for on this cloud (class or plane); others as given. */
ag_cut_ground ag_cut_ground_method(const ag_cloud *c, ag_cut_ground requested);

/* owner[i] (one entry per point) receives the footprint index of point i, or -1 (outside
 * all, or ground); stats (optional, nfp entries) the counts per footprint. */
ag_status ag_cut_assign(const ag_cloud *c, const ag_cut_footprint *fps, size_t nfp,
                        const ag_cut_options *opt, int32_t *owner, ag_cut_stats *stats,
                        ag_error *err);

/* Whether (x, y) is inside the footprint (odd number of loops around it). */
int ag_cut_inside(const ag_cut_footprint *f, double x, double y);

/* Distance from (x, y) to the footprint's nearest edge. */
double ag_cut_edge_distance(const ag_cut_footprint *f, double x, double y);

#endif
