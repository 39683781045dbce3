/* A kd-tree over 3D points for k-nearest-neighbour and radius queries.
 *
 * Built once (median splits on the widest axis, small leaves, the points copied into tree
 * order so that a query touches few cache lines) and then only read, so one tree can serve
 * normals, plane fitting and clustering in turn. Indices are the caller's point numbers. */
#ifndef AG_KDTREE_H
#define AG_KDTREE_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef struct ag_kdtree ag_kdtree;

/* Builds a tree over the points xyz[3*i..3*i+2] for i in subset[0..n), or for i in [0, n)
 * when subset is NULL. Positions are copied; xyz may be freed afterwards. n must be below
 * 2^32 (AG_ERR_TOO_LARGE). An empty tree is valid and answers every query with nothing. */
ag_status ag_kdtree_build(const double *xyz, const uint32_t *subset, size_t n, ag_kdtree **out,
                          ag_error *err);
void ag_kdtree_free(ag_kdtree *t);

size_t ag_kdtree_size(const ag_kdtree *t);
/* The point numbers in tree order: neighbours in space are mostly neighbours here, so
 * iterating queries in this order is cache-friendly. */
const uint32_t *ag_kdtree_order(const ag_kdtree *t);

/* The min(k, size) points nearest to q (q itself included when it is a tree point), nearest
 * first: their numbers in idx and squared distances in d2 (optional). Returns the count. */
size_t ag_kdtree_knn(const ag_kdtree *t, const double q[3], size_t k, uint32_t *idx, double *d2);

/* The same as ag_kdtree_knn (d2 required), faster when hint holds k distinct
 * tree points near q (the neighbours of the previous query in tree order): their farthest
 * bounds the search from the start. xyz are the positions the tree was built from. */
size_t ag_kdtree_knn_hint(const ag_kdtree *t, const double q[3], size_t k, const uint32_t *hint,
                          const double *xyz, uint32_t *idx, double *d2);

/* Calls fn for every tree point, in tree order, with its min(k, size) nearest points,
 * nearest first (k <= 64), and their positions (the tree's copies, close together in memory):
 * the answers of ag_kdtree_knn, faster, because each search starts
 * bounded by the previous point's neighbours (close by in tree order). A non-zero return
 * from fn stops; it is returned. */
typedef int (*ag_kdtree_knn_fn)(void *user, uint32_t id, const uint32_t *ids, const double *d2,
                                const double *const *pos, size_t m);
int ag_kdtree_knn_each(const ag_kdtree *t, size_t k, ag_kdtree_knn_fn fn, void *user);

/* Calls visit for every point within distance r of q (inclusive), in no particular order.
 * A non-zero return from visit stops the query; that value is returned, else 0. */
typedef int (*ag_kdtree_visit)(void *user, uint32_t id, double d2);
int ag_kdtree_radius(const ag_kdtree *t, const double q[3], double r, ag_kdtree_visit visit,
                     void *user);

#endif
