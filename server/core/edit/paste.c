/* Copy / paste (paper §4.3). The source selection is joined into one source: the union box of
 * the selected nodes and every component of their subtrees. It may come from another model
 * (op->source, style transfer between buildings; NULL = the edited model).
 *
 * - placement insert: the destination keeps what it holds and the source is added in its box;
 *   replace: the destination node and its subtree are removed first.
 * - fit derive: the source box is mapped onto the destination box (relative parameters: every
 *   part keeps its place relative to the source box). fit fill: the source is repeated along the
 *   destination's two longest axes, counts = round(destination / source) per axis (at least 1),
 *   each copy stretched to its cell so the source keeps its approximate aspect ratio; along the
 *   destination's shortest axis one copy keeps the source's size (at most the destination's)
 *   and sits flush with the destination's outer face when that axis is the way it faces, else
 *   centred (a window stays in the wall's outer face).
 * - orientation: the source is turned by quarter turns about z from the direction it faces to
 *   the one the destination faces (ag_place_facing: the thinner horizontal axis, away from the
 *   building's centre), so a window copied from a side facade onto the front is turned.
 * Pasted components from another model are grouped as "src_L<n>" so that they are not counted
 * with this model's labels of the same number. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "edit.h"
#include "place.h"

#define PASTE_MAX_TRIANGLES 50000000.0
/* A fill needing more copies per axis is refused before its triangles are even counted. */
#define PASTE_MAX_COPIES 1e7

ag_status ag_edit_paste(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                        ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    const ag_proceduralize_result *src = op->source ? op->source : in;
    int cross = src != in;
    if (op->nnodes == 0 || !op->nodes)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste needs a source selection (nodes is empty)");
    ag_status st = ag_place_check_node(in, op->node, "paste destination node", err);
    if (st)
        return st;
    char what[64];
    for (size_t i = 0; i < op->nnodes; i++) {
        snprintf(what, sizeof what, "paste source nodes[%zu]%s", i,
                 cross ? " (source model)" : "");
        if ((st = ag_place_check_node(src, op->nodes[i], what, err)))
            return st;
    }
    if (op->placement != AG_EDIT_INSERT && op->placement != AG_EDIT_REPLACE)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste placement must be insert (0) or replace (1), not %d",
                            op->placement);
    if (op->fit != AG_EDIT_FILL && op->fit != AG_EDIT_DERIVE)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste fit must be fill (0) or derive (1), not %d", op->fit);

    const ag_splittree *ts = src->tree, *td = in->tree;
    uint8_t *smark = calloc(ts->ncomponents + 1, 1);
    uint8_t *dmark = calloc(td->ncomponents + 1, 1);
    ag_place_builder *b = ag_place_builder_create();
    if (!smark || !dmark || !b) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    /* the joined source */
    ag_box Bs = ts->nodes[op->nodes[0]].box;
    size_t ns = 0, stris = 0;
    for (size_t i = 0; i < op->nnodes; i++) {
        const ag_box *nb = &ts->nodes[op->nodes[i]].box;
        ag_box_extend_box(&Bs, nb);
        ns += ag_place_mark_subtree(ts, op->nodes[i], smark);
    }
    if (ns == 0) {
        st = ag_error_set(err, AG_ERR_INVALID, op->nodes[0], "the source selection has no geometry");
        goto done;
    }
    for (size_t c = 0; c < ts->ncomponents; c++)
        if (smark[c])
            stris += src->labels->ntris[c];

    const ag_box Bd = td->nodes[op->node].box;
    int fs = ag_place_facing(&Bs, &ts->nodes[AG_EDIT_ROOT].box);
    int fd = ag_place_facing(&Bd, &td->nodes[AG_EDIT_ROOT].box);
    int k = (fd - fs) & 3;
    double S[3];
    ag_box_extents(&Bs, S);
    if (k & 1) {
        double x = S[0];
        S[0] = S[1];
        S[1] = x;
    }

    /* cells of the destination that receive one copy each */
    unsigned counts[3] = {1, 1, 1};
    ag_box cell0 = Bd;
    double step[3] = {0, 0, 0};
    if (op->fit == AG_EDIT_FILL) {
        if (ag_place_fill_grid(&Bd, S, fd, counts, step, &cell0)) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, op->node,
                              "the source is too small to fill node %d", (int)op->node);
            goto done;
        }
        double total = (double)counts[0] * counts[1] * counts[2];
        double limit = op->budget && op->budget->max_triangles &&
                               (double)op->budget->max_triangles < PASTE_MAX_TRIANGLES
                           ? (double)op->budget->max_triangles
                           : PASTE_MAX_TRIANGLES;
        if (total * (double)stris > limit) {
            st = ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, op->node,
                              "filling node %d needs %.0f copies of %zu triangles (limit %.0f "
                              "triangles)",
                              (int)op->node, total, stris, limit);
            goto done;
        }
        if (op->budget && op->budget->max_components &&
            total * (double)op->nnodes > (double)op->budget->max_components) {
            st = ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, op->node,
                              "filling node %d needs %.0f copies of %zu nodes (limit %zu "
                              "terminals)",
                              (int)op->node, total, op->nnodes, op->budget->max_components);
            goto done;
        }
    }

    if (op->placement == AG_EDIT_REPLACE)
        ag_place_mark_subtree(td, op->node, dmark);
    st = ag_place_copy_unmarked(b, in, dmark);
    size_t copies = 0;
    for (unsigned z = 0; z < counts[2] && !st; z++)
        for (unsigned y = 0; y < counts[1] && !st; y++)
            for (unsigned x = 0; x < counts[0] && !st; x++) {
                ag_box cell = cell0;
                unsigned ix[3] = {x, y, z};
                for (int a = 0; a < 3; a++) {
                    cell.min[a] += ix[a] * step[a];
                    cell.max[a] += ix[a] * step[a];
                }
                ag_place_map map;
                ag_place_boxes(&map, &Bs, &cell, k);
                for (size_t c = 0; c < ts->ncomponents && !st; c++)
                    if (smark[c])
                        st = ag_place_copy(b, src, (uint32_t)c, &map, cross ? "src_" : NULL);
                copies++;
            }
    if (st) {
        st = ag_error_set(err, st, 0, "out of memory while pasting");
        goto done;
    }
    st = ag_place_finish(b, out, err);
    b = NULL;
    if (!st && rep)
        snprintf(rep->message, sizeof rep->message,
                 "pasted %zu cop%s (%u x %u x %u) of %zu components into node %d, turned by %d "
                 "quarter turn%s",
                 copies, copies == 1 ? "y" : "ies", counts[0], counts[1], counts[2], ns,
                 (int)op->node, k, k == 1 ? "" : "s");
done:
    ag_place_builder_free(b);
    free(smark);
    free(dmark);
    return st;
}
