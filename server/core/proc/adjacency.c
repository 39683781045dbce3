#include "adjacency.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"

/* Finding the pairs from scratch: every pair of visible boxes that meet within the tolerance,
 * found with a grid per size class instead of a sweep along one axis (a sweep compares every
 * box with all those it overlaps along x: on a facade facing x, or a block of buildings in
 * rows, that is most pairs). Each box, grown by the tolerance, is registered on the finest of
 * halving grid levels whose cell is not smaller than its largest extent, so it covers at most
 * 2 cells per axis there, and is found from every box of its level or a finer one through
 * the cells that box covers on the coarser level. A pair is reported from one cell only (the
 * one holding the lower corner of the overlap of the grown boxes), so each pair costs a few
 * hash look-ups whatever the layout: O(n log n) in all, the final sort included. */
#define ADJ_MAX_LEVELS 40

static void adj_cells(const double o[3], double h, const double lo[3], const double hi[3],
                      int64_t clo[3], int64_t chi[3])
{
    for (int a = 0; a < 3; a++) {
        clo[a] = (int64_t)floor((lo[a] - o[a]) / h);
        chi[a] = (int64_t)floor((hi[a] - o[a]) / h);
    }
}

/* As ag_box_meets, and a box with a NaN meets nothing. */
static int boxes_meet(const ag_box *a, const ag_box *b, double tol)
{
    return ag_box_meets_axis(a, b, 0, tol) && ag_box_meets_axis(a, b, 1, tol) &&
           ag_box_meets_axis(a, b, 2, tol);
}

/* A pair's sort key: the smaller node index, then the larger. */
static uint64_t pair_key(uint32_t x, uint32_t y)
{
    return x < y ? (uint64_t)x << 32 | y : (uint64_t)y << 32 | x;
}

/* The sorted keys as t's pairs, a repeated key (a pair found twice) once. */
static ag_status set_pairs(ag_splittree *t, const ag_radix_item *pairs, size_t npairs)
{
    uint32_t *adj = npairs ? malloc(2 * npairs * sizeof *adj) : NULL;
    if (npairs && !adj)
        return AG_ERR_NOMEM;
    size_t n = 0;
    for (size_t p = 0; p < npairs; p++) {
        if (p > 0 && pairs[p].key == pairs[p - 1].key)
            continue;
        adj[2 * n] = (uint32_t)(pairs[p].key >> 32);
        adj[2 * n + 1] = (uint32_t)pairs[p].key;
        n++;
    }
    free(t->adj);
    t->adj = adj;
    t->nadj = n;
    return AG_OK;
}

/* Forgets what the pairs were found for: they are then found from scratch next time. */
static void forget(ag_splittree *t)
{
    free(t->adj_seen);
    t->adj_seen = NULL;
    t->adj_nseen = 0;
}

/* Records what t's pairs are found for: the nodes from `from` on (the ones before are as
 * recorded), and the tolerance. */
static ag_status remember(ag_splittree *t, size_t from)
{
    if (t->nnodes > t->adj_nseen || !t->adj_seen) {
        ag_adj_seen *s = realloc(t->adj_seen, (t->nnodes + 1) * sizeof *s);
        if (!s) {
            forget(t);
            return AG_ERR_NOMEM;
        }
        t->adj_seen = s;
    }
    for (size_t n = from; n < t->nnodes; n++) {
        t->adj_seen[n].box = t->nodes[n].box;
        t->adj_seen[n].visible = t->nodes[n].kind == AG_NODE_COMPONENT;
    }
    t->adj_nseen = t->nnodes;
    t->adj_tol = t->tol;
    return AG_OK;
}

ag_status ag_splittree_adjacency(ag_splittree *t)
{
    free(t->adj);
    t->adj = NULL;
    t->nadj = 0;
    forget(t);
    /* the visible nodes in one pass (an edited tree's are a few among many dead ones) */
    size_t nv = 0;
    uint32_t *node = malloc((t->nnodes + 1) * sizeof *node);
    if (!node)
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT)
            node[nv++] = (uint32_t)i;
    if (nv < 2) {
        free(node);
        return remember(t, 0);
    }
    double tol = t->tol;
    int *level = malloc(nv * sizeof *level);
    ag_radix_item *ent = NULL, *pairs = NULL;
    ag_radix_index cells = {0};
    size_t nent = 0, npairs = 0, cap_pairs = 0;
    ag_status st = AG_ERR_NOMEM;
    if (!level)
        goto done;

    /* the grid levels, halving: a cell of level 0 is as large as the largest grown box */
    double o[3] = {INFINITY, INFINITY, INFINITY}, top = 0, bottom = INFINITY;
    for (size_t i = 0; i < nv; i++) {
        const ag_box *b = &t->nodes[node[i]].box;
        double e = 0;
        for (int a = 0; a < 3; a++) {
            o[a] = fmin(o[a], b->min[a] - tol);
            e = fmax(e, b->max[a] - b->min[a] + 2 * tol);
        }
        top = fmax(top, e);
        bottom = fmin(bottom, e);
    }
    if (!(top > 0))
        top = 1;
    if (!(bottom > 0))
        bottom = top * ldexp(1, -ADJ_MAX_LEVELS);
    double h[ADJ_MAX_LEVELS];
    int nlevels = 1;
    h[0] = top;
    while (nlevels < ADJ_MAX_LEVELS && h[nlevels - 1] / 2 >= bottom) {
        h[nlevels] = h[nlevels - 1] / 2;
        nlevels++;
    }
    int used[ADJ_MAX_LEVELS] = {0};
    size_t cap_ent = 0;
    for (size_t i = 0; i < nv; i++) {
        const ag_box *b = &t->nodes[node[i]].box;
        double lo[3], hi[3], e = 0;
        for (int a = 0; a < 3; a++) {
            lo[a] = b->min[a] - tol;
            hi[a] = b->max[a] + tol;
            e = fmax(e, hi[a] - lo[a]);
        }
        int l = 0;
        while (l + 1 < nlevels && h[l + 1] >= e)
            l++;
        level[i] = l;
        used[l] = 1;
        int64_t clo[3], chi[3];
        adj_cells(o, h[l], lo, hi, clo, chi);
        for (int64_t x = clo[0]; x <= chi[0]; x++)
            for (int64_t y = clo[1]; y <= chi[1]; y++)
                for (int64_t z = clo[2]; z <= chi[2]; z++) {
                    if (AG_ARRAY_RESERVE(ent, cap_ent, nent + 1))
                        goto done;
                    ent[nent].key = ag_radix_cell_key(l, x, y, z);
                    ent[nent++].val = (uint32_t)i;
                }
    }
    if (ag_radix_sort(ent, nent) || ag_radix_index_build(&cells, ent, nent))
        goto done;

    for (size_t i = 0; i < nv; i++) {
        const ag_box *a = &t->nodes[node[i]].box;
        double lo[3], hi[3];
        for (int ax = 0; ax < 3; ax++) {
            lo[ax] = a->min[ax] - tol;
            hi[ax] = a->max[ax] + tol;
        }
        for (int l = 0; l <= level[i]; l++) {
            if (!used[l])
                continue;
            int64_t clo[3], chi[3];
            adj_cells(o, h[l], lo, hi, clo, chi);
            for (int64_t x = clo[0]; x <= chi[0]; x++)
                for (int64_t y = clo[1]; y <= chi[1]; y++)
                    for (int64_t z = clo[2]; z <= chi[2]; z++) {
                        uint64_t key = ag_radix_cell_key(l, x, y, z);
                        size_t e = ag_radix_index_find(&cells, key);
                        for (; e < nent && ent[e].key == key; e++) {
                            uint32_t j = ent[e].val;
                            /* boxes of one level meet from the later one */
                            if (level[j] != l || (l == level[i] && j >= i))
                                continue;
                            const ag_box *b = &t->nodes[node[j]].box;
                            if (!boxes_meet(a, b, tol))
                                continue;
                            /* the pair's own cell: the one holding the overlap's corner */
                            double c[3];
                            for (int ax = 0; ax < 3; ax++)
                                c[ax] = fmax(lo[ax], b->min[ax] - tol);
                            if ((int64_t)floor((c[0] - o[0]) / h[l]) != x ||
                                (int64_t)floor((c[1] - o[1]) / h[l]) != y ||
                                (int64_t)floor((c[2] - o[2]) / h[l]) != z)
                                continue;
                            if (AG_ARRAY_RESERVE(pairs, cap_pairs, npairs + 1))
                                goto done;
                            pairs[npairs].key = pair_key(node[i], node[j]);
                            pairs[npairs++].val = 0;
                        }
                    }
        }
    }
    ag_radix_index_free(&cells);
    free(ent);
    ent = NULL;
    if (ag_radix_sort(pairs, npairs))
        goto done;
    /* a hash collision of two cells lists a pair twice: set_pairs keeps it once */
    if ((st = set_pairs(t, pairs, npairs)) == AG_OK)
        st = remember(t, 0);
done:
    ag_radix_index_free(&cells);
    free(node);
    free(level);
    free(ent);
    free(pairs);
    return st;
}


/* ---- bringing the pairs up to date ------------------------------------------------------- */

/* From this share of changed visible nodes on (one in ADJ_UPDATE_MAX_SHARE), finding all
 * pairs again costs less than searching the changed ones (bench/adjacency: a search is 4-10
 * times cheaper with a fifth changed, about even with most changed). */
#define ADJ_UPDATE_MAX_SHARE 2

/* The changed nodes' neighbours are searched in a bounding-box hierarchy over every visible
 * box: the boxes in the order of their centres along a Morton curve, a complete binary tree
 * over that order (node k's children 2k and 2k + 1, leaves from m on), each node the bound of
 * its leaves. Near boxes are near in the order, so a query visits about log n nodes per box it
 * meets, whatever the split tree's shape (a wall with thousands of windows as children is one
 * fan-out the split tree itself would scan per query). Built in O(n) after an O(n) radix sort;
 * pairs between two unchanged boxes are never looked at. */
typedef struct {
    size_t m;       /* leaves: a power of two >= the visible boxes */
    ag_box *bound;  /* 2m: [1, m) the inner nodes, [m, 2m) the boxes (empty past the last) */
    uint32_t *leaf; /* m: the node of each leaf */
    ag_radix_item *found;
    size_t nfound, cap_found;
} adj_bvh;

static ag_status bvh_build(adj_bvh *h, const ag_splittree *t, const uint32_t *vis, size_t nv)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < nv; i++)
        for (int a = 0; a < 3; a++) {
            const ag_box *b = &t->nodes[vis[i]].box;
            double c = 0.5 * (b->min[a] + b->max[a]);
            lo[a] = fmin(lo[a], c);
            hi[a] = fmax(hi[a], c);
        }
    h->m = 1;
    while (h->m < nv)
        h->m *= 2;
    ag_radix_item *ord = malloc((nv + 1) * sizeof *ord);
    h->bound = malloc(2 * h->m * sizeof *h->bound);
    h->leaf = malloc(h->m * sizeof *h->leaf);
    if (!ord || !h->bound || !h->leaf) {
        free(ord);
        return AG_ERR_NOMEM;
    }
    for (size_t k = 0; k < nv; k++) {
        const ag_box *b = &t->nodes[vis[k]].box;
        uint64_t code = 0;
        for (int a = 0; a < 3; a++) {
            double c = 0.5 * (b->min[a] + b->max[a]);
            double u = hi[a] > lo[a] ? (c - lo[a]) / (hi[a] - lo[a]) : 0;
            code |= ag_radix_morton_spread((uint64_t)(fmin(fmax(u, 0), 1) * 2097151.0)) << a;
        }
        ord[k].key = code;
        ord[k].val = vis[k];
    }
    if (ag_radix_sort(ord, nv)) {
        free(ord);
        return AG_ERR_NOMEM;
    }
    for (size_t i = 0; i < h->m; i++) {
        ag_box *b = &h->bound[h->m + i];
        if (i < nv) {
            h->leaf[i] = ord[i].val;
            *b = t->nodes[ord[i].val].box;
        } else {
            h->leaf[i] = UINT32_MAX;
            *b = ag_box_empty();
        }
    }
    free(ord);
    for (size_t i = h->m; i-- > 1;) {
        h->bound[i] = h->bound[2 * i];
        ag_box_extend_box(&h->bound[i], &h->bound[2 * i + 1]);
    }
    return AG_OK;
}

/* The pairs of visible node q with every other visible node whose box meets its box. */
static ag_status bvh_query(adj_bvh *h, const ag_splittree *t, uint32_t q)
{
    const ag_box *qb = &t->nodes[q].box;
    size_t stack[128], sp = 0; /* depth log2(m) < 64: at most one pending sibling per level */
    stack[sp++] = 1;
    while (sp) {
        size_t i = stack[--sp];
        if (!boxes_meet(&h->bound[i], qb, t->tol))
            continue;
        if (i < h->m) {
            stack[sp++] = 2 * i + 1;
            stack[sp++] = 2 * i;
            continue;
        }
        uint32_t x = h->leaf[i - h->m];
        if (x == q || x == UINT32_MAX)
            continue;
        if (AG_ARRAY_RESERVE(h->found, h->cap_found, h->nfound + 1))
            return AG_ERR_NOMEM;
        h->found[h->nfound].key = pair_key(q, x);
        h->found[h->nfound++].val = 0;
    }
    return AG_OK;
}

/* t's pairs without those of a changed node (the others are as they were), merged with the
 * sorted pairs found for the changed nodes (those have a changed node: the two are apart).
 * In place: the kept pairs close up from the front, then the two merge from the back into
 * the array grown by the found ones (a new array of a few million pairs costs more in fresh
 * pages than the merge itself). */
static ag_status merge_found(ag_splittree *t, const uint8_t *changed, ag_radix_item *found,
                             size_t nfound)
{
    size_t nn = t->nnodes, nf = 0;
    for (size_t f = 0; f < nfound; f++) /* a pair of two changed nodes was found from both */
        if (!nf || found[f].key != found[nf - 1].key)
            found[nf++] = found[f];
    uint32_t *adj = t->adj;
    size_t w = 0;
    for (size_t p = 0; p < t->nadj; p++) {
        uint32_t a = adj[2 * p], b = adj[2 * p + 1];
        if (a >= nn || b >= nn || changed[a] || changed[b])
            continue;
        if (w != p) { /* pairs before the first one dropped stay where they are */
            adj[2 * w] = a;
            adj[2 * w + 1] = b;
        }
        w++;
    }
    t->nadj = w;
    if (!nf)
        return AG_OK;
    adj = realloc(t->adj, 2 * (w + nf) * sizeof *adj);
    if (!adj)
        return AG_ERR_NOMEM;
    t->adj = adj;
    size_t k = w, f = nf, o = w + nf;
    while (f > 0) {
        uint64_t fk = found[f - 1].key;
        if (k > 0 && ((uint64_t)adj[2 * (k - 1)] << 32 | adj[2 * (k - 1) + 1]) > fk) {
            k--;
            o--;
            adj[2 * o] = adj[2 * k];
            adj[2 * o + 1] = adj[2 * k + 1];
        } else {
            f--;
            o--;
            adj[2 * o] = (uint32_t)(fk >> 32);
            adj[2 * o + 1] = (uint32_t)fk;
        }
    }
    t->nadj = w + nf;
    return AG_OK;
}

/* Records the changed nodes (the list of them, nchg) and the nodes past the ones recorded (ns
 * of them). */
static ag_status remember_changed(ag_splittree *t, const uint32_t *chg, size_t nchg, size_t ns)
{
    size_t from = ns < t->nnodes ? ns : t->nnodes;
    ag_status st = remember(t, from);
    for (size_t i = 0; !st && i < nchg && chg[i] < from; i++) {
        uint32_t n = chg[i];
        t->adj_seen[n].box = t->nodes[n].box;
        t->adj_seen[n].visible = t->nodes[n].kind == AG_NODE_COMPONENT;
    }
    return st;
}

ag_status ag_splittree_adjacency_update(ag_splittree *t, int *from_scratch)
{
    if (from_scratch)
        *from_scratch = 1;
    if (!t->adj_seen || t->adj_tol != t->tol)
        return ag_splittree_adjacency(t);
    size_t nn = t->nnodes, ns = t->adj_nseen, top = nn > ns ? nn : ns, nv = 0, nch = 0;
    uint8_t *changed = calloc(top + 1, 1);
    /* one pass over the nodes (mostly dead ones in an edited tree) lists what the rest uses:
     * the visible nodes, and the changed ones (visible ones first in a second list) */
    uint32_t *vis = malloc((nn + 1) * sizeof *vis), *chg = malloc((top + 1) * sizeof *chg);
    if (!changed || !vis || !chg) {
        free(changed);
        free(vis);
        free(chg);
        return AG_ERR_NOMEM;
    }
    size_t nchg = 0;
    for (size_t n = 0; n < top; n++) {
        int now = n < nn && t->nodes[n].kind == AG_NODE_COMPONENT;
        int then = n < ns && t->adj_seen[n].visible;
        if (now != then ||
            (now && memcmp(&t->adj_seen[n].box, &t->nodes[n].box, sizeof(ag_box)))) {
            changed[n] = 1;
            chg[nchg++] = (uint32_t)n;
            nch += now;
        }
        if (now)
            vis[nv++] = (uint32_t)n;
    }
    adj_bvh h = {0};
    ag_status st = AG_OK;
    int whole = nch * ADJ_UPDATE_MAX_SHARE >= nv && nch > 0;
    if (!whole && nch) {
        st = bvh_build(&h, t, vis, nv);
        for (size_t i = 0; !st && i < nchg; i++)
            if (chg[i] < nn && t->nodes[chg[i]].kind == AG_NODE_COMPONENT)
                st = bvh_query(&h, t, chg[i]);
        free(h.bound);
        free(h.leaf);
    }
    free(vis);
    if (!st && !whole) {
        st = ag_radix_sort(h.found, h.nfound);
        if (!st)
            st = merge_found(t, changed, h.found, h.nfound);
        if (!st)
            st = remember_changed(t, chg, nchg, ns);
    }
    free(h.found);
    free(changed);
    free(chg);
    if (whole && !st)
        return ag_splittree_adjacency(t);
    if (from_scratch && !st)
        *from_scratch = 0;
    if (st) {
        forget(t);
        free(t->adj);
        t->adj = NULL;
        t->nadj = 0;
    }
    return st;
}

void ag_splittree_adjacency_take(ag_splittree *t, ag_splittree *from)
{
    free(t->adj);
    free(t->adj_seen);
    t->adj = from->adj;
    t->nadj = from->nadj;
    t->adj_seen = from->adj_seen;
    t->adj_nseen = from->adj_nseen;
    t->adj_tol = from->adj_tol;
    from->adj = NULL;
    from->nadj = 0;
    from->adj_seen = NULL;
    from->adj_nseen = 0;
}
