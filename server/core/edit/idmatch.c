/* Ids for a model proceduralized again (idmatch.h). */
#include "idmatch.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

/* The nearest ancestor of n that is not an intermediate split node (-1 for the root). */
static int32_t holder(const ag_splittree *t, int32_t n)
{
    int32_t p = t->nodes[n].parent;
    while (p >= 0 && t->nodes[p].kind == AG_NODE_SPLIT)
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

/* f2o: per fresh node, the old node it matches (-1). */
static ag_status match(const ag_proceduralize_result *old, const ag_proceduralize_result *fresh,
                       const uint8_t *changed, int32_t *f2o)
{
    const ag_splittree *O = old->tree, *F = fresh->tree;
    size_t no = O->nnodes, nf = F->nnodes;
    double tol = fmax(match_tolerance(old), match_tolerance(fresh));
    /* old nodes that may be matched, bucketed by their holder */
    uint32_t *start = calloc(no + 2, sizeof *start);
    int32_t *list = malloc((no + 1) * sizeof *list);
    int32_t *queue = malloc((nf + 1) * sizeof *queue);
    uint8_t *taken = calloc(no + 1, 1);
    ag_status st = AG_OK;
    if (!start || !list || !queue || !taken) {
        st = AG_ERR_NOMEM;
        goto done;
    }
    for (size_t n = 1; n < no; n++) {
        int32_t h = matchable(&O->nodes[n]) && !(changed && changed[n]) ? holder(O, (int32_t)n)
                                                                         : -1;
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
        int32_t h = matchable(&O->nodes[n]) && !(changed && changed[n]) ? holder(O, (int32_t)n)
                                                                         : -1;
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
    /* top-down, so a node's holder is matched (or not) before it */
    size_t qh = 0, qt = 0;
    queue[qt++] = 0;
    while (qh < qt) {
        int32_t f = queue[qh++];
        for (int32_t c = F->nodes[f].first_child; c >= 0 && qt < nf; c = F->nodes[c].next_sibling)
            queue[qt++] = c;
        const ag_tnode *x = &F->nodes[f];
        if (f == 0 || !matchable(x))
            continue;
        int32_t h = holder(F, f);
        if (h < 0 || f2o[h] < 0)
            continue;
        const char *name = name_of(fresh, x);
        int32_t best = -1;
        double bd = tol;
        for (uint32_t i = start[f2o[h]]; i < start[f2o[h] + 1]; i++) {
            int32_t o = list[i];
            const ag_tnode *y = &O->nodes[o];
            if (taken[o] || y->kind != x->kind || strcmp(name_of(old, y), name))
                continue;
            double d = box_distance(&x->box, &y->box);
            if (d <= bd) {
                bd = d;
                best = o;
            }
        }
        if (best >= 0) {
            f2o[f] = best;
            taken[best] = 1;
        }
    }
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
    free(start);
    free(list);
    free(queue);
    free(taken);
    return st;
}

static int32_t remap(const int32_t *id, int32_t n)
{
    return n >= 0 ? id[n] : -1;
}

/* fresh's tree with node f at id[f], the other slots dead; *source per node: the fresh node it
 * is. */
static ag_splittree *renumbered(const ag_splittree *F, const int32_t *id, size_t nnodes,
                                int32_t **source)
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

ag_status ag_idmatch_renumber(const ag_proceduralize_result *old,
                              const ag_proceduralize_result *fresh, const uint8_t *changed,
                              const ag_patterns_options *popt, ag_proceduralize_result **out,
                              ag_idmatch_report *rep, ag_error *err)
{
    *out = NULL;
    const ag_splittree *O = old->tree, *F = fresh->tree;
    int32_t *f2o = malloc((F->nnodes + 1) * sizeof *f2o);
    int32_t *id = malloc((F->nnodes + 1) * sizeof *id);
    if (!f2o || !id || match(old, fresh, changed, f2o)) {
        free(f2o);
        free(id);
        return nomem(err);
    }
    ag_idmatch_report r = {0};
    size_t next = O->nnodes;
    uint8_t *alive = calloc(O->nnodes + 1, 1);
    if (!alive) {
        free(f2o);
        free(id);
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
    for (size_t n = 0; n < O->nnodes; n++)
        r.dead += O->nodes[n].kind == AG_NODE_COMPONENT && !alive[n];
    free(alive);
    free(f2o);
    int32_t *source = NULL;
    ag_splittree *T = renumbered(F, id, next, &source);
    free(id);
    if (!T)
        return nomem(err);
    ag_status st = ag_rebuild(fresh, T, source, popt, out, err);
    if (!st && rep)
        *rep = r;
    return st;
}
