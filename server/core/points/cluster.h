/* Connected pieces of point sets.
 *
 * Components: each plane's inliers split into pieces connected through the neighbour
 * graph (two points are connected when one is among the other's k nearest and they are at
 * most `radius` apart). Pieces on a grid: the same on a grid of cells, for gaps larger than
 * the graph reaches. Euclidean clustering: what no plane holds is grouped into clusters
 * whose points are chained by gaps below the tolerance T_C (single linkage, as PCL's
 * Euclidean cluster extraction that the paper uses), on the grid: linear time at any
 * density. */
#ifndef AG_CLUSTER_H
#define AG_CLUSTER_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"
#include "ransac.h"

/* Relabels: every point with labels[i] >= 0 gets the index of its connected component
 * within its label (components numbered from 0 in order of their first point); points in
 * components smaller than min_size get -1. *ncomponents receives the count; comp_of_label
 * (optional, ncomponents entries, malloc'd) the label each component came from. */
ag_status ag_cluster_components(const ag_cloud *c, const ag_ransac_graph *g, double radius,
                                int32_t *labels, size_t min_size, size_t *ncomponents,
                                int32_t **comp_of_label, ag_error *err);

/* Pieces of each label on a grid of cell size `cell`: points of one label whose cells touch
 * (26-neighbourhood) are one piece, so pieces closer than `cell` are always joined and pieces
 * farther apart than about twice `cell` never are. Linear time, whatever the gap. Points in
 * pieces smaller than min_size get labels[i] = -1 and piece[i] = -1; the others get their
 * piece number (from 0) in piece[i]. *npieces receives the count. */
ag_status ag_cluster_pieces(const ag_cloud *c, int32_t *labels, double cell, size_t min_size,
                            int32_t *piece, size_t *npieces, ag_error *err);

/* Clusters the points idx[0..m): out[idx[j]] = first_id + cluster, or -1 for clusters
 * smaller than min_size. *nclusters receives the count of clusters kept. Points closer than
 * the tolerance are always in one cluster; the chain may also bridge gaps up to about 3.5
 * times the tolerance (cells of the tolerance's size that touch). */
ag_status ag_cluster_euclidean(const ag_cloud *c, const uint32_t *idx, size_t m, double tolerance,
                               size_t min_size, int32_t first_id, int32_t *out, size_t *nclusters,
                               ag_error *err);

#endif
