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

ag_status ag_edit_paste(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                        ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    const ag_proceduralize_result *src = op->source ? op->source : in;
    int cross = src != in;
    const ag_splittree *ts = src->tree, *td = in->tree;
    uint8_t *smark = calloc(ts->ncomponents + 1, 1);
    uint8_t *dmark = calloc(td->ncomponents + 1, 1);
    ag_place_builder *b = ag_place_builder_create();
    ag_place_paste_plan pl;
    ag_status st;
    if (!smark || !dmark || !b) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    if ((st = ag_place_paste_plan_make(in, op, smark, &pl, err)))
        goto done;
    if (op->placement == AG_EDIT_REPLACE)
        ag_place_mark_subtree(td, op->node, dmark);
    st = ag_place_copy_unmarked(b, in, dmark);
    size_t copies = 0;
    for (unsigned z = 0; z < pl.counts[2] && !st; z++)
        for (unsigned y = 0; y < pl.counts[1] && !st; y++)
            for (unsigned x = 0; x < pl.counts[0] && !st; x++) {
                ag_box cell = ag_place_paste_cell(&pl, x, y, z);
                ag_place_map map;
                ag_place_boxes(&map, &pl.source_box, &cell, pl.turns);
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
        ag_place_paste_message(rep, &pl, op);
done:
    ag_place_builder_free(b);
    free(smark);
    free(dmark);
    return st;
}
