/* Shared pieces of the structural edits (split, join, paste, remove).
 *
 * A visible node's geometry is relative to its box, so a subtree moves into a new box by one
 * affine map per subtree: the old box, turned by k quarter turns about z about its centre, is
 * scaled per axis onto the new box (the same placement a grammar application uses). The
 * builder collects the edited mesh: one component per placed terminal, group = label name
 * ("L<label + 1>", the names the exported grammar gives its terminals). */
#ifndef AG_PLACE_H
#define AG_PLACE_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../proc/proceduralize.h"
#include "../status.h"
#include "edit.h"

typedef struct {
    double M[3][3];
    double t[3];
} ag_place_map;

void ag_place_identity(ag_place_map *m);
/* Maps `from` onto `to` turned by k quarter turns counter-clockwise about +z. An axis along
 * which `from` is flat keeps its (zero) size and lands on the centre of `to`. */
void ag_place_boxes(ag_place_map *m, const ag_box *from, const ag_box *to, int k);
void ag_place_apply(const ag_place_map *m, const double p[3], double q[3]);
ag_box ag_place_apply_box(const ag_place_map *m, const ag_box *b);

/* Checks that node names a live node of r's split tree. `what` describes the field for the
 * message ("nodes[2] of the source model"). AG_ERR_NOT_FOUND with element = node. */
ag_status ag_place_check_node(const ag_proceduralize_result *r, int32_t node, const char *what,
                              ag_error *err);

/* Checks a join's or a remove's selection: not empty ("<verb> needs <need> (nodes is empty)"),
 * every node live ("<verb> nodes[i]"), none the root ("the root cannot be <done>"). */
ag_status ag_place_check_selection(const ag_proceduralize_result *in, const ag_edit_op *op,
                                   const char *verb, const char *need, const char *done,
                                   ag_error *err);

/* Checks a split: its node, its axis and its plane strictly inside the node's box (by more than
 * a face coincidence); *ncomponents gets the components of the node's subtree (none:
 * AG_ERR_INVALID). */
ag_status ag_place_check_split(const ag_proceduralize_result *in, const ag_edit_op *op,
                               size_t *ncomponents, ag_error *err);

/* Sets mark[c] = 1 for every component of node's subtree (node included); mark holds
 * r->tree->ncomponents entries. Returns the number of components newly marked. */
size_t ag_place_mark_subtree(const ag_splittree *t, int32_t node, uint8_t *mark);

/* The direction a box faces inside a reference box (its building): along its thinner
 * horizontal axis, away from the reference's centre. 0: +x, 1: +y, 2: -x, 3: -y (quarter turns
 * from +x). A box centred on the reference faces -y (x-long) or -x (y-long). */
int ag_place_facing(const ag_box *b, const ag_box *ref);

/* The grid of a fill: a source of size S (already turned to B's axes) repeated in box B along
 * B's two longest axes, counts = round(B / S) per axis (1 below 1.5 copies), each cell B / count
 * there; along the third axis one cell of min(S, B), flush with the face B faces (facing as
 * ag_place_facing gives it) when that is the axis, else centred. cell0 is the first cell, step
 * the offset between cells (0 on the third axis). Returns -1 when a source is too small to
 * count (1e7 copies or more along an axis). */
int ag_place_fill_grid(const ag_box *B, const double S[3], int facing, unsigned counts[3],
                       double step[3], ag_box *cell0);

/* Label name of component c of r into buf (prefix may be NULL). */
void ag_place_label_name(const ag_proceduralize_result *r, uint32_t c, const char *prefix,
                         char *buf, size_t cap);

typedef struct ag_place_builder ag_place_builder;

ag_place_builder *ag_place_builder_create(void);
void ag_place_builder_free(ag_place_builder *b);
/* Starts a new component in group `group` (created on first use). */
ag_status ag_place_begin(ag_place_builder *b, const char *group);
/* Appends the triangles of component c of r to the current component, vertices mapped by m
 * (NULL: unchanged). */
ag_status ag_place_add(ag_place_builder *b, const ag_proceduralize_result *r, uint32_t c,
                       const ag_place_map *m);
/* begin (group = label name of c with prefix) + add. */
ag_status ag_place_copy(ag_place_builder *b, const ag_proceduralize_result *r, uint32_t c,
                        const ag_place_map *m, const char *prefix);
/* Copies every component of r that has a node in the tree and is not marked (mark may be
 * NULL), unchanged, in component order. */
ag_status ag_place_copy_unmarked(ag_place_builder *b, const ag_proceduralize_result *r,
                                 const uint8_t *mark);
size_t ag_place_triangles(const ag_place_builder *b);
/* Hands over the mesh; AG_ERR_INVALID when it has no triangle (the edit would leave nothing).
 * The builder is freed either way. */
ag_status ag_place_finish(ag_place_builder *b, ag_mesh **out, ag_error *err);

/* What a paste places (paste.c): the source selection joined into one box, the quarter turns
 * from the way it faces to the way the destination faces, and the destination's cells that
 * receive one copy each (fill: a grid, derive: the destination box). */
typedef struct {
    ag_box source_box;
    int turns;
    unsigned counts[3];
    double step[3];
    ag_box cell0;
    size_t ncomponents; /* source components, each placed once per cell */
    size_t copies;      /* cells */
} ag_place_paste_plan;

/* Checks the paste op (nodes of both models, placement, fit) and makes its plan; smark
 * (op->source's, or in's, tree->ncomponents entries, zeroed) gets the source components. A fill
 * past the op's budget or the paste's own ceiling is refused with AG_ERR_RESULT_TOO_LARGE. */
ag_status ag_place_paste_plan_make(const ag_proceduralize_result *in, const ag_edit_op *op,
                                   uint8_t *smark, ag_place_paste_plan *p, ag_error *err);
/* The cell (x, y, z) of the plan's grid. */
ag_box ag_place_paste_cell(const ag_place_paste_plan *p, unsigned x, unsigned y, unsigned z);
/* The report message of a paste. */
void ag_place_paste_message(ag_edit_report *rep, const ag_place_paste_plan *p,
                            const ag_edit_op *op);

#endif
