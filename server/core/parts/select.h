/* Selecting what to save or where to compose (paper §4.1): a selection window or a click,
 * then walking the split tree, then the common ancestor of what is selected.
 *
 * Only visible and pattern nodes are selectable and walked: intermediate split nodes are
 * skipped (a node's parent is its nearest non-split ancestor, its children the nodes its child
 * slots lead to). A selection window is either a world box (the visible nodes whose boxes lie
 * inside it) or a screen rectangle in normalized device coordinates with a view-projection
 * matrix (column-major, as WebGL and three.js keep it): a visible node is covered when all
 * eight corners of its box are in front of the camera and project inside the rectangle.
 * A click is a ray: the first triangle it hits names its component's node, a leaf. */
#ifndef AG_SELECT_H
#define AG_SELECT_H

#include <stddef.h>
#include <stdint.h>

#include "../proc/proceduralize.h"
#include "../status.h"

/* Visible nodes inside a world box, in tree order; *nodes malloc'd (NULL when none). */
ag_status ag_select_box(const ag_splittree *t, const ag_box *window, int32_t **nodes, size_t *n,
                        ag_error *err);
/* Visible nodes covered by the rectangle [x0, x1] x [y0, y1] of normalized device coordinates
 * (-1..1) under the view-projection matrix vp. */
ag_status ag_select_rect(const ag_splittree *t, const double vp[16], const double rect[4],
                         int32_t **nodes, size_t *n, ag_error *err);
/* The visible node of the first triangle hit by the ray origin + s dir (s > 0);
 * AG_ERR_NOT_FOUND when the ray hits nothing. */
ag_status ag_select_pick(const ag_proceduralize_result *r, const double origin[3],
                         const double dir[3], int32_t *node, ag_error *err);

/* Walking: the parent (-1 for the root), the children (up to cap written, the count
 * returned), the previous (dir -1) or next (dir +1) sibling, -1 when there is none. */
int32_t ag_select_parent(const ag_splittree *t, int32_t node);
size_t ag_select_children(const ag_splittree *t, int32_t node, int32_t *out, size_t cap);
int32_t ag_select_sibling(const ag_splittree *t, int32_t node, int dir);

/* Common ancestors by the paper's per-path stacks: every selected node's path from the root
 * is a stack of labels, walked level by level from the root while the labels of the level
 * have a non-empty intersection. At the tree level a label is the node itself (one common
 * ancestor); at the rule level it is the node's rule (a pattern's: its rule's pattern), so
 * that the windows of two facades meet at their rule: the distinct nodes of the last level
 * are offered (*nodes malloc'd, *n >= 1). Nodes must be live; AG_ERR_NOT_FOUND names one that
 * is not, AG_ERR_INVALID an empty selection. */
ag_status ag_select_common_tree(const ag_splittree *t, const int32_t *sel, size_t nsel,
                                int32_t *ancestor, ag_error *err);
ag_status ag_select_common_rule(const ag_splittree *t, const int32_t *sel, size_t nsel,
                                int32_t **nodes, size_t *n, ag_error *err);

#endif
