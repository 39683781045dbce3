/* Plane detection by RANSAC, in the two passes of the segmentation (§3.1).
 *
 * Global pass (the paper's): a candidate plane is scored by the inliers it has among a
 * random sample of the points still free, within a distance threshold; the best of a round
 * is refitted by least squares to all its inliers and taken when it has enough of them.
 * With the paper's 2.5 % of the diagonal this finds the dominant planes of a building, and
 * merges its details.
 *
 * Local pass (the refinement): a smaller threshold and a normal-angle test, and candidates
 * generated from the flattest points first (their PCA normals are the hypotheses); a
 * candidate's support is the set of inliers connected to it through the neighbour graph,
 * refitted twice. Scoring by connected support (as in Schnabel et al.'s efficient RANSAC)
 * finds small planes — a ledge of 20 points — that a global sample would never see.
 *
 * Both work on the points of a region of the cloud that no plane holds yet, and append the
 * planes they find to a list; plane_of[i] (one entry per cloud point) receives the index. */
#ifndef AG_RANSAC_H
#define AG_RANSAC_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"

typedef struct {
    double n[3];   /* unit normal */
    double d;      /* n . p + d = 0 for points p on the plane */
    size_t count;  /* inliers taken */
} ag_plane;

typedef struct {
    ag_plane *items;
    size_t n, cap;
} ag_plane_list;

void ag_plane_list_free(ag_plane_list *l);

/* Least-squares plane (smallest principal axis) through the points idx[0..m); returns -1
 * for fewer than three points or a degenerate set. pl->count is set to m. */
int ag_ransac_fit(const double *xyz, const uint32_t *idx, size_t m, ag_plane *pl);

typedef struct {
    double threshold;    /* inlier distance in metres (> 0) */
    double max_angle;    /* degrees between a point's normal and the plane's; 0: no test */
    size_t min_points;   /* smallest plane taken (>= 3) */
    unsigned max_planes; /* planes per call; 0: 2000 for the global pass, no limit for the
                          * local one (its work is bounded by the points) */
    /* global pass */
    unsigned hypotheses; /* candidates per round; 0 = 256 */
    unsigned sample;     /* points a candidate is scored on; 0 = 4096 */
    unsigned failures;   /* rounds without a plane before giving up; 0 = 3 */
    uint64_t seed;
    int adaptive;            /* narrow the threshold to a clean plane's own noise */
    const ag_plane *extra;   /* planes tried as candidates in every round until one wins */
    size_t nextra;           /* (the coarse planes, for the refinement) */
    /* local pass */
    double radius;       /* neighbours farther apart than this are not connected; 0: any */
    /* Called now and then with a rough fraction done; non-zero cancels. */
    int (*progress)(void *user, double fraction);
    void *user;
} ag_ransac_options;

/* The neighbour graph the local pass walks: k neighbours per point (from the normals). */
typedef struct {
    const uint32_t *ids; /* n * k */
    unsigned k;
} ag_ransac_graph;

/* Global pass: candidates drawn from and scored on the points idx[0..m) that have
 * plane_of < 0; a candidate that wins takes its inliers among the free points of
 * universe[0..nu) (idx itself when universe is NULL), so that a plane found from one part
 * of the cloud is not cut at that part's border. Needs c->normals when max_angle > 0. */
ag_status ag_ransac_global(const ag_cloud *c, const uint32_t *idx, size_t m,
                           const uint32_t *universe, size_t nu, const ag_ransac_options *o,
                           int32_t *plane_of, ag_plane_list *planes, ag_error *err);

/* Local pass over the points idx[0..m) (seed candidates; ordered by ascending variation
 * when given) that have plane_of < 0 and, when region is not NULL, region[i] == region_id.
 * Needs c->normals. */
ag_status ag_ransac_local(const ag_cloud *c, const ag_ransac_graph *g, const float *variation,
                          const uint32_t *idx, size_t m, const int32_t *region, int32_t region_id,
                          const ag_ransac_options *o, int32_t *plane_of, ag_plane_list *planes,
                          ag_error *err);

#endif
