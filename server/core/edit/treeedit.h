/* The edited split tree of a structural edit (split, join, paste, remove), the input of
 * ag_rebuild (rebuild.h) as a resize makes it: every node the edit does not remove keeps its
 * index (its id), new nodes are appended, removed nodes are dead, and every node names the
 * node it copies (its source). The result is then made without proceduralizing again, so a
 * selection, a presence or an op that names a node by its id still names it after the edit.
 *
 *   split   the node keeps the lower half along the axis (its subtree squeezed into it); a copy
 *           of its subtree, appended, takes the upper half (split of the root: each of the
 *           root's subtrees so)
 *   join    the visible nodes at or directly below the selection become one visible node whose
 *           box is the union of theirs and whose terminal is their geometry together (a label
 *           of its own); it keeps the id of the one nearest the root (the smallest of those as
 *           near), the others are dead and their children hang under it; it hangs under the
 *           nearest visible ancestor that holds it
 *   paste   the copies of the source selection are appended: inserted under the destination
 *           (its nearest visible ancestor when it is invisible), or, when they replace it,
 *           under its nearest visible ancestor with the destination's subtree dead
 *   remove  the selection's subtrees (and the split chains they hang by) are dead
 *
 * A join's terminal, and the source of a paste that turns it (a window of a side facade pasted
 * on the front) or comes from another model, are geometry the input has no component for:
 * *base is then a view of the input with those components appended (a turned source turned
 * in place, about its box's centre, with its quarter turns counted on; another model's labels
 * and variants as new ones), and ag_treeedit_base_free frees what the view owns; else *base is
 * the input itself. A mirror image turned is still a turn of its variant's terminal (a mirror
 * image has a variant of its own, label.h), so a turned paste of mirrored terminals is made so
 * too. */
#ifndef AG_EDIT_TREEEDIT_H
#define AG_EDIT_TREEEDIT_H

#include <stdint.h>

#include "../proc/proceduralize.h"
#include "../status.h"
#include "edit.h"

/* The input a rebuild reads (in's mesh, labels and tree), with what a join adds. */
typedef struct {
    ag_proceduralize_result view; /* what ag_rebuild is given */
    ag_labels labels;             /* the view's labels when it adds a component */
    ag_splittree tree;            /* the view's tree when it adds a node */
    ag_mesh mesh;                 /* the view's mesh when it adds geometry (positions, triangles) */
    int owns;                     /* labels' and tree's added arrays are owned */
    int owns_mesh;                /* mesh's positions and triangles are owned */
} ag_treeedit_base;

void ag_treeedit_base_free(ag_treeedit_base *b);

/* Each fills *tree and *source (malloc'd, tree->nnodes entries) for ag_rebuild over
 * base->view, and rep's message; the op is checked as the mesh-returning operation checks it
 * (same messages). */
ag_status ag_treeedit_split(const ag_proceduralize_result *in, const ag_edit_op *op,
                            ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                            ag_edit_report *rep, ag_error *err);
ag_status ag_treeedit_join(const ag_proceduralize_result *in, const ag_edit_op *op,
                           ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                           ag_edit_report *rep, ag_error *err);
ag_status ag_treeedit_paste(const ag_proceduralize_result *in, const ag_edit_op *op,
                            ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                            ag_edit_report *rep, ag_error *err);
ag_status ag_treeedit_remove(const ag_proceduralize_result *in, const ag_edit_op *op,
                             ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                             ag_edit_report *rep, ag_error *err);

/* x and its subtree are dead (linked to nothing), with the intermediate split node x hangs by;
 * stack holds t->nnodes entries (the walk's). */
void ag_treeedit_kill_subtree(ag_splittree *t, int32_t x, int32_t *stack);

/* Boxes of the invisible nodes from what they hold: a pattern and the root span their
 * children, an intermediate split node its child (post-order; a node holding nothing keeps
 * its box). */
ag_status ag_treeedit_span_invisible(ag_splittree *t);

#endif
