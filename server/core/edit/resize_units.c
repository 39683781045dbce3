/* The units of a resize (resize_internal.h): the boxes the attachment equations move. A
 * pattern is one unit: its cells are its lattice periods, laid out again from the pattern's
 * new box by the layout (a facade stretched 2x holds twice the windows), unless a cell itself
 * is edited; then the pattern is open and its cells are units of their own. */
#include <stdlib.h>
#include <string.h>

#include "resize_internal.h"

void ag__resize_units_free(ag__resize_units *u)
{
    free(u->va);
    free(u->unit);
    free(u->open);
    free(u->lattice);
    free(u->adj_start);
    free(u->adj_list);
    memset(u, 0, sizeof *u);
}

static int is_pattern(const ag_splittree *t, int32_t n)
{
    return n >= 0 && t->nodes[n].kind == AG_NODE_PATTERN && t->nodes[n].pattern >= 0 &&
           (size_t)t->nodes[n].pattern < t->npatterns;
}

static int cmp_pair(const void *a, const void *b)
{
    const uint32_t *x = a, *y = b;
    if (x[0] != y[0])
        return x[0] < y[0] ? -1 : 1;
    return x[1] < y[1] ? -1 : x[1] > y[1];
}

ag_status ag__resize_units_build(ag__resize_units *u, const ag_splittree *t, const int32_t *open,
                                 size_t nopen, ag_error *err)
{
    memset(u, 0, sizeof *u);
    u->t = t;
    size_t nn = t->nnodes;
    u->va = malloc((nn + 1) * sizeof *u->va);
    u->unit = malloc((nn + 1) * sizeof *u->unit);
    u->open = calloc(nn + 1, 1);
    u->lattice = calloc(nn + 1, 1);
    u->adj_start = calloc(nn + 2, sizeof *u->adj_start);
    uint32_t *pairs = malloc((4 * t->nadj + 2) * sizeof *pairs);
    if (!u->va || !u->unit || !u->open || !u->lattice || !u->adj_start || !pairs) {
        free(pairs);
        ag__resize_units_free(u);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t n = 0; n < nn; n++)
        u->va[n] = n ? ag__resize_visible_ancestor(t, (int32_t)n) : -1;
    for (size_t i = 0; i < nopen; i++) {
        int32_t p = open[i] >= 0 ? t->nodes[open[i]].parent : -1;
        if (is_pattern(t, p))
            u->open[p] = 1;
    }
    for (size_t n = 0; n < nn; n++) {
        const ag_tnode *x = &t->nodes[n];
        u->unit[n] = -1;
        if (x->kind == AG_NODE_COMPONENT) {
            int32_t p = x->parent;
            u->unit[n] = is_pattern(t, p) && !u->open[p] ? p : (int32_t)n;
        } else if (is_pattern(t, (int32_t)n) && !u->open[n]) {
            u->unit[n] = (int32_t)n;
            const ag_pattern *P = &t->patterns[x->pattern];
            for (int a = 0; a < 3; a++) {
                int repeats = 0;
                if (!P->nvec)
                    repeats = P->counts[a] >= 2;
                else
                    for (int v = 0; v < P->nvec; v++)
                        repeats |= P->counts[v] >= 2 && P->vec[v][a] != 0;
                if (repeats)
                    u->lattice[n] |= (uint8_t)(1u << a);
            }
        }
    }
    /* unit pairs from the visible nodes' adjacency, each once */
    size_t np = 0;
    for (size_t k = 0; k < t->nadj; k++) {
        int32_t a = u->unit[t->adj[2 * k]], b = u->unit[t->adj[2 * k + 1]];
        if (a < 0 || b < 0 || a == b)
            continue;
        pairs[2 * np] = (uint32_t)(a < b ? a : b);
        pairs[2 * np + 1] = (uint32_t)(a < b ? b : a);
        np++;
    }
    qsort(pairs, np, 2 * sizeof *pairs, cmp_pair);
    size_t w = 0;
    for (size_t k = 0; k < np; k++)
        if (!w || pairs[2 * k] != pairs[2 * (w - 1)] || pairs[2 * k + 1] != pairs[2 * (w - 1) + 1]) {
            pairs[2 * w] = pairs[2 * k];
            pairs[2 * w + 1] = pairs[2 * k + 1];
            w++;
        }
    np = w;
    u->adj_list = malloc((2 * np + 1) * sizeof *u->adj_list);
    uint32_t *fill = malloc((nn + 1) * sizeof *fill);
    if (!u->adj_list || !fill) {
        free(fill);
        free(pairs);
        ag__resize_units_free(u);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t k = 0; k < np; k++) {
        u->adj_start[pairs[2 * k] + 1]++;
        u->adj_start[pairs[2 * k + 1] + 1]++;
    }
    for (size_t n = 0; n < nn; n++)
        u->adj_start[n + 1] += u->adj_start[n];
    memcpy(fill, u->adj_start, nn * sizeof *fill);
    for (size_t k = 0; k < np; k++) {
        uint32_t a = pairs[2 * k], b = pairs[2 * k + 1];
        u->adj_list[fill[a]++] = b;
        u->adj_list[fill[b]++] = a;
    }
    free(fill);
    free(pairs);
    return AG_OK;
}

size_t ag__resize_child_units(const ag__resize_units *u, int32_t n, int32_t *out, size_t cap)
{
    const ag_splittree *t = u->t;
    size_t k = 0;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, c);
        if (e < 0 || t->nodes[e].kind == AG_NODE_DEAD)
            continue;
        if (is_pattern(t, e) && u->open[e]) {
            for (int32_t x = t->nodes[e].first_child; x >= 0; x = t->nodes[x].next_sibling) {
                if (k < cap)
                    out[k] = x;
                k++;
            }
            continue;
        }
        if (u->unit[e] != e)
            continue;
        if (k < cap)
            out[k] = e;
        k++;
    }
    return k;
}
