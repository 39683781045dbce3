/* Structure-preserving resize (see edit.h for the op and attach.h for the equations).
 *
 * 1. The edited nodes: the op's node, and in global mode every visible node of its rule
 *    (turned by their quarter turns). Each gets a target box, kept inside the box of its
 *    nearest visible ancestor (a window never leaves its wall).
 * 2. The area of effect: breadth-first from the edited nodes over the adjacency of visible
 *    nodes with the same nearest visible ancestor (the same level of nesting); local mode
 *    keeps only nodes meeting the region. Their descendants are not unknowns: they are
 *    re-derived from their ancestors afterwards.
 * 3. Hard attachments (targets, ground, shared coordinates) are eliminated by merging
 *    coordinates into classes; the soft ones (ratios, size, position) over the free classes
 *    form a sparse least-squares system (lsq.h) whose factorization depends only on the
 *    structure, so a drag re-solves with new targets without refactorizing.
 * 4. Emission: every visible node's component is mapped affinely from its old box to its new
 *    one; a node stretched past AG_EDIT_SPLIT_RATIO splits into two copies of its subtree,
 *    and a pattern whose cells pass AG_EDIT_SPLIT_RATIO or fall under AG_EDIT_JOIN_RATIO
 *    doubles or halves its count on that axis, recursively, keeping each cell's share of its
 *    period; plain siblings of one rule (not cells of a grid pattern) squeezed under
 *    AG_EDIT_JOIN_RATIO join with their nearest same-rule sibling along that axis, recursively.
 *    Editing the root or an invisible node maps its subtree affinely (no solve).
 * The steps live in resize_system.c (1-3, in named phases), resize_solve.c and resize_emit.c
 * (4); resize_internal.h holds what they share. */
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

/* The mesh of the model with the nodes moved to boxes, with pattern split/join. What it would
 * place is counted first and refused past the budget's limits (budget may be NULL). */
ag_status ag_edit_resize_emit(const ag_proceduralize_result *in, const ag_box *boxes,
                              const ag_edit_budget *budget, ag_mesh **out, ag_edit_report *rep,
                              ag_error *err);
/* The same with another split ratio (see ag_edit_op.split_ratio; 0 = AG_EDIT_SPLIT_RATIO) and
 * thin share (ag_edit_op.thin_share). */
ag_status ag_edit_resize_emit_ratio(const ag_proceduralize_result *in, const ag_box *boxes,
                                    double split_ratio, double thin_share,
                                    const ag_edit_budget *budget, ag_mesh **out,
                                    ag_edit_report *rep, ag_error *err);

#endif
