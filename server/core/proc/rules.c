#include "rules.h"

#include <assert.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"
#include "../base/search.h"
#include "weld.h"

/* Box of child e relative to the centre of node v, rotated by k quarter turns. */
static void rel_box(const ag_splittree *t, int32_t v, int32_t e, int k, double lo[3], double hi[3])
{
    const ag_box *cb = &t->nodes[e].box;
    double c[3];
    ag_box_centre(&t->nodes[v].box, c);
    double x0 = cb->min[0] - c[0], y0 = cb->min[1] - c[1];
    double x1 = cb->max[0] - c[0], y1 = cb->max[1] - c[1];
    ag_label_rotate(k, &x0, &y0);
    ag_label_rotate(k, &x1, &y1);
    lo[0] = fmin(x0, x1);
    hi[0] = fmax(x0, x1);
    lo[1] = fmin(y0, y1);
    hi[1] = fmax(y0, y1);
    lo[2] = cb->min[2] - c[2];
    hi[2] = cb->max[2] - c[2];
}

static size_t children(const ag_splittree *t, int32_t v, int32_t *buf, size_t cap)
{
    size_t n = 0;
    for (int32_t s = t->nodes[v].first_child; s >= 0; s = t->nodes[s].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, s);
        if (e >= 0) {
            if (n < cap)
                buf[n] = e;
            n++;
        }
    }
    return n;
}

/* Do pattern nodes x (of a) and y (of b) repeat the same cells the same way, y being x turned
 * by k quarter turns? */
static int same_pattern(const ag_splittree *t, const ag_tnode *x, const ag_tnode *y, int k)
{
    if (x->pattern < 0 || y->pattern < 0 || (size_t)x->pattern >= t->npatterns ||
        (size_t)y->pattern >= t->npatterns)
        return 0;
    const ag_pattern *p = &t->patterns[x->pattern], *q = &t->patterns[y->pattern];
    if (p->rule != q->rule || ((p->rot + k) & 3) != q->rot || p->nvec != q->nvec)
        return 0;
    if (!p->nvec) {
        int odd = k & 1;
        return p->counts[odd ? 1 : 0] == q->counts[0] && p->counts[odd ? 0 : 1] == q->counts[1] &&
               p->counts[2] == q->counts[2];
    }
    for (int v = 0; v < p->nvec; v++) {
        double vx = p->vec[v][0], vy = p->vec[v][1];
        ag_label_rotate(k, &vx, &vy);
        if (p->counts[v] != q->counts[v] || fabs(vx - q->vec[v][0]) > t->tol ||
            fabs(vy - q->vec[v][1]) > t->tol || fabs(p->vec[v][2] - q->vec[v][2]) > t->tol)
            return 0;
    }
    return 1;
}

/* Scratch of same() for nodes with many children, kept across calls: a's children's boxes
 * and a cell index of their lower corners. */
typedef struct {
    double *lo, *hi;   /* 3 per child of a */
    ag_radix_item *ent;
    size_t cap_ent;
    int nomem;
} same_scratch;

/* Above this many children a's are found through the cell index instead of a scan of all of
 * them per child of b (a wall holding thousands of windows: n^2). */
#define SAME_INDEX_MIN 64

/* Is child x of a (turned by k) the same as child y of b, boxes lo/hi relative to the
 * nodes' centres? */
static int same_child(const ag_splittree *t, const ag_tnode *x, const ag_tnode *y, int k,
                      const double alo[3], const double ahi[3], const double blo[3],
                      const double bhi[3])
{
    if (x->kind != y->kind)
        return 0;
    if (x->kind == AG_NODE_PATTERN ? !same_pattern(t, x, y, k)
                                   : x->rule != y->rule || ((x->rule_rot + k) & 3) != y->rule_rot)
        return 0;
    for (int d = 0; d < 3; d++)
        if (!(fabs(alo[d] - blo[d]) <= t->tol && fabs(ahi[d] - bhi[d]) <= t->tol))
            return 0;
    return 1;
}

static uint64_t corner_cell(const double p[3], double cell, const int64_t add[3])
{
    return ag__cell_hash((int64_t)floor(p[0] / cell) + add[0], (int64_t)floor(p[1] / cell) + add[1],
                         (int64_t)floor(p[2] / cell) + add[2]);
}

/* Does a box of extents eb have the size of one of extents ea turned by k quarter turns? */
static int same_size(const double ea[3], const double eb[3], int k, double tol)
{
    int odd = k & 1;
    return !(fabs(ea[odd ? 1 : 0] - eb[0]) > tol || fabs(ea[odd ? 0 : 1] - eb[1]) > tol ||
             fabs(ea[2] - eb[2]) > tol);
}

/* A rule's representative as the search for a node's rule first compares it: its child
 * count, the sum of its children's classes (below), turn and extents. */
typedef struct {
    size_t kids;
    uint64_t sig;
    double ext[3];
    uint8_t rot;
} rule_key;

/* A child's class as same_child compares it before its turn and place: its kind and its rule
 * (a pattern's: the pattern's rule; none for a pattern out of range). Two nodes whose
 * children's classes differ as multisets are not the same: the sums of their mixed classes
 * tell most such pairs apart without the comparison. */
static uint64_t child_class(const ag_splittree *t, const ag_tnode *x)
{
    uint64_t r;
    if (x->kind == AG_NODE_PATTERN)
        r = x->pattern >= 0 && (size_t)x->pattern < t->npatterns
                ? (uint32_t)t->patterns[x->pattern].rule
                : UINT64_C(1) << 32;
    else
        r = (uint32_t)x->rule;
    uint64_t z = r ^ (uint64_t)x->kind << 40;
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9); /* splitmix64's finaliser */
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

/* The number of children of v (as children() counts them) and the sum of their classes. */
static size_t children_sig(const ag_splittree *t, int32_t v, uint64_t *sig)
{
    size_t n = 0;
    uint64_t s = 0;
    for (int32_t c = t->nodes[v].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, c);
        if (e >= 0) {
            s += child_class(t, &t->nodes[e]);
            n++;
        }
    }
    *sig = s;
    return n;
}

/* Does b match rep a with b = rotate(a, k)? b must also have a's size: a rule is placed scaled
 * to the box it is applied to (its children would move with it) and a pattern's cells are of
 * one size (nodes of one variant have it anyway; an edited model's stretched copies of a
 * variant do not). Pattern children repeat the same rule the same way. Each child of b, in
 * order, takes the first unused child of a that is the same. */
static int same(const ag_splittree *t, int32_t a, int32_t b, int k, int32_t *ca, int32_t *cb,
                uint8_t *used, size_t n, same_scratch *sc)
{
    double tol = t->tol;
    {   /* the sizes first: most candidates differ there, before their children are walked */
        double ea[3], eb[3];
        ag_box_extents(&t->nodes[a].box, ea);
        ag_box_extents(&t->nodes[b].box, eb);
        if (!same_size(ea, eb, k, tol))
            return 0;
    }
    size_t na = children(t, a, ca, n), nb = children(t, b, cb, n);
    assert(na == n && nb == n); /* the caller compared the counts */
    (void)na;
    (void)nb;
    memset(used, 0, n);
    if (n <= SAME_INDEX_MIN) {
        for (size_t j = 0; j < n; j++) {
            double blo[3], bhi[3];
            rel_box(t, b, cb[j], 0, blo, bhi);
            int ok = 0;
            for (size_t i = 0; i < n && !ok; i++) {
                if (used[i])
                    continue;
                double alo[3], ahi[3];
                rel_box(t, a, ca[i], k, alo, ahi);
                if (same_child(t, &t->nodes[ca[i]], &t->nodes[cb[j]], k, alo, ahi, blo, bhi)) {
                    used[i] = 1;
                    ok = 1;
                }
            }
            if (!ok)
                return 0;
        }
        return 1;
    }
    /* a's children by the cell of their lower corner: a child within tol lies in the cells
     * (of 4 r) that [lo - r, lo + r] meets, at most 2 per axis, so b's child looks up its
     * own cell only; of the candidates, the first unused in a's order is the one a scan
     * would take */
    double amax = 0;
    for (size_t i = 0; i < n; i++) {
        rel_box(t, a, ca[i], k, sc->lo + 3 * i, sc->hi + 3 * i);
        for (int d = 0; d < 3; d++)
            amax = fmax(amax, fabs(sc->lo[3 * i + d]));
    }
    double r = 1.01 * tol + 16 * DBL_EPSILON * (amax + 1), cell = 4 * r;
    size_t ne = 0;
    for (size_t i = 0; i < n; i++) {
        const double *lo = sc->lo + 3 * i;
        double l[3] = {lo[0] - r, lo[1] - r, lo[2] - r}, h[3] = {lo[0] + r, lo[1] + r, lo[2] + r};
        int64_t c0[3], c1[3];
        for (int d = 0; d < 3; d++) {
            c0[d] = (int64_t)floor(l[d] / cell);
            c1[d] = (int64_t)floor(h[d] / cell) - c0[d];
        }
        for (int64_t x = 0; x <= c1[0]; x++)
            for (int64_t y = 0; y <= c1[1]; y++)
                for (int64_t z = 0; z <= c1[2]; z++) {
                    if (AG_ARRAY_RESERVE(sc->ent, sc->cap_ent, ne + 1)) {
                        sc->nomem = 1;
                        return 0;
                    }
                    int64_t add[3] = {x, y, z};
                    sc->ent[ne].key = corner_cell(l, cell, add);
                    sc->ent[ne++].val = (uint32_t)i;
                }
    }
    if (ag_radix_sort(sc->ent, ne)) {
        sc->nomem = 1;
        return 0;
    }
    static const int64_t none[3] = {0, 0, 0};
    for (size_t j = 0; j < n; j++) {
        double blo[3], bhi[3];
        rel_box(t, b, cb[j], 0, blo, bhi);
        uint64_t key = corner_cell(blo, cell, none);
        size_t best = SIZE_MAX;
        for (size_t e = ag_search_lower_u64(&sc->ent[0].key, ne, sizeof *sc->ent, key);
             e < ne && sc->ent[e].key == key; e++) {
            size_t i = sc->ent[e].val;
            if (i < best && !used[i] &&
                same_child(t, &t->nodes[ca[i]], &t->nodes[cb[j]], k, sc->lo + 3 * i,
                           sc->hi + 3 * i, blo, bhi))
                best = i;
        }
        if (best == SIZE_MAX)
            return 0;
        used[best] = 1;
    }
    return 1;
}

size_t ag_rules_max_count(const ag_splittree *t)
{
    size_t m = 0;
    for (size_t r = 0; r < t->nrules; r++)
        if (t->rule_count[r] > m)
            m = t->rule_count[r];
    return m;
}

/* The visible nodes in an order where every visible node comes after the visible nodes below
 * it: reverse index order when every visible node's nearest visible ancestor has a smaller
 * index (a tree as built, or edited keeping that), else a post-order walk. One pass over the
 * nodes (an edited tree is mostly dead nodes: each pass over them costs more than the live
 * ones' work) also gives the largest variant of a visible node. */
static int32_t *children_first(const ag_splittree *t, size_t *n_out, int32_t *maxvariant)
{
    size_t N = t->nnodes, n = 0;
    int32_t *order = malloc((N + 1) * sizeof *order);
    if (!order)
        return NULL;
    int indexed = 1;
    int32_t mv = -1;
    for (size_t i = 0; i < N; i++) {
        const ag_tnode *x = &t->nodes[i];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        if (x->variant > mv)
            mv = x->variant;
        order[n++] = (int32_t)i;
        if (!indexed)
            continue;
        int32_t p = x->parent;
        while (p >= 0 && t->nodes[p].kind != AG_NODE_COMPONENT && t->nodes[p].kind != AG_NODE_ROOT)
            p = t->nodes[p].parent;
        indexed = p < (int32_t)i;
    }
    *maxvariant = mv;
    if (indexed) {
        for (size_t i = 0, j = n; i < j / 2; i++) {
            int32_t v = order[i];
            order[i] = order[j - 1 - i];
            order[j - 1 - i] = v;
        }
        *n_out = n;
        return order;
    }
    n = 0;
    /* iterative post-order: a node is emitted once its children are */
    int32_t *stack = malloc((N + 1) * sizeof *stack), *next = malloc((N + 1) * sizeof *next);
    if (!stack || !next) {
        free(stack);
        free(next);
        free(order);
        return NULL;
    }
    size_t sp = 0;
    stack[sp++] = 0;
    next[0] = t->nodes[0].first_child;
    while (sp) {
        int32_t v = stack[sp - 1];
        int32_t c = next[v];
        if (c >= 0 && sp < N + 1) {
            next[v] = t->nodes[c].next_sibling;
            stack[sp++] = c;
            next[c] = t->nodes[c].first_child;
            continue;
        }
        sp--;
        if (t->nodes[v].kind == AG_NODE_COMPONENT)
            order[n++] = v;
    }
    free(stack);
    free(next);
    *n_out = n;
    return order;
}

/* The comparison's scratch, grown to the most children a compared node has (not the tree's
 * size: most of an edited tree's nodes are dead). */
typedef struct {
    int32_t *ca, *cb;
    uint8_t *used;
    size_t cap;
} same_bufs;

static int bufs_reserve(same_bufs *b, same_scratch *sc, size_t n)
{
    if (n <= b->cap && b->ca)
        return 0;
    size_t cap;
    if (ag_array_capacity(b->cap ? b->cap : 16, n, 3 * sizeof *sc->lo, &cap) ||
        AG_ARRAY_RESIZE(b->ca, cap) || AG_ARRAY_RESIZE(b->cb, cap) ||
        AG_ARRAY_RESIZE(b->used, cap) || AG_ARRAY_RESIZE(sc->lo, 3 * cap) ||
        AG_ARRAY_RESIZE(sc->hi, 3 * cap))
        return -1;
    b->cap = cap;
    return 0;
}

ag_status ag_rules_label(ag_splittree *t, ag_error *err)
{
    size_t N = t->nnodes;
    /* children first, so each comparison is one level deep */
    size_t norder = 0;
    int32_t maxlabel = -1;
    int32_t *order = children_first(t, &norder, &maxlabel);
    /* per variant: list of rules whose representative has that variant */
    int32_t *lhead = order ? malloc(((size_t)maxlabel + 2) * sizeof *lhead) : NULL;
    int32_t *rnext = malloc((norder + 1) * sizeof *rnext);
    /* per rule: what same() looks at first of its representative, kept together (an edited
     * model's stretched copies make many rules of one variant, each node tries them all) */
    rule_key *rkey = malloc((norder + 1) * sizeof *rkey);
    same_bufs bufs = {0};
    same_scratch sc = {NULL, NULL, NULL, 0, 0};
    free(t->rule_count);
    free(t->rule_rep);
    /* a rule has one visible node at least */
    t->rule_count = malloc((norder + 1) * sizeof *t->rule_count);
    t->rule_rep = malloc((norder + 1) * sizeof *t->rule_rep);
    t->nrules = 0;
    if (!order || !lhead || !rnext || !rkey || !t->rule_count || !t->rule_rep) {
        free(order);
        free(lhead);
        free(rnext);
        free(rkey);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while labeling rules");
    }
    for (int32_t l = 0; l <= maxlabel; l++)
        lhead[l] = -1;
    for (size_t oi = 0; oi < norder && !sc.nomem; oi++) {
        size_t ii = (size_t)order[oi];
        ag_tnode *b = &t->nodes[ii];
        uint64_t sig;
        size_t nb = children_sig(t, (int32_t)ii, &sig);
        double eb[3];
        ag_box_extents(&b->box, eb);
        int32_t found = -1;
        int fk = 0;
        for (int32_t r = lhead[b->variant]; r >= 0 && found < 0; r = rnext[r]) {
            const rule_key *q = &rkey[r];
            if (q->kids != nb || q->sig != sig ||
                !same_size(q->ext, eb, (b->rot - q->rot) & 3, t->tol))
                continue;
            int32_t a = t->rule_rep[r];
            if (bufs_reserve(&bufs, &sc, nb)) {
                sc.nomem = 1;
                break;
            }
            int k = (b->rot - t->nodes[a].rot) & 3;
            if (same(t, a, (int32_t)ii, k, bufs.ca, bufs.cb, bufs.used, nb, &sc)) {
                found = r;
                fk = k;
            }
        }
        if (sc.nomem)
            break;
        if (found < 0) {
            found = (int32_t)t->nrules++;
            t->rule_rep[found] = (int32_t)ii;
            t->rule_count[found] = 0;
            rkey[found].kids = nb;
            rkey[found].sig = sig;
            rkey[found].rot = b->rot;
            memcpy(rkey[found].ext, eb, sizeof eb);
            rnext[found] = lhead[b->variant];
            lhead[b->variant] = found;
            fk = 0;
        }
        b->rule = found;
        b->rule_rot = (uint8_t)fk;
        t->rule_count[found]++;
    }
    free(order);
    free(sc.lo);
    free(sc.hi);
    free(sc.ent);
    free(bufs.ca);
    free(bufs.cb);
    free(bufs.used);
    free(lhead);
    free(rnext);
    free(rkey);
    if (sc.nomem)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while labeling rules");
    /* a pattern repeats its cells' rule */
    for (size_t p = 0; p < t->npatterns; p++) {
        int32_t pn = t->patterns[p].node;
        int32_t c = pn >= 0 && (size_t)pn < N ? t->nodes[pn].first_child : -1;
        if (c >= 0 && t->nodes[pn].kind == AG_NODE_PATTERN) {
            t->patterns[p].rule = t->nodes[c].rule;
            t->patterns[p].rot = t->nodes[c].rule_rot;
        }
    }
    return AG_OK;
}
