/* Remove (paper §4.3): the selected nodes go with their whole subtrees. Adding is a paste with
 * the insert placement (paste.c). */
#include <stdio.h>
#include <stdlib.h>

#include "edit.h"
#include "place.h"

ag_status ag_edit_remove(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_status st = ag_place_check_selection(in, op, "remove", "at least one node", "removed", err);
    if (st)
        return st;
    const ag_splittree *t = in->tree;
    uint8_t *mark = calloc(t->ncomponents + 1, 1);
    ag_place_builder *b = ag_place_builder_create();
    if (!mark || !b) {
        free(mark);
        ag_place_builder_free(b);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t n = 0;
    for (size_t i = 0; i < op->nnodes; i++)
        n += ag_place_mark_subtree(t, op->nodes[i], mark);
    st = ag_place_copy_unmarked(b, in, mark);
    free(mark);
    if (st) {
        ag_place_builder_free(b);
        return ag_error_set(err, st, 0, "out of memory while removing");
    }
    if (ag_place_triangles(b) == 0) {
        ag_place_builder_free(b);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "removing the selection would leave no geometry");
    }
    st = ag_place_finish(b, out, err);
    if (!st && rep)
        snprintf(rep->message, sizeof rep->message, "removed %zu components", n);
    return st;
}
