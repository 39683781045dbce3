/* Per-point normals by principal component analysis of the k nearest neighbours.
 *
 * The normal is the eigenvector of the smallest eigenvalue of the neighbourhood's
 * covariance; the surface variation l0 / (l0 + l1 + l2) says how planar the neighbourhood
 * is (0 flat, 1/3 isotropic). Normals are oriented by the building convention: up when
 * they are closer to vertical than 60 degrees, else away from the cloud's vertical axis
 * through its centroid. */
#ifndef AG_NORMALS_H
#define AG_NORMALS_H

#include "../base/kdtree.h"
#include "../status.h"
#include "cloud.h"

typedef struct {
    unsigned k; /* neighbours including the point itself; 0 = 16 */
    /* Called every few thousand points with the fraction done; non-zero cancels. */
    int (*progress)(void *user, double fraction);
    void *user;
} ag_normals_options;

typedef struct {
    double spacing; /* median distance from a point to its nearest other point */
} ag_normals_info;

/* Fills c->normals (allocating them) from the tree over c's points. Optional outputs:
 * `variation` (n floats) the surface variation per point; `neighbours` (n * k ids) the k
 * nearest points of each point, nearest first (the point itself first; a cloud of fewer
 * than k points repeats the last one), reused by the segmentation as its graph. */
ag_status ag_normals_compute(ag_cloud *c, const ag_kdtree *tree, const ag_normals_options *opt,
                             float *variation, uint32_t *neighbours, ag_normals_info *info,
                             ag_error *err);

/* Mean and covariance {xx, xy, xz, yy, yz, zz} (sums, not divided) of the points
 * xyz[3*idx[j]..] for j < m, or of the first m points when idx is NULL. */
void ag_normals_covariance(const double *xyz, const uint32_t *idx, size_t m, double mean[3],
                           double cov[6]);

/* The unit eigenvector of the smallest eigenvalue of the symmetric 3x3 matrix
 * {a00, a01, a02, a11, a12, a22}, and the eigenvalues ascending in ev (optional). */
void ag_normals_smallest_eigenvector(const double a[6], double n[3], double ev[3]);

#endif
