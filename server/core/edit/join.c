/* Join (paper §4.2): the selected nodes' components become one component whose box is the
 * union of theirs; their descendants stay separate and nest under it. Join is topological:
 * re-proceduralizing gives the joined node a label of its own, and where the same join is
 * made on repeated subtrees (two pairs of identical windows in the same layout) the joined
 * nodes are copies of one another, so they become one new rule applied to each copy.
 *
 * A selected invisible node (a pattern, an intermediate split) stands for the visible nodes
 * directly below it, so selecting a pattern joins its instances. The group of the joined
 * component is named after its labels in ascending order ("L3+L3"), so equal joins share a
 * group. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit.h"
#include "place.h"

/* Marks the visible nodes at or directly below v (through invisible nodes only). */
static size_t mark_top_visible(const ag_splittree *t, int32_t v, uint8_t *mark)
{
    const ag_tnode *x = &t->nodes[v];
    if (x->kind == AG_NODE_COMPONENT) {
        if (x->component < 0 || mark[x->component])
            return 0;
        mark[x->component] = 1;
        return 1;
    }
    size_t n = 0;
    for (int32_t s = x->first_child; s >= 0; s = t->nodes[s].next_sibling)
        n += mark_top_visible(t, s, mark);
    return n;
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return x < y ? -1 : x > y;
}

/* "L3+L3+L7"; long names become a hash of the full one so that equal joins still match. */
static void join_name(const ag_proceduralize_result *in, const uint8_t *mark, size_t n,
                      int32_t *labels, char *buf, size_t cap)
{
    const ag_splittree *t = in->tree;
    size_t k = 0;
    for (size_t c = 0; c < t->ncomponents; c++)
        if (mark[c])
            labels[k++] = in->labels->label[c];
    qsort(labels, k, sizeof *labels, cmp_i32);
    size_t len = 0;
    int fits = 1;
    uint64_t h = 1469598103934665603ULL;
    for (size_t i = 0; i < k; i++) {
        char one[24];
        int w = snprintf(one, sizeof one, "%sL%d", i ? "+" : "", (int)labels[i] + 1);
        for (int j = 0; j < w; j++)
            h = (h ^ (unsigned char)one[j]) * 1099511628211ULL;
        if (fits && len + (size_t)w < cap && len + (size_t)w < 120) {
            memcpy(buf + len, one, (size_t)w + 1);
            len += (size_t)w;
        } else {
            fits = 0;
        }
    }
    if (!fits)
        snprintf(buf, cap, "J%zu_%016llx", n, (unsigned long long)h);
}

ag_status ag_edit_join(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                       ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_status st = ag_place_check_selection(in, op, "join", "a selection of at least two nodes",
                                            "joined", err);
    if (st)
        return st;
    const ag_splittree *t = in->tree;
    uint8_t *mark = calloc(t->ncomponents + 1, 1);
    int32_t *labels = malloc((t->ncomponents + 1) * sizeof *labels);
    ag_place_builder *b = ag_place_builder_create();
    if (!mark || !labels || !b) {
        free(mark);
        free(labels);
        ag_place_builder_free(b);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t n = 0;
    for (size_t i = 0; i < op->nnodes; i++)
        n += mark_top_visible(t, op->nodes[i], mark);
    if (n < 2) {
        st = ag_error_set(err, AG_ERR_INVALID, 0,
                          "join needs at least two distinct visible nodes; the selection of "
                          "%zu node(s) names %zu",
                          op->nnodes, n);
        goto done;
    }
    char name[128];
    join_name(in, mark, n, labels, name, sizeof name);
    st = ag_place_copy_unmarked(b, in, mark);
    if (!st)
        st = ag_place_begin(b, name);
    for (size_t c = 0; c < t->ncomponents && !st; c++)
        if (mark[c])
            st = ag_place_add(b, in, (uint32_t)c, NULL);
    if (st) {
        st = ag_error_set(err, st, 0, "out of memory while joining");
        goto done;
    }
    st = ag_place_finish(b, out, err);
    b = NULL;
    if (!st && rep) {
        rep->joins++;
        snprintf(rep->message, sizeof rep->message, "joined %zu nodes into one (%s)", n, name);
    }
done:
    ag_place_builder_free(b);
    free(mark);
    free(labels);
    return st;
}
