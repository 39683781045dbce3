/* Structure-preserving resize (see edit.h for the op and attach.h for the equations).
 *
 * 1. Units: the boxes the equations move are the visible nodes and the patterns (a pattern is
 *    one box whose cells are its lattice periods; an edited cell opens its pattern).
 * 2. The edited level: the op's node, and in global mode every visible node of its rule
 *    (turned by their quarter turns) and every mirror image of it (a node of its label of the
 *    other hand, as the labeling recorded it: reflected, then turned, so a handed window's
 *    twin grows the other way), each with a target box kept inside its nearest visible
 *    ancestor (a window never leaves its wall); around them, breadth-first over the units'
 *    adjacency, the units with the same nearest visible ancestor (local mode: only those
 *    meeting the region). The root is resized like any node: its target is the frame of every
 *    unit right below it.
 * 3. The system: hard attachments (targets, the frame's faces, the ground, shared
 *    coordinates) merge coordinates into classes; the soft ones (overlap ratios, size,
 *    position) over the free classes form a sparse least-squares system (lsq.h) whose
 *    factorization depends only on the structure, so a drag re-solves with new targets
 *    without refactorizing. A unique element keeps its size where one end is attached (the
 *    paper's size equations) and its centre's place where it floats; a pattern, and one of
 *    several elements of one rule, follows what it lies in (not along a thin axis).
 * 4. Down the tree: every changed node's children are solved the same way in its new box
 *    (moved as a whole when it only moved); a pattern's count doubles or halves while a
 *    period would pass AG_EDIT_SPLIT_RATIO or fall under AG_EDIT_JOIN_RATIO, its cells keeping
 *    the original size and spacing at twice or half the length; a leaf stretched past the split
 *    ratio on an axis that is not thin splits into two copies; plain siblings of one rule
 *    squeezed under the join ratio join with their nearest same-rule sibling, recursively.
 * The steps live in resize_units.c (1), resize.c (2), resize_system.c (3, in named phases) and
 * resize_layout.c (4); resize_internal.h holds what they share. A commit gives the new tree
 * (nodes keep their indices, copies are appended, removed nodes are dead), which
 * core/edit/rebuild.h turns into the new model. */
#ifndef AG_EDIT_RESIZE_H
#define AG_EDIT_RESIZE_H

#include "../base/tolerance.h" /* AG_EDIT_SPLIT_RATIO, AG_EDIT_JOIN_RATIO */
#include "../proc/proceduralize.h"
#include "edit.h"

/* Squeezed plain siblings join only under nodes with at most this many children. */
#define AG_EDIT_JOIN_SIBLINGS_MAX 20000

/* Largest result of an emission (a huge stretch splits exponentially) when the op's budget
 * sets no lower limit: AG_ERR_RESULT_TOO_LARGE. */
#define AG_EDIT_MAX_TRIANGLES 20000000

typedef struct ag_edit_resize_solver ag_edit_resize_solver;

/* Builds the equations and factorization for op's node, mode and region. */
ag_status ag_edit_resize_solver_create(const ag_proceduralize_result *in, const ag_edit_op *op,
                                       ag_edit_resize_solver **out, ag_error *err);
void ag_edit_resize_solver_free(ag_edit_resize_solver *s);
/* Non-zero when s was built for the same node, mode and region as op (only targets moved). */
int ag_edit_resize_solver_matches(const ag_edit_resize_solver *s, const ag_edit_op *op);
/* Solves for op's target; boxes (nnodes entries) receives every node's new box. */
ag_status ag_edit_resize_solver_solve(ag_edit_resize_solver *s, const ag_edit_op *op,
                                      ag_box *boxes, ag_edit_report *rep, ag_error *err);

/* The edited tree of a resize: *tree (nodes that stay keep their index, copies appended,
 * removed nodes dead) and *source (per node, malloc'd: the node of in's tree it copies), the
 * input for ag_rebuild (rebuild.h). What the tree would place is counted before anything is
 * made of it and refused past the op's budget (AG_ERR_RESULT_TOO_LARGE); the budget's
 * callback is polled while the tree is laid out. */
ag_status ag_edit_resize_tree(const ag_proceduralize_result *in, const ag_edit_op *op,
                              ag_splittree **tree, int32_t **source, ag_edit_report *rep,
                              ag_error *err);

#endif
