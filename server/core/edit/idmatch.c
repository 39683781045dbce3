/* Ids for a model proceduralized again (idmatch.h). */
#include "idmatch.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "rebuild.h"

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while matching node ids");
}

/* A node's label name: its component's group ("" for invisible nodes). */
static const char *name_of(const ag_proceduralize_result *r, const ag_tnode *x)
{
    const ag_mesh *m = r->mesh;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 ||
        (size_t)x->component >= m->ncomponents)
        return "";
    int32_t g = m->component_group[x->component];
    return g >= 0 && (size_t)g < m->ngroups && m->group_names[g] ? m->group_names[g] : "";
}

/* The nearest visible ancestor of n, or the root (-1 for the root): patterns come and go
 * with an edit (a row with a window less is no pattern), what holds a node stays. */
static int32_t holder(const ag_splittree *t, int32_t n)
{
    int32_t p = t->nodes[n].parent;
    while (p > 0 && t->nodes[p].kind != AG_NODE_COMPONENT)
        p = t->nodes[p].parent;
    return p;
}

/* The largest distance between corresponding faces of two boxes. */
static double box_distance(const ag_box *a, const ag_box *b)
{
    double d = 0;
    for (int k = 0; k < 3; k++)
        d = fmax(d, fmax(fabs(a->min[k] - b->min[k]), fabs(a->max[k] - b->max[k])));
    return d;
}

/* An old node keyed by its box's lower x, for the search by place. */
typedef struct {
    double x;
    int32_t n;
} keyed;

static int by_x(const void *a, const void *b)
{
    double x = ((const keyed *)a)->x, y = ((const keyed *)b)->x;
    return x < y ? -1 : x > y;
}

/* The first of k (sorted by x) at x or above. */
static size_t first_at_or_above(const keyed *k, size_t n, double x)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (k[mid].x < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static int matchable(const ag_tnode *x)
{
    return x->kind == AG_NODE_COMPONENT || x->kind == AG_NODE_PATTERN;
}

/* Boxes this close are the same: the derivation places shared terminals, which differ from
 * the instances by up to the labels' tolerances. */
static double match_tolerance(const ag_proceduralize_result *r)
{
    const ag_labels *L = r->labels;
    double tol = fmax(r->tree->tol, r->tree->eps);
    if (L)
        tol = fmax(tol, fmax(L->tol, L->share));
    return 2 * tol;
}

/* A fresh node and an old node it may take the id of. */
typedef struct {
    int32_t f, o;
    uint8_t shape;  /* 1: their components have as many triangles (one terminal's) */
    uint8_t holder; /* 1: the old node's holder is what the fresh node's holder matched */
    double d;       /* box_distance */
    double overlap; /* their boxes' common volume over the larger volume */
} candidate;

/* The more alike first: the same terminal, the nearer box, the larger overlap, held by the
 * match of the fresh node's holder; then the old id, then the fresh node, so that ties
 * (boxes that coincide) are decided the same way whatever order either tree lists them in. */
static int by_likeness(const void *pa, const void *pb)
{
    const candidate *a = pa, *b = pb;
    if (a->shape != b->shape)
        return a->shape > b->shape ? -1 : 1;
    if (a->d != b->d)
        return a->d < b->d ? -1 : 1;
    if (a->overlap != b->overlap)
        return a->overlap > b->overlap ? -1 : 1;
    if (a->holder != b->holder)
        return a->holder > b->holder ? -1 : 1;
    if (a->o != b->o)
        return a->o < b->o ? -1 : 1;
    return (a->f > b->f) - (a->f < b->f);
}

static double overlap_share(const ag_box *a, const ag_box *b)
{
    double v = 1;
    for (int k = 0; k < 3; k++)
        v *= fmax(0, fmin(a->max[k], b->max[k]) - fmax(a->min[k], b->min[k]));
    double big = fmax(ag_box_volume(a), ag_box_volume(b));
    return big > 0 ? v / big : 1;
}

/* The candidates of one round of matching, and what both trees are. */
typedef struct {
    const ag_proceduralize_result *old, *fresh;
    double tol;
    int32_t *f2o;
    uint8_t *taken;
    candidate *c;
    size_t n, cap;
} rounds;

/* The mean of a component's triangle corners, from its box's lower corner (0 when it has
 * none): with its triangle count, what tells two terminals on one box apart (a window and its
 * mirror image, a pane and the wall it fills). */
static void corner_mean(const ag_proceduralize_result *r, const ag_tnode *x, double out[3])
{
    const ag_labels *L = r->labels;
    const ag_mesh *m = r->mesh;
    out[0] = out[1] = out[2] = 0;
    if (!L || x->component < 0 || (size_t)x->component >= L->ncomponents)
        return;
    uint32_t a = L->tri_start[x->component], b = L->tri_start[x->component + 1];
    for (uint32_t i = a; i < b; i++)
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                out[k] += m->pos[3 * m->tri[3 * L->tris[i] + c] + k];
    for (int k = 0; k < 3 && b > a; k++)
        out[k] = out[k] / (3.0 * (b - a)) - x->box.min[k];
}

/* Do old node y and fresh node x place one terminal (the same triangle count, the same
 * corner mean within tol)? */
static int same_shape(const rounds *R, const ag_tnode *x, const ag_tnode *y)
{
    const ag_labels *FL = R->fresh->labels, *OL = R->old->labels;
    if (x->component < 0 || y->component < 0 || (size_t)x->component >= FL->ncomponents ||
        (size_t)y->component >= OL->ncomponents)
        return x->component < 0 && y->component < 0;
    if (FL->ntris[x->component] != OL->ntris[y->component])
        return 0;
    double p[3], q[3];
    corner_mean(R->fresh, x, p);
    corner_mean(R->old, y, q);
    return fabs(p[0] - q[0]) <= R->tol && fabs(p[1] - q[1]) <= R->tol &&
           fabs(p[2] - q[2]) <= R->tol;
}

/* Old node o for fresh node f, when it is free, of f's kind and label name, on f's box (and
 * of its shape when `shaped`). */
static ag_status offer(rounds *R, int32_t f, int32_t o, int shaped)
{
    const ag_splittree *O = R->old->tree, *F = R->fresh->tree;
    const ag_tnode *x = &F->nodes[f], *y = &O->nodes[o];
    if (R->taken[o] || y->kind != x->kind || strcmp(name_of(R->old, y), name_of(R->fresh, x)))
        return AG_OK;
    double d = box_distance(&x->box, &y->box);
    if (!(d <= R->tol))
        return AG_OK;
    int shape = same_shape(R, x, y);
    if (shaped && !shape)
        return AG_OK;
    if (AG_ARRAY_RESERVE(R->c, R->cap, R->n + 1))
        return AG_ERR_NOMEM;
    int32_t hf = holder(F, f), ho = holder(O, o);
    R->c[R->n++] = (candidate){f,
                               o,
                               (uint8_t)shape,
                               hf >= 0 && R->f2o[hf] >= 0 ? R->f2o[hf] == ho : hf < 0 && ho < 0,
                               d,
                               overlap_share(&x->box, &y->box)};
    return AG_OK;
}

/* The round's candidates taken best first, each node once. */
static void settle(rounds *R)
{
    if (R->n) /* R->c is NULL until a candidate is added; qsort must not see it */
        qsort(R->c, R->n, sizeof *R->c, by_likeness);
    for (size_t i = 0; i < R->n; i++) {
        const candidate *c = &R->c[i];
        if (R->f2o[c->f] < 0 && !R->taken[c->o]) {
            R->f2o[c->f] = c->o;
            R->taken[c->o] = 1;
        }
    }
    R->n = 0;
}

/* The holder an old node is bucketed under, or -1 when it may not be matched. */
static int32_t bucket_of(const ag_splittree *O, const uint8_t *changed, size_t n)
{
    return matchable(&O->nodes[n]) && !(changed && changed[n]) ? holder(O, (int32_t)n) : -1;
}

/* f2o: per fresh node, the old node it matches (-1). Every choice is made among all the
 * candidates of a round at once (rounds.settle), never by the order nodes come in. */
static ag_status match(const ag_proceduralize_result *old, const ag_proceduralize_result *fresh,
                       const uint8_t *changed, int32_t *f2o)
{
    const ag_splittree *O = old->tree, *F = fresh->tree;
    size_t no = O->nnodes, nf = F->nnodes;
    /* old nodes that may be matched, bucketed by their holder */
    uint32_t *start = calloc(no + 2, sizeof *start);
    int32_t *list = malloc((no + 1) * sizeof *list);
    int32_t *queue = malloc((nf + 1) * sizeof *queue);
    uint32_t *depth = calloc(nf + 1, sizeof *depth);
    uint8_t *taken = calloc(no + 1, 1);
    keyed *k = NULL;
    rounds R = {old, fresh, fmax(match_tolerance(old), match_tolerance(fresh)), f2o, taken,
                NULL, 0, 0};
    ag_status st = AG_OK;
    if (!start || !list || !queue || !depth || !taken) {
        st = AG_ERR_NOMEM;
        goto done;
    }
    for (size_t n = 1; n < no; n++) {
        int32_t h = bucket_of(O, changed, n);
        if (h >= 0)
            start[h + 1]++;
    }
    for (size_t n = 0; n < no; n++)
        start[n + 1] += start[n];
    uint32_t *fill = calloc(no + 1, sizeof *fill);
    if (!fill) {
        st = AG_ERR_NOMEM;
        goto done;
    }
    for (size_t n = 1; n < no; n++) {
        int32_t h = bucket_of(O, changed, n);
        if (h >= 0)
            list[start[h] + fill[h]++] = (int32_t)n;
    }
    free(fill);
    for (size_t f = 0; f < nf; f++)
        f2o[f] = -1;
    if (!no || !nf || F->nodes[0].kind != AG_NODE_ROOT || O->nodes[0].kind != AG_NODE_ROOT)
        goto done;
    f2o[0] = 0;
    taken[0] = 1;
    /* breadth first, one round per depth, so a node's holder is matched (or not) before it;
     * of the same shape only, since which of two coincident boxes holds the other depends on
     * the order they came in (the other shapes wait for the round below) */
    size_t qh = 0, qt = 0;
    queue[qt++] = 0;
    while (qh < qt) {
        size_t level = qh;
        for (; qh < qt && depth[queue[qh]] == depth[queue[level]]; qh++) {
            int32_t f = queue[qh];
            for (int32_t c = F->nodes[f].first_child; c >= 0 && qt < nf;
                 c = F->nodes[c].next_sibling) {
                depth[c] = depth[f] + 1;
                queue[qt++] = c;
            }
            const ag_tnode *x = &F->nodes[f];
            if (f == 0 || !matchable(x))
                continue;
            int32_t h = holder(F, f);
            if (h < 0 || f2o[h] < 0)
                continue;
            for (uint32_t i = start[f2o[h]]; i < start[f2o[h] + 1] && !st; i++)
                st = offer(&R, f, list[i], 1);
        }
        if (st)
            goto done;
        settle(&R);
    }
    /* a node whose holder is new (nested in a node the change made, such as a joined one)
     * or held otherwise now: the same label on the same box anywhere, in one round */
    size_t nl = 0;
    k = malloc((no + 1) * sizeof *k);
    if (!k) {
        st = AG_ERR_NOMEM;
        goto done;
    }
    for (size_t n = 1; n < no; n++)
        if (!taken[n] && matchable(&O->nodes[n]) && !(changed && changed[n]))
            k[nl++] = (keyed){O->nodes[n].box.min[0], (int32_t)n};
    qsort(k, nl, sizeof *k, by_x);
    for (size_t q = 0; q < qt && !st; q++) {
        int32_t f = queue[q];
        const ag_tnode *x = &F->nodes[f];
        if (f == 0 || f2o[f] >= 0 || !matchable(x))
            continue;
        for (size_t i = first_at_or_above(k, nl, x->box.min[0] - R.tol);
             i < nl && k[i].x <= x->box.min[0] + R.tol && !st; i++)
            st = offer(&R, f, k[i].n, 0);
    }
    if (st)
        goto done;
    settle(&R);
    /* an intermediate split node follows the chain end below it */
    for (size_t f = 1; f < nf; f++) {
        const ag_tnode *x = &F->nodes[f];
        int32_t c = x->first_child;
        if (x->kind != AG_NODE_SPLIT || c < 0 || f2o[c] < 0)
            continue;
        int32_t p = O->nodes[f2o[c]].parent;
        if (p > 0 && O->nodes[p].kind == AG_NODE_SPLIT && !taken[p]) {
            f2o[f] = p;
            taken[p] = 1;
        }
    }
done:
    free(k);
    free(R.c);
    free(start);
    free(list);
    free(queue);
    free(depth);
    free(taken);
    return st;
}

static int32_t remap(const int32_t *id, int32_t n)
{
    return n >= 0 ? id[n] : -1;
}

/* fresh's tree with node f at id[f], the other slots dead (an old id keeps its old node's
 * box and pivot, as a dead node does); *source per node: the fresh node it is. */
static ag_splittree *renumbered(const ag_splittree *O, const ag_splittree *F, const int32_t *id,
                                size_t nnodes, int32_t **source)
{
    ag_splittree *T = calloc(1, sizeof *T);
    int32_t *src = malloc((nnodes + 1) * sizeof *src);
    if (T) {
        T->nodes = malloc((nnodes + 1) * sizeof *T->nodes);
        T->patterns = malloc((F->npatterns + 1) * sizeof *T->patterns);
        T->rule_count = malloc((F->nrules + 1) * sizeof *T->rule_count);
        T->rule_rep = malloc((F->nrules + 1) * sizeof *T->rule_rep);
    }
    if (!T || !src || !T->nodes || !T->patterns || !T->rule_count || !T->rule_rep) {
        ag_splittree_free(T);
        free(src);
        return NULL;
    }
    T->nnodes = T->cap = nnodes;
    T->tol = F->tol;
    T->eps = F->eps;
    for (size_t n = 0; n < nnodes; n++) {
        ag_tnode *x = &T->nodes[n];
        if (n < O->nnodes)
            *x = O->nodes[n];
        else
            memset(x, 0, sizeof *x);
        x->kind = AG_NODE_DEAD;
        x->parent = x->first_child = x->last_child = x->next_sibling = -1;
        x->component = x->label = x->variant = x->rule = x->pattern = -1;
        src[n] = 0;
    }
    for (size_t f = 0; f < F->nnodes; f++) {
        if (id[f] < 0)
            continue;
        ag_tnode *x = &T->nodes[id[f]];
        *x = F->nodes[f];
        x->parent = remap(id, x->parent);
        x->first_child = remap(id, x->first_child);
        x->last_child = remap(id, x->last_child);
        x->next_sibling = remap(id, x->next_sibling);
        src[id[f]] = (int32_t)f;
    }
    for (size_t p = 0; p < F->npatterns; p++) {
        T->patterns[p] = F->patterns[p];
        T->patterns[p].node = remap(id, F->patterns[p].node);
    }
    T->npatterns = T->cap_patterns = F->npatterns;
    for (size_t r = 0; r < F->nrules; r++) {
        T->rule_count[r] = F->rule_count[r];
        T->rule_rep[r] = remap(id, F->rule_rep[r]);
    }
    T->nrules = F->nrules;
    *source = src;
    return T;
}

/* Label numbers for fresh's components as the old model named its kept nodes' labels:
 * proceduralizing again classes by shape, so a kept node's label may come back together with
 * new geometry of its shape, or split (a stretched window is another shape now). A variant
 * whose kept members all had one old label ("L<k>") goes to that label; the other variants
 * keep their label's number unless an old name took it, else follow the largest number.
 * label (per component) and vlabel (per variant) get the numbers, *nlabels the label count;
 * -1 when out of memory. */
static int old_label_names(const ag_proceduralize_result *old,
                           const ag_proceduralize_result *fresh, const int32_t *f2o,
                           int32_t *label, int32_t *vlabel, size_t *nlabels)
{
    const ag_labels *L = fresh->labels;
    const ag_splittree *F = fresh->tree, *O = old->tree;
    size_t nv = L->nvariants, nl = L->nlabels;
    size_t *claim = calloc(nv + 1, sizeof *claim);
    uint8_t *mixed = calloc(nv + 1, 1), *used = NULL;
    int32_t *moved = malloc((nl + 1) * sizeof *moved);
    size_t top = nl;
    int st = -1;
    if (!claim || !mixed || !moved)
        goto done;
    for (size_t f = 0; f < F->nnodes; f++) {
        const ag_tnode *x = &F->nodes[f];
        if (x->kind != AG_NODE_COMPONENT || f2o[f] < 0 || x->component < 0 ||
            (size_t)x->component >= L->ncomponents)
            continue;
        int32_t v = L->variant[x->component];
        if (v < 0 || (size_t)v >= nv)
            continue;
        size_t k = ag__rebuild_label_number(name_of(old, &O->nodes[f2o[f]]));
        if (!k || (claim[v] && claim[v] != k))
            mixed[v] = 1;
        else
            claim[v] = k;
    }
    for (size_t v = 0; v < nv; v++) {
        if (mixed[v])
            claim[v] = 0;
        if (claim[v] > top)
            top = claim[v];
    }
    used = calloc(top + 1, 1);
    if (!used)
        goto done;
    for (size_t v = 0; v < nv; v++)
        if (claim[v])
            used[claim[v] - 1] = 1;
    for (size_t l = 0; l < nl; l++)
        moved[l] = -1;
    size_t next = top;
    for (size_t v = 0; v < nv; v++) {
        int32_t l = L->variant_label[v];
        if (claim[v]) {
            vlabel[v] = (int32_t)claim[v] - 1;
        } else if (l < 0 || (size_t)l >= nl) {
            vlabel[v] = l;
        } else {
            if (moved[l] < 0)
                moved[l] = used[l] ? (int32_t)next++ : l;
            vlabel[v] = moved[l];
        }
    }
    for (size_t c = 0; c < L->ncomponents; c++) {
        int32_t v = L->variant[c];
        label[c] = v >= 0 && (size_t)v < nv ? vlabel[v] : L->label[c];
    }
    *nlabels = next > nl ? next : nl;
    st = 0;
done:
    free(claim);
    free(mixed);
    free(used);
    free(moved);
    return st;
}

ag_status ag_idmatch_renumber(const ag_proceduralize_result *old,
                              const ag_proceduralize_result *fresh, const uint8_t *changed,
                              const ag_patterns_options *popt, ag_proceduralize_result **out,
                              ag_idmatch_report *rep, ag_error *err)
{
    *out = NULL;
    const ag_splittree *O = old->tree, *F = fresh->tree;
    const ag_labels *FL = fresh->labels;
    int32_t *f2o = malloc((F->nnodes + 1) * sizeof *f2o);
    int32_t *id = malloc((F->nnodes + 1) * sizeof *id);
    int32_t *label = malloc((FL->ncomponents + 1) * sizeof *label);
    int32_t *vlabel = malloc((FL->nvariants + 1) * sizeof *vlabel);
    size_t nlabels = 0;
    if (!f2o || !id || !label || !vlabel || match(old, fresh, changed, f2o) ||
        old_label_names(old, fresh, f2o, label, vlabel, &nlabels)) {
        free(f2o);
        free(id);
        free(label);
        free(vlabel);
        return nomem(err);
    }
    ag_idmatch_report r = {0};
    size_t next = O->nnodes;
    uint8_t *alive = calloc(O->nnodes + 1, 1);
    if (!alive) {
        free(f2o);
        free(id);
        free(label);
        free(vlabel);
        return nomem(err);
    }
    for (size_t f = 0; f < F->nnodes; f++) {
        const ag_tnode *x = &F->nodes[f];
        if (x->kind == AG_NODE_DEAD) {
            id[f] = -1;
            continue;
        }
        id[f] = f2o[f] >= 0 ? f2o[f] : (int32_t)next++;
        if (f2o[f] >= 0)
            alive[f2o[f]] = 1;
        if (x->kind == AG_NODE_COMPONENT) {
            if (f2o[f] >= 0)
                r.kept++;
            else
                r.appended++;
        }
    }
    int same = next == O->nnodes && F->nnodes == O->nnodes;
    for (size_t n = 0; n < O->nnodes; n++) {
        r.dead += O->nodes[n].kind == AG_NODE_COMPONENT && !alive[n];
        same = same && (O->nodes[n].kind == AG_NODE_DEAD ? F->nodes[n].kind == AG_NODE_DEAD
                                                         : f2o[n] == (int32_t)n);
    }
    for (size_t c = 0; same && c < FL->ncomponents; c++)
        same = label[c] == FL->label[c];
    free(alive);
    if (same) { /* fresh numbers every node as old did: nothing to rebuild */
        free(f2o);
        free(id);
        free(label);
        free(vlabel);
        if (rep)
            *rep = r;
        return AG_OK;
    }
    free(f2o);
    int32_t *source = NULL;
    ag_splittree *T = renumbered(O, F, id, next, &source);
    free(id);
    if (!T) {
        free(label);
        free(vlabel);
        return nomem(err);
    }
    /* fresh as the rebuild reads it, its labels named after the old ones */
    ag_proceduralize_result view = *fresh;
    ag_labels named = *fresh->labels;
    named.label = label;
    named.variant_label = vlabel;
    named.nlabels = nlabels;
    view.labels = &named;
    for (size_t n = 0; n < T->nnodes; n++)
        if (T->nodes[n].kind == AG_NODE_COMPONENT && T->nodes[n].component >= 0 &&
            (size_t)T->nodes[n].component < named.ncomponents)
            T->nodes[n].label = label[T->nodes[n].component];
    ag_status st = ag_rebuild(&view, T, source, popt, out, err);
    free(label);
    free(vlabel);
    if (!st && rep)
        *rep = r;
    return st;
}
