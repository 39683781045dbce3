#include "splittree.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"
#include "../base/search.h"
#include "../base/tolerance.h"
#include "adjacency.h"

void ag_splittree_free(ag_splittree *t)
{
    if (!t)
        return;
    free(t->nodes);
    free(t->comp_node);
    free(t->adj);
    free(t->adj_seen);
    free(t->rule_count);
    free(t->rule_rep);
    free(t->patterns);
    free(t);
}

/* A malloc'd copy of n elements of size sz (NULL for none). */
static void *dup_array(const void *p, size_t n, size_t sz, int *fail)
{
    if (!p || !n)
        return NULL;
    void *q = malloc(n * sz);
    if (!q)
        *fail = 1;
    else
        memcpy(q, p, n * sz);
    return q;
}

ag_splittree *ag_splittree_copy(const ag_splittree *t)
{
    ag_splittree *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    *c = *t;
    int fail = 0;
    c->nodes = dup_array(t->nodes, t->nnodes, sizeof *t->nodes, &fail);
    c->cap = c->nodes ? t->nnodes : 0;
    c->comp_node = dup_array(t->comp_node, t->ncomponents, sizeof *t->comp_node, &fail);
    c->adj = dup_array(t->adj, 2 * t->nadj, sizeof *t->adj, &fail);
    c->adj_seen = dup_array(t->adj_seen, t->adj_nseen, sizeof *t->adj_seen, &fail);
    c->rule_count = dup_array(t->rule_count, t->nrules, sizeof *t->rule_count, &fail);
    c->rule_rep = dup_array(t->rule_rep, t->nrules, sizeof *t->rule_rep, &fail);
    c->patterns = dup_array(t->patterns, t->npatterns, sizeof *t->patterns, &fail);
    c->cap_patterns = c->patterns ? t->npatterns : 0;
    if (fail) {
        ag_splittree_free(c);
        return NULL;
    }
    return c;
}

ag_box ag_splittree_child_box(const ag_box *p, const double pivot[3], int octant)
{
    ag_box b;
    int q = octant - 1;
    for (int a = 0; a < 3; a++) {
        /* min + pivot can round past max (a flat child on the parent's upper face, far from
         * the origin): the cut stays inside the parent, so a child box is never inverted */
        double v = fmin(fmax(p->min[a] + pivot[a], p->min[a]), p->max[a]);
        if (q >> a & 1) {
            b.min[a] = v;
            b.max[a] = p->max[a];
        } else {
            b.min[a] = p->min[a];
            b.max[a] = v;
        }
    }
    return b;
}

int32_t ag_splittree_chain_end(const ag_splittree *t, int32_t n)
{
    assert(n < 0 || (size_t)n < t->nnodes);
    while (n >= 0 && t->nodes[n].kind == AG_NODE_SPLIT)
        n = t->nodes[n].first_child;
    return n;
}

int32_t ag_splittree_most_repeated(const ag_splittree *t)
{
    int32_t best = -1;
    size_t count = 1;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind == AG_NODE_COMPONENT && n->rule >= 0 && t->rule_count[n->rule] > count) {
            count = t->rule_count[n->rule];
            best = (int32_t)i;
        }
    }
    return best;
}

static int32_t new_node(ag_splittree *t, int kind)
{
    if (t->nnodes >= INT32_MAX || AG_ARRAY_RESERVE(t->nodes, t->cap, t->nnodes + 1))
        return -1;
    int32_t i = (int32_t)t->nnodes++;
    ag_tnode *n = &t->nodes[i];
    memset(n, 0, sizeof *n);
    n->parent = n->first_child = n->last_child = n->next_sibling = -1;
    n->component = n->label = n->variant = n->rule = n->pattern = -1;
    n->kind = (uint8_t)kind;
    return i;
}

void ag_splittree_attach(ag_splittree *t, int32_t parent, int32_t child)
{
    assert(parent >= 0 && (size_t)parent < t->nnodes && child > 0 && (size_t)child < t->nnodes);
    assert(parent != child);
    ag_tnode *p = &t->nodes[parent];
    t->nodes[child].parent = parent;
    t->nodes[child].next_sibling = -1;
    if (p->last_child >= 0)
        t->nodes[p->last_child].next_sibling = child;
    else
        p->first_child = child;
    p->last_child = child;
}

/* A pivot (relative to the parent's min corner) kept within the parent's extent. */
static double pivot_within(double pivot, double size)
{
    if (pivot < 0)
        pivot = 0;
    if (pivot > size)
        pivot = size;
    return pivot;
}

/* A child of parent cut by (pivot, octant q + 1), of the given kind; -1 when out of memory. */
static int32_t add_split(ag_splittree *t, int32_t parent, const double piv[3], int q, int kind)
{
    int32_t n = new_node(t, kind);
    if (n < 0)
        return -1;
    memcpy(t->nodes[n].pivot, piv, sizeof t->nodes[n].pivot);
    t->nodes[n].octant = (uint8_t)(q + 1);
    t->nodes[n].box = ag_splittree_child_box(&t->nodes[parent].box, piv, q + 1);
    ag_splittree_attach(t, parent, n);
    return n;
}

/* The one or two point splits that cut box c out of parent box P (insertion's rule): the first
 * keeps, per axis, the part from P's face that c shares (or from c's min when it shares none);
 * the second, needed when c shares no face of P on some axis, then cuts c's max there. Returns
 * the number of splits (1 or 2). */
static int chain_splits(const ag_box *P, const ag_box *c, double eps, double piv[2][3],
                        int oct[2])
{
    int done[3], single = 1, q = 0;
    for (int a = 0; a < 3; a++) {
        int lo = fabs(c->min[a] - P->min[a]) <= eps, hi = fabs(c->max[a] - P->max[a]) <= eps;
        done[a] = 1;
        if (lo) {
            piv[0][a] = c->max[a] - P->min[a];
        } else if (hi) {
            piv[0][a] = c->min[a] - P->min[a];
            q |= 1 << a;
        } else {
            piv[0][a] = c->min[a] - P->min[a];
            q |= 1 << a;
            done[a] = 0;
            single = 0;
        }
        piv[0][a] = pivot_within(piv[0][a], ag_box_extent(P, a));
    }
    oct[0] = q + 1;
    if (single)
        return 1;
    const ag_box I = ag_splittree_child_box(P, piv[0], oct[0]);
    q = 0;
    for (int a = 0; a < 3; a++) {
        if (done[a]) {
            piv[1][a] = 0;
            q |= 1 << a;
        } else {
            piv[1][a] = pivot_within(c->max[a] - I.min[a], ag_box_extent(&I, a));
        }
    }
    oct[1] = q + 1;
    return 2;
}

int32_t ag_splittree_insert(ag_splittree *t, int32_t parent, const ag_box *c, int kind)
{
    assert(parent >= 0 && (size_t)parent < t->nnodes);
    const ag_box P = t->nodes[parent].box;
    double piv[2][3];
    int oct[2];
    int n = chain_splits(&P, c, t->eps, piv, oct);
    int32_t k = add_split(t, parent, piv[0], oct[0] - 1, n == 1 ? kind : AG_NODE_SPLIT);
    if (k < 0 || n == 1)
        return k;
    return add_split(t, k, piv[1], oct[1] - 1, kind);
}

int32_t ag_splittree_add_node(ag_splittree *t, int kind)
{
    return new_node(t, kind);
}

void ag_splittree_detach(ag_splittree *t, int32_t child)
{
    int32_t p = t->nodes[child].parent;
    if (p < 0)
        return;
    ag_tnode *P = &t->nodes[p];
    int32_t prev = -1;
    for (int32_t s = P->first_child; s >= 0; prev = s, s = t->nodes[s].next_sibling) {
        if (s != child)
            continue;
        if (prev >= 0)
            t->nodes[prev].next_sibling = t->nodes[s].next_sibling;
        else
            P->first_child = t->nodes[s].next_sibling;
        if (P->last_child == s)
            P->last_child = prev;
        break;
    }
    t->nodes[child].parent = -1;
    t->nodes[child].next_sibling = -1;
}

void ag_splittree_attach_after(ag_splittree *t, int32_t parent, int32_t after, int32_t child)
{
    if (after < 0) {
        ag_splittree_attach(t, parent, child);
        return;
    }
    assert(t->nodes[after].parent == parent);
    t->nodes[child].parent = parent;
    t->nodes[child].next_sibling = t->nodes[after].next_sibling;
    t->nodes[after].next_sibling = child;
    if (t->nodes[parent].last_child == after)
        t->nodes[parent].last_child = child;
}

ag_status ag_splittree_hang(ag_splittree *t, int32_t parent, int32_t node)
{
    double piv[2][3];
    int oct[2];
    int n = chain_splits(&t->nodes[parent].box, &t->nodes[node].box, t->eps, piv, oct);
    int32_t at = parent;
    if (n == 2) {
        at = add_split(t, parent, piv[0], oct[0] - 1, AG_NODE_SPLIT);
        if (at < 0)
            return AG_ERR_NOMEM;
    }
    ag_tnode *x = &t->nodes[node];
    memcpy(x->pivot, piv[n - 1], sizeof x->pivot);
    x->octant = (uint8_t)oct[n - 1];
    ag_splittree_attach(t, at, node);
    return AG_OK;
}

ag_status ag_splittree_rechain(ag_splittree *t, int32_t end)
{
    int32_t first = end, parent = t->nodes[end].parent;
    if (parent < 0)
        return AG_OK;
    if (t->nodes[parent].kind == AG_NODE_SPLIT) {
        first = parent;
        parent = t->nodes[parent].parent;
    }
    if (parent < 0 || t->nodes[parent].kind == AG_NODE_PATTERN)
        return AG_OK; /* a pattern's cells are placed by the pattern, not by splits */
    double piv[2][3];
    int oct[2];
    int n = chain_splits(&t->nodes[parent].box, &t->nodes[end].box, t->eps, piv, oct);
    if (first == end && n == 2) {
        /* a second split is needed: an intermediate node in the end's slot */
        int32_t s = new_node(t, AG_NODE_SPLIT);
        if (s < 0)
            return AG_ERR_NOMEM;
        ag_tnode *S = &t->nodes[s], *E = &t->nodes[end], *P = &t->nodes[parent];
        S->parent = parent;
        S->next_sibling = E->next_sibling;
        S->first_child = S->last_child = end;
        if (P->first_child == end)
            P->first_child = s;
        if (P->last_child == end)
            P->last_child = s;
        for (int32_t c = P->first_child; c >= 0; c = t->nodes[c].next_sibling)
            if (t->nodes[c].next_sibling == end)
                t->nodes[c].next_sibling = s;
        E->parent = s;
        E->next_sibling = -1;
        first = s;
    }
    ag_tnode *F = &t->nodes[first];
    memcpy(F->pivot, piv[0], sizeof F->pivot);
    F->octant = (uint8_t)oct[0];
    F->box = ag_splittree_child_box(&t->nodes[parent].box, piv[0], oct[0]);
    if (first != end) {
        ag_tnode *E = &t->nodes[end];
        if (n == 2) {
            memcpy(E->pivot, piv[1], sizeof E->pivot);
            E->octant = (uint8_t)oct[1];
        } else { /* one split suffices: the second keeps the whole intermediate box */
            memset(E->pivot, 0, sizeof E->pivot);
            E->octant = 8;
        }
    }
    return AG_OK;
}

typedef struct {
    double vol;
    uint32_t c;
} volc;

static int cmp_volc(const void *a, const void *b)
{
    const volc *x = a, *y = b;
    if (x->vol != y->vol)
        return x->vol > y->vol ? -1 : 1;
    return x->c < y->c ? -1 : x->c > y->c;
}

/* Spatial index of visible nodes for the parent search: a box is registered in the cells it
 * covers on the finest of three grid levels where it covers at most 64 cells (boxes larger
 * than that are kept in a short list). A query looks at the cell holding the centre of the
 * new box on each level: every node enclosing the box is found without scanning siblings.
 * The coarsest cell is an eighth of the diagonal, each level four times finer per axis. */
#define GI_LEVELS 3
#define GI_COARSEST 8.0   /* cells per diagonal on the coarsest level */
#define GI_REFINE 4       /* finer per axis from one level to the next */
#define GI_MAX_CELLS 64   /* most cells one box is registered in */
#define GI_MIN_CELLS 1024 /* first size of the hash table (a power of two) */
typedef struct {
    uint64_t key;
    int32_t head; /* -1 = empty slot */
} gcell;

typedef struct {
    int32_t node, next;
} gentry;

typedef struct {
    double h[GI_LEVELS], o[3];
    gcell *cells;
    size_t cap, used;
    gentry *ent;
    size_t nent, capent;
    int32_t *large;
    size_t nlarge, caplarge;
} gindex;

static gcell *gi_slot(gindex *g, uint64_t key)
{
    size_t i = key & (g->cap - 1);
    while (g->cells[i].head >= 0 && g->cells[i].key != key)
        i = (i + 1) & (g->cap - 1);
    return &g->cells[i];
}

static int gi_grow(gindex *g)
{
    /* a power of two from GI_MIN_CELLS on, for the probe mask */
    size_t nc;
    if (ag_array_capacity(g->cap, g->cap ? g->cap + 1 : GI_MIN_CELLS, sizeof *g->cells, &nc))
        return -1;
    gcell *old = g->cells;
    size_t oc = g->cap;
    g->cells = malloc(nc * sizeof *g->cells);
    if (!g->cells) {
        g->cells = old;
        return -1;
    }
    g->cap = nc;
    for (size_t i = 0; i < nc; i++)
        g->cells[i].head = -1;
    for (size_t i = 0; i < oc; i++)
        if (old[i].head >= 0)
            *gi_slot(g, old[i].key) = old[i];
    free(old);
    return 0;
}

static int gi_add(gindex *g, const ag_box *b, int32_t node)
{
    for (int l = GI_LEVELS - 1; l >= 0; l--) {
        int64_t lo[3], hi[3];
        double cells = 1;
        for (int a = 0; a < 3; a++) {
            lo[a] = (int64_t)floor((b->min[a] - g->o[a]) / g->h[l]);
            hi[a] = (int64_t)floor((b->max[a] - g->o[a]) / g->h[l]);
            cells *= (double)(hi[a] - lo[a] + 1);
        }
        if (cells > GI_MAX_CELLS && l > 0)
            continue;
        if (cells > GI_MAX_CELLS)
            break;
        for (int64_t x = lo[0]; x <= hi[0]; x++)
            for (int64_t y = lo[1]; y <= hi[1]; y++)
                for (int64_t z = lo[2]; z <= hi[2]; z++) {
                    if (2 * (g->used + 1) > g->cap && gi_grow(g))
                        return -1;
                    if (AG_ARRAY_RESERVE(g->ent, g->capent, g->nent + 1))
                        return -1;
                    uint64_t key = ag_radix_cell_key(l, x, y, z);
                    gcell *c = gi_slot(g, key);
                    if (c->head < 0) {
                        c->key = key;
                        g->used++;
                    }
                    g->ent[g->nent].node = node;
                    g->ent[g->nent].next = c->head;
                    c->head = (int32_t)g->nent++;
                }
        return 0;
    }
    if (AG_ARRAY_RESERVE(g->large, g->caplarge, g->nlarge + 1))
        return -1;
    g->large[g->nlarge++] = node;
    return 0;
}

static void gi_free(gindex *g)
{
    free(g->cells);
    free(g->ent);
    free(g->large);
}

ag_status ag_splittree_build(const ag_mesh *m, const ag_labels *L, ag_splittree **out,
                             ag_error *err)
{
    *out = NULL;
    gindex gi = {0};
    ag_splittree *t = calloc(1, sizeof *t);
    size_t nc = L->ncomponents;
    volc *order = malloc((nc + 1) * sizeof *order);
    /* visible nesting level per node (indexed by node; grown with the tree) */
    uint32_t *depth = NULL;
    if (!t || !order)
        goto nomem;
    t->ncomponents = nc;
    t->comp_node = malloc((nc + 1) * sizeof *t->comp_node);
    if (!t->comp_node)
        goto nomem;
    double diag = L->diagonal > 0 ? L->diagonal : 1.0;
    t->tol = L->exact;
    t->eps = AG_PROC_COINCIDENT * diag;
    double min_extent = AG_PROC_ORDER_MIN_EXTENT * diag;
    int32_t root = new_node(t, AG_NODE_ROOT);
    if (root < 0)
        goto nomem;
    ag_box all = ag_box_empty();
    size_t n = 0;
    for (size_t c = 0; c < nc; c++) {
        t->comp_node[c] = -1;
        if (!L->ntris[c])
            continue;
        ag_box_extend_box(&all, &L->box[c]);
        order[n].vol = ag_box_volume_floor(&L->box[c], min_extent);
        order[n++].c = (uint32_t)c;
    }
    if (n == 0) {
        gi_free(&gi);
        free(depth);
        ag_splittree_free(t);
        free(order);
        return ag_error_set(err, AG_ERR_EMPTY, 0, "no component has triangles");
    }
    t->nodes[root].box = all;
    qsort(order, n, sizeof *order, cmp_volc);
    depth = calloc(3 * n + 8, sizeof *depth); /* at most two splits per component */
    if (!depth)
        goto nomem;
    double per_diag = GI_COARSEST;
    for (int l = 0; l < GI_LEVELS; l++, per_diag *= GI_REFINE)
        gi.h[l] = diag / per_diag;
    for (int a = 0; a < 3; a++)
        gi.o[a] = all.min[a];
    /* a component nests in a box that holds it within the exact tolerance: a vertex jitter
     * below what derivation reproduces (a flush window a fraction of a micrometre out of its
     * wall's face) does not change where it hangs */
    double nest = fmax(t->eps, t->tol);
    for (size_t i = 0; i < n; i++) {
        uint32_t c = order[i].c;
        const ag_box *cb = &L->box[c];
        /* the tightest enclosing visible node; on equal volume the later (deeper) one */
        int32_t P = root;
        double bv = INFINITY, ctr[3];
        ag_box_centre(cb, ctr);
        for (int l = 0; l <= GI_LEVELS; l++) {
            if (l < GI_LEVELS) {
                if (!gi.cap)
                    continue;
                uint64_t key = ag_radix_cell_key(l, (int64_t)floor((ctr[0] - gi.o[0]) / gi.h[l]),
                                    (int64_t)floor((ctr[1] - gi.o[1]) / gi.h[l]),
                                    (int64_t)floor((ctr[2] - gi.o[2]) / gi.h[l]));
                gcell *cell = gi_slot(&gi, key);
                for (int32_t en = cell->head; en >= 0; en = gi.ent[en].next) {
                    int32_t e = gi.ent[en].node;
                    if (!ag_box_contains(&t->nodes[e].box, cb, nest))
                        continue;
                    double v = ag_box_volume_floor(&t->nodes[e].box, min_extent);
                    if (v < bv || (v == bv && e > P)) {
                        bv = v;
                        P = e;
                    }
                }
                continue;
            }
            for (size_t q = 0; q < gi.nlarge; q++) {
                int32_t e = gi.large[q];
                if (!ag_box_contains(&t->nodes[e].box, cb, nest))
                    continue;
                double v = ag_box_volume_floor(&t->nodes[e].box, min_extent);
                if (v < bv || (v == bv && e > P)) {
                    bv = v;
                    P = e;
                }
            }
        }
        /* bound the nesting (export and derivation recurse along it) */
        if (P != root && depth[P] >= AG_SPLITTREE_MAX_NESTING)
            P = root;
        int32_t k = ag_splittree_insert(t, P, cb, AG_NODE_COMPONENT);
        if (k < 0 || gi_add(&gi, &t->nodes[k].box, k))
            goto nomem;
        depth[k] = P == root ? 1 : depth[P] + 1;
        t->nodes[k].component = (int32_t)c;
        t->nodes[k].label = L->label[c];
        t->nodes[k].variant = L->variant[c];
        t->nodes[k].rot = L->vrot[c];
        t->comp_node[c] = k;
    }
    free(order);
    order = NULL;
    gi_free(&gi);
    gi = (gindex){0};
    free(depth);
    depth = NULL;
    if (ag_splittree_adjacency(t))
        goto nomem;
    *out = t;
    return AG_OK;
nomem:
    gi_free(&gi);
    free(depth);
    free(order);
    ag_splittree_free(t);
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while building the split tree");
}

ag_splittree_stats ag_splittree_stats_of(const ag_splittree *t)
{
    ag_splittree_stats s = {0};
    /* patterns re-parent nodes to later nodes, so depths are memoised walking up */
    int32_t *depth = malloc((t->nnodes + 1) * sizeof *depth);
    if (depth)
        for (size_t i = 0; i < t->nnodes; i++)
            depth[i] = -1;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind == AG_NODE_DEAD)
            continue;
        s.nodes++;
        if (n->kind == AG_NODE_COMPONENT)
            s.visible++;
        else
            s.invisible++;
        if (!depth)
            continue;
        int32_t d = 0, j = (int32_t)i;
        while (j >= 0 && depth[j] < 0) {
            j = t->nodes[j].parent;
            d++;
        }
        int32_t base = j >= 0 ? depth[j] : -1;
        /* second walk fills the memo */
        j = (int32_t)i;
        int32_t k = base + d;
        while (j >= 0 && depth[j] < 0) {
            depth[j] = k--;
            j = t->nodes[j].parent;
        }
        if ((size_t)depth[i] > s.depth)
            s.depth = (size_t)depth[i];
    }
    free(depth);
    return s;
}
