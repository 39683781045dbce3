/* Split (paper §4.2): a plane cuts a node's box in two and the node's whole subtree is
 * duplicated into both halves, each copy squeezed into its half. Re-proceduralizing the result
 * turns the two copies into two applications of one rule (or a pattern of count 2). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../base/tolerance.h"
#include "edit.h"
#include "place.h"

ag_status ag_edit_split(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                        ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    size_t n;
    ag_status st = ag_place_check_split(in, op, &n, err);
    if (st)
        return st;
    const ag_splittree *t = in->tree;
    const ag_box B = t->nodes[op->node].box;
    int a = op->axis;
    uint8_t *mark = calloc(t->ncomponents + 1, 1);
    ag_place_builder *b = ag_place_builder_create();
    if (!mark || !b) {
        free(mark);
        ag_place_builder_free(b);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_place_mark_subtree(t, op->node, mark);
    ag_box half[2] = {B, B};
    half[0].max[a] = op->at;
    half[1].min[a] = op->at;
    ag_place_map map[2];
    ag_place_boxes(&map[0], &B, &half[0], 0);
    ag_place_boxes(&map[1], &B, &half[1], 0);
    st = ag_place_copy_unmarked(b, in, mark);
    for (int h = 0; h < 2 && !st; h++)
        for (size_t c = 0; c < t->ncomponents && !st; c++)
            if (mark[c])
                st = ag_place_copy(b, in, (uint32_t)c, &map[h], NULL);
    free(mark);
    if (st) {
        ag_place_builder_free(b);
        return ag_error_set(err, st, 0, "out of memory while splitting");
    }
    st = ag_place_finish(b, out, err);
    if (!st && rep) {
        rep->splits++;
        snprintf(rep->message, sizeof rep->message,
                 "split node %d at %c = %g: %zu components duplicated into both halves",
                 (int)op->node, "xyz"[a], op->at, n);
    }
    return st;
}
