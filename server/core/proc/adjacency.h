/* Adjacency of a split tree's visible nodes: every pair whose boxes meet (touch or overlap
 * within the tree's tolerance tol on every axis), each pair once as (smaller node index,
 * larger), the pairs sorted so. The order is the nodes' alone, so a tree's pairs do not
 * depend on how they were found (from scratch or brought up to date).
 *
 * The tree keeps what its pairs were found for (adj_seen: per node its box and whether it was
 * visible, and adj_tol), and copies keep it with the pairs: an edited copy brings its pairs up
 * to date from those, finding again only the pairs of the nodes whose box or visibility
 * changed (pairs of two unchanged boxes are unchanged). */
#ifndef AG_ADJACENCY_H
#define AG_ADJACENCY_H

#include "../status.h"
#include "splittree.h"

/* The pairs found from scratch (O(n log n) in the nodes and pairs). AG_ERR_NOMEM. */
ag_status ag_splittree_adjacency(ag_splittree *t);

/* The pairs brought up to date with t's current boxes, kinds and tolerance: exactly what
 * ag_splittree_adjacency would find. Only the changed nodes' neighbours are searched (in a
 * bounding-box hierarchy over the visible boxes, O(n) to build, about log n per pair found);
 * the pairs of two unchanged nodes are kept as they are (one O(pairs) copy, no geometry).
 * It finds them all from scratch when
 * it knows nothing of them (no adj_seen), when the tolerance changed, or when half of the
 * visible nodes or more changed. *from_scratch (may be NULL) says which it did. AG_ERR_NOMEM
 * (t then has no pairs and knows nothing of them). */
ag_status ag_splittree_adjacency_update(ag_splittree *t, int *from_scratch);

/* Moves from's pairs and what they were found for onto t (t's own freed; from is left with
 * none): t then updates from them. */
void ag_splittree_adjacency_take(ag_splittree *t, ag_splittree *from);

#endif
