/* An edited tree to a proceduralization result (rebuild.h): chains, mesh, labels, rules,
 * patterns, grammar. */
#include "rebuild.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "../proc/adjacency.h"
#include "resize.h"

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while rebuilding the edited model");
}

/* ---- the mesh ---------------------------------------------------------------------------- */

/* The visible nodes of t in component order: the input's components whose node stays, in
 * their order, then the nodes that place another's component (copies), in index order.
 * comps (ncomps of them) lists t's visible nodes in index order when the caller has them, so
 * the dead nodes are not looked at again; NULL: they are found here. */
static int32_t *component_order(const ag_proceduralize_result *in, const ag_splittree *t,
                                const int32_t *source, const int32_t *comps, size_t ncomps,
                                size_t *n)
{
    const ag_splittree *ot = in->tree;
    int32_t *order = malloc((t->nnodes + 1) * sizeof *order);
    uint8_t *taken = calloc(t->nnodes + 1, 1);
    if (!order || !taken) {
        free(order);
        free(taken);
        return NULL;
    }
    size_t k = 0;
    for (size_t c = 0; c < ot->ncomponents; c++) {
        int32_t v = ot->comp_node[c];
        if (v >= 0 && (size_t)v < t->nnodes && t->nodes[v].kind == AG_NODE_COMPONENT &&
            source[v] == v) {
            order[k++] = v;
            taken[v] = 1;
        }
    }
    /* then the nodes that place another node's component (copies, a join's node) */
    if (comps) {
        for (size_t i = 0; i < ncomps; i++)
            if (!taken[comps[i]])
                order[k++] = comps[i];
    } else {
        for (size_t v = 0; v < t->nnodes; v++)
            if (t->nodes[v].kind == AG_NODE_COMPONENT && !taken[v])
                order[k++] = (int32_t)v;
    }
    free(taken);
    *n = k;
    return order;
}

/* Emits the components of `order` into a new mesh: each node's source component mapped from
 * the source's box onto the node's. */
static ag_status emit(const ag_proceduralize_result *in, const ag_splittree *t,
                      const int32_t *source, const int32_t *order, size_t n, ag_mesh **out,
                      ag_error *err)
{
    const ag_splittree *ot = in->tree;
    const ag_labels *L = in->labels;
    const ag_mesh *src = in->mesh;
    size_t nv = 0, ntri = 0;
    for (size_t i = 0; i < n; i++) {
        int32_t oc = ot->nodes[source[order[i]]].component;
        if (oc >= 0 && (size_t)oc < L->ncomponents) {
            ntri += L->tri_start[oc + 1] - L->tri_start[oc];
            nv += 3 * (L->tri_start[oc + 1] - L->tri_start[oc]);
        }
    }
    if (ntri > AG_EDIT_MAX_TRIANGLES)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "resize: the result would exceed %d triangles",
                            AG_EDIT_MAX_TRIANGLES);
    ag_mesh *m = ag_mesh_create();
    int32_t *group_of = malloc((L->nlabels + 1) * sizeof *group_of);
    uint32_t *vmap = malloc((src->nverts + 1) * sizeof *vmap);
    uint32_t *stamp = calloc(src->nverts + 1, sizeof *stamp);
    ag_status st = m && group_of && vmap && stamp ? ag_mesh_reserve(m, nv, ntri) : AG_ERR_NOMEM;
    for (size_t l = 0; l < L->nlabels; l++)
        group_of[l] = -1;
    for (size_t i = 0; i < n && !st; i++) {
        const ag_tnode *x = &t->nodes[order[i]];
        const ag_tnode *sx = &ot->nodes[source[order[i]]];
        int32_t oc = sx->component;
        int32_t lab = oc >= 0 && (size_t)oc < L->ncomponents ? L->label[oc] : -1;
        int32_t g = -1;
        if (lab >= 0 && (size_t)lab < L->nlabels) {
            if (group_of[lab] < 0) {
                char name[32];
                size_t gi;
                snprintf(name, sizeof name, "L%d", lab + 1);
                if ((st = ag_mesh_add_group(m, name, &gi)))
                    break;
                group_of[lab] = (int32_t)gi;
            }
            g = group_of[lab];
        }
        size_t comp;
        if ((st = ag_mesh_add_component(m, g, &comp)))
            break;
        if (oc < 0 || (size_t)oc >= L->ncomponents)
            continue;
        double s[3], tt[3];
        for (int a = 0; a < 3; a++) {
            double w = ag_box_extent(&sx->box, a), w2 = ag_box_extent(&x->box, a);
            s[a] = w > AG_EDIT_FLAT ? w2 / w : 1;
            tt[a] = w > AG_EDIT_FLAT ? x->box.min[a] - s[a] * sx->box.min[a]
                                     : ag_box_centre_axis(&x->box, a) - sx->box.min[a];
        }
        uint32_t emission = (uint32_t)i + 1;
        for (uint32_t k = L->tri_start[oc]; k < L->tri_start[oc + 1] && !st; k++) {
            uint32_t tr = L->tris[k], v[3];
            for (int j = 0; j < 3 && !st; j++) {
                uint32_t sv = src->tri[3 * tr + j];
                if (stamp[sv] != emission) {
                    const double *p = &src->pos[3 * sv];
                    stamp[sv] = emission;
                    vmap[sv] = (uint32_t)m->nverts;
                    st = ag_mesh_add_vertex(m, s[0] * p[0] + tt[0], s[1] * p[1] + tt[1],
                                            s[2] * p[2] + tt[2]);
                }
                v[j] = vmap[sv];
            }
            if (!st)
                st = ag_mesh_add_triangle(m, v[0], v[1], v[2], (uint32_t)comp);
        }
    }
    free(group_of);
    free(vmap);
    free(stamp);
    if (st) {
        ag_mesh_free(m);
        return st == AG_ERR_NOMEM ? nomem(err) : ag_error_set(err, st, 0, "the edited mesh");
    }
    *out = m;
    return AG_OK;
}

ag_status ag_rebuild_mesh(const ag_proceduralize_result *in, const ag_splittree *t,
                          const int32_t *source, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    size_t n;
    int32_t *order = component_order(in, t, source, NULL, 0, &n);
    if (!order)
        return nomem(err);
    ag_status st = emit(in, t, source, order, n, out, err);
    free(order);
    return st;
}

/* ---- labels ------------------------------------------------------------------------------ */

static ag_labels *labels_new(size_t nc, size_t nlabels, size_t nvariants)
{
    ag_labels *L = calloc(1, sizeof *L);
    if (!L)
        return NULL;
    L->ncomponents = nc;
    L->nlabels = nlabels;
    L->nvariants = nvariants;
    L->box = malloc((nc + 1) * sizeof *L->box);
    L->ntris = calloc(nc + 1, sizeof *L->ntris);
    L->label = malloc((nc + 1) * sizeof *L->label);
    L->rot = calloc(nc + 1, 1);
    L->variant = malloc((nc + 1) * sizeof *L->variant);
    L->vrot = calloc(nc + 1, 1);
    L->tri_start = calloc(nc + 2, sizeof *L->tri_start);
    L->exemplar = calloc(nlabels + 1, sizeof *L->exemplar);
    L->count = calloc(nlabels + 1, sizeof *L->count);
    L->variant_exemplar = calloc(nvariants + 1, sizeof *L->variant_exemplar);
    L->variant_count = calloc(nvariants + 1, sizeof *L->variant_count);
    L->variant_label = calloc(nvariants + 1, sizeof *L->variant_label);
    L->mirror = calloc(nc + 1, 1);
    L->turn = calloc(nc + 1, sizeof *L->turn);
    L->variant_deviation = calloc(nvariants + 1, sizeof *L->variant_deviation);
    if (!L->box || !L->ntris || !L->label || !L->rot || !L->variant || !L->vrot ||
        !L->tri_start || !L->exemplar || !L->count || !L->variant_exemplar ||
        !L->variant_count || !L->variant_label || !L->mirror || !L->turn ||
        !L->variant_deviation) {
        ag_labels_free(L);
        return NULL;
    }
    return L;
}

/* Triangle lists, boxes (the tree's), exemplars and counts of labels whose per-component
 * classes are set. */
static ag_status labels_complete(ag_labels *L, const ag_mesh *m, const ag_splittree *t)
{
    size_t nc = L->ncomponents;
    for (size_t i = 0; i < m->ntris; i++)
        L->ntris[m->tri_component[i]]++;
    for (size_t c = 0; c < nc; c++)
        L->tri_start[c + 1] = L->tri_start[c] + L->ntris[c];
    L->tris = malloc((m->ntris + 1) * sizeof *L->tris);
    uint32_t *fill = malloc((nc + 1) * sizeof *fill);
    if (!L->tris || !fill) {
        free(fill);
        return AG_ERR_NOMEM;
    }
    memcpy(fill, L->tri_start, nc * sizeof *fill);
    for (size_t i = 0; i < m->ntris; i++)
        L->tris[fill[m->tri_component[i]]++] = (uint32_t)i;
    free(fill);
    for (size_t l = 0; l < L->nlabels; l++)
        L->exemplar[l] = UINT32_MAX;
    for (size_t v = 0; v < L->nvariants; v++)
        L->variant_exemplar[v] = UINT32_MAX;
    for (size_t c = 0; c < nc; c++) {
        int32_t n = c < t->ncomponents ? t->comp_node[c] : -1;
        L->box[c] = n >= 0 ? t->nodes[n].box : ag_box_empty();
        if (!L->ntris[c]) {
            L->label[c] = L->variant[c] = -1;
            continue;
        }
        int32_t l = L->label[c], v = L->variant[c];
        if (l >= 0 && (size_t)l < L->nlabels) {
            if (L->exemplar[l] == UINT32_MAX)
                L->exemplar[l] = (uint32_t)c;
            L->count[l]++;
        }
        if (v >= 0 && (size_t)v < L->nvariants) {
            if (L->variant_exemplar[v] == UINT32_MAX)
                L->variant_exemplar[v] = (uint32_t)c;
            L->variant_count[v]++;
        }
    }
    /* a label or variant nothing uses any more keeps a valid (unused) exemplar */
    for (size_t l = 0; l < L->nlabels; l++)
        if (L->exemplar[l] == UINT32_MAX)
            L->exemplar[l] = 0;
    for (size_t v = 0; v < L->nvariants; v++)
        if (L->variant_exemplar[v] == UINT32_MAX)
            L->variant_exemplar[v] = 0;
    return AG_OK;
}

/* An edit that removes a label's or a variant's exemplar makes another component its first,
 * and the terminal is then taken from that one: the turns of the others (and of their nodes)
 * count from it. */
static void rebase_turns(ag_labels *L, ag_splittree *t)
{
    for (size_t c = 0; c < L->ncomponents; c++) {
        int32_t v = L->variant[c], l = L->label[c];
        int32_t n = c < t->ncomponents ? t->comp_node[c] : -1;
        if (v >= 0 && (size_t)v < L->nvariants) {
            uint32_t e = L->variant_exemplar[v];
            if (e != c && L->vrot[e]) {
                L->vrot[c] = (uint8_t)((L->vrot[c] - L->vrot[e]) & 3);
                if (n >= 0)
                    t->nodes[n].rot = (uint8_t)((t->nodes[n].rot - L->vrot[e]) & 3);
            }
        }
        if (l >= 0 && (size_t)l < L->nlabels) {
            uint32_t e = L->exemplar[l];
            if (e != c && (L->rot[e] || L->turn[e] != 0)) {
                L->rot[c] = (uint8_t)((L->rot[c] - L->rot[e]) & 3);
                L->turn[c] -= L->turn[e];
            }
        }
    }
    /* the exemplars last: the others were counted from their old turns */
    for (size_t v = 0; v < L->nvariants; v++) {
        uint32_t e = L->variant_exemplar[v];
        if (e < L->ncomponents && L->vrot[e]) {
            int32_t n = e < t->ncomponents ? t->comp_node[e] : -1;
            if (n >= 0)
                t->nodes[n].rot = (uint8_t)((t->nodes[n].rot - L->vrot[e]) & 3);
            L->vrot[e] = 0;
        }
    }
    for (size_t l = 0; l < L->nlabels; l++) {
        uint32_t e = L->exemplar[l];
        if (e < L->ncomponents) {
            L->rot[e] = 0;
            L->turn[e] = 0;
        }
    }
}

/* ---- the tree ---------------------------------------------------------------------------- */

/* The visible nodes of a tree being rebuilt, when known: every visible node (norder, in
 * component order, each with its own component) and the pattern nodes in index order. The
 * later stages then look at these instead of every node: an edited tree's nodes are mostly
 * dead ones. */
typedef struct {
    const int32_t *order;
    size_t norder;
    const int32_t *pats;
    size_t npats;
} live_nodes;

/* Component map of a tree whose visible nodes carry their component (all of them in
 * live->order when live is given; distinct nodes have distinct components). */
static ag_status tree_components(ag_splittree *t, size_t nc, const live_nodes *live)
{
    free(t->comp_node);
    t->ncomponents = nc;
    t->comp_node = malloc((nc + 1) * sizeof *t->comp_node);
    if (!t->comp_node)
        return AG_ERR_NOMEM;
    for (size_t c = 0; c < nc; c++)
        t->comp_node[c] = -1;
    if (live) {
        for (size_t i = 0; i < live->norder; i++) {
            const ag_tnode *x = &t->nodes[live->order[i]];
            if (x->kind == AG_NODE_COMPONENT && x->component >= 0 && (size_t)x->component < nc)
                t->comp_node[x->component] = live->order[i];
        }
        return AG_OK;
    }
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && t->nodes[n].component >= 0 &&
            (size_t)t->nodes[n].component < nc)
            t->comp_node[t->nodes[n].component] = (int32_t)n;
    return AG_OK;
}

/* Patterns whose node is gone are dropped; the others renumbered. */
static void compact_patterns(ag_splittree *t)
{
    size_t k = 0;
    for (size_t p = 0; p < t->npatterns; p++) {
        int32_t n = t->patterns[p].node;
        if (n < 0 || (size_t)n >= t->nnodes || t->nodes[n].kind != AG_NODE_PATTERN ||
            t->nodes[n].pattern != (int32_t)p)
            continue;
        t->patterns[k] = t->patterns[p];
        t->nodes[n].pattern = (int32_t)k++;
    }
    t->npatterns = k;
}

/* Does pattern node pn still repeat one rule on its grid? */
static int pattern_holds(const ag_splittree *t, int32_t pn)
{
    const ag_tnode *P = &t->nodes[pn];
    if (P->pattern < 0 || (size_t)P->pattern >= t->npatterns)
        return 0;
    const ag_pattern *pp = &t->patterns[P->pattern];
    int32_t first = P->first_child;
    if (first < 0)
        return 0;
    const ag_tnode *f = &t->nodes[first];
    double tol = t->tol > 0 ? t->tol : t->eps;
    size_t k = 0;
    for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling, k++) {
        const ag_tnode *x = &t->nodes[c];
        if (x->kind != AG_NODE_COMPONENT || x->rule != f->rule || x->rule_rot != f->rule_rot ||
            x->rule < 0)
            return 0;
        for (int a = 0; a < 3; a++)
            if (fabs(ag_box_extent(&x->box, a) - ag_box_extent(&f->box, a)) > tol)
                return 0;
        if (pp->nvec)
            continue;
        size_t rest = k;
        for (int a = 0; a < 3; a++) {
            uint32_t cnt = pp->counts[a] ? pp->counts[a] : 1;
            size_t ia = rest % cnt;
            rest /= cnt;
            if (fabs(x->box.min[a] - (f->box.min[a] + (double)ia * pp->step[a])) > tol)
                return 0;
        }
    }
    if (!pp->nvec && k != (size_t)pp->counts[0] * pp->counts[1] * pp->counts[2])
        return 0;
    return 1;
}

/* The pattern's cells hang from its parent again, each by its own split chain; the pattern and
 * the chain above it go. */
static ag_status dissolve(ag_splittree *t, int32_t pn)
{
    int32_t end = pn, top = pn, parent = t->nodes[pn].parent;
    if (parent >= 0 && t->nodes[parent].kind == AG_NODE_SPLIT) {
        top = parent;
        parent = t->nodes[parent].parent;
    }
    if (parent < 0)
        return AG_OK;
    ag_splittree_detach(t, top);
    int32_t c = t->nodes[end].first_child;
    t->nodes[end].first_child = t->nodes[end].last_child = -1;
    while (c >= 0) {
        int32_t next = t->nodes[c].next_sibling;
        t->nodes[c].parent = -1;
        t->nodes[c].next_sibling = -1;
        ag_status st = ag_splittree_hang(t, parent, c);
        if (st)
            return st;
        c = next;
    }
    for (int32_t x = top; x >= 0;) {
        int32_t below = x == end ? -1 : t->nodes[x].first_child;
        ag_tnode *n = &t->nodes[x];
        n->kind = AG_NODE_DEAD;
        n->parent = n->first_child = n->last_child = n->next_sibling = -1;
        x = below;
    }
    return AG_OK;
}

/* Rules found again; patterns that no longer hold dissolved (then rules once more); new
 * repetitions found. */
static ag_status rules_and_patterns(ag_splittree *t, const ag_patterns_options *popt,
                                    const live_nodes *live, ag_error *err)
{
    ag_status st = ag_rules_label(t, err);
    if (st)
        return st;
    int dissolved = 0;
    /* a dissolution only adds split nodes and kills its own pattern's chain: the pattern
     * nodes listed before are all there are */
    size_t npn = live ? live->npats : t->nnodes;
    for (size_t i = 0; i < npn; i++) {
        int32_t n = live ? live->pats[i] : (int32_t)i;
        if (t->nodes[n].kind == AG_NODE_PATTERN && !pattern_holds(t, n)) {
            if ((st = dissolve(t, n)))
                return nomem(err);
            dissolved = 1;
        }
    }
    if (dissolved) {
        compact_patterns(t);
        if ((st = ag_rules_label(t, err)))
            return st;
    }
    size_t before = t->npatterns;
    if ((st = ag_patterns_find(t, popt, err)))
        return st;
    /* rules were found before the new patterns, as proceduralization finds them */
    (void)before;
    return AG_OK;
}

static ag_status finish(ag_mesh *mesh, ag_labels *L, ag_splittree *t, int with_rules,
                        const ag_patterns_options *popt, const live_nodes *live,
                        ag_proceduralize_result **out, ag_error *err)
{
    ag_proceduralize_result *r = calloc(1, sizeof *r);
    ag_status st = r ? AG_OK : AG_ERR_NOMEM;
    if (!st)
        st = tree_components(t, mesh->ncomponents, live);
    if (!st)
        st = labels_complete(L, mesh, t);
    if (!st)
        st = ag_splittree_adjacency_update(t, NULL); /* only the changed nodes' pairs found again */
    if (st) {
        st = nomem(err);
        goto fail;
    }
    if (with_rules)
        rebase_turns(L, t);
    if (with_rules && (st = rules_and_patterns(t, popt, live, err)))
        goto fail;
    /* a dead node names nothing (its old rule, pattern or component may be out of range now),
     * nor links to any node (a chain a new pattern replaced keeps its links otherwise): it is
     * the node a reload of the kept tree makes. In the pass that maps the components again
     * (new patterns moved nodes, none changed its component); a dead node cleared before is
     * only read. */
    if (with_rules) {
        size_t nc = mesh->ncomponents;
        free(t->comp_node);
        t->ncomponents = nc;
        if (!(t->comp_node = malloc((nc + 1) * sizeof *t->comp_node))) {
            st = nomem(err);
            goto fail;
        }
        for (size_t c = 0; c < nc; c++)
            t->comp_node[c] = -1;
        for (size_t n = 0; n < t->nnodes; n++) {
            ag_tnode *x = &t->nodes[n];
            if (x->kind == AG_NODE_COMPONENT) {
                if (x->component >= 0 && (size_t)x->component < nc)
                    t->comp_node[x->component] = (int32_t)n;
            } else if (x->kind == AG_NODE_DEAD &&
                       (x->rule != -1 || x->pattern != -1 || x->component != -1 ||
                        x->label != -1 || x->variant != -1 || x->parent != -1 ||
                        x->first_child != -1 || x->last_child != -1 || x->next_sibling != -1)) {
                x->rule = x->pattern = x->component = -1;
                x->label = x->variant = -1;
                x->parent = x->first_child = x->last_child = x->next_sibling = -1;
            }
        }
    }
    r->mesh = mesh;
    r->labels = L;
    r->tree = t;
    r->segment.components = mesh->ncomponents;
    mesh = NULL;
    L = NULL;
    t = NULL;
    if ((st = ag_grammar_export(r->mesh, r->labels, r->tree, &r->grammar, &r->info, err)))
        goto fail;
    *out = r;
    return AG_OK;
fail:
    ag_proceduralize_result_free(r);
    ag_mesh_free(mesh);
    ag_labels_free(L);
    ag_splittree_free(t);
    return st;
}

ag_status ag_rebuild(const ag_proceduralize_result *in, ag_splittree *t, int32_t *source,
                     const ag_patterns_options *popt, ag_proceduralize_result **out,
                     ag_error *err)
{
    *out = NULL;
    const ag_labels *OL = in->labels;
    const ag_splittree *ot = in->tree;
    ag_mesh *mesh = NULL;
    ag_labels *L = NULL;
    size_t n = 0, ncomps = 0, cap_comps = 0, npats = 0, cap_pats = 0;
    int32_t *comps = NULL, *pats = NULL, *order = NULL;
    ag_status st = AG_OK;
    /* the chains from the new boxes; the one pass over every node also lists the visible and
     * the pattern nodes (a rechain adds split nodes only) */
    for (size_t v = 0; v < t->nnodes && !st; v++) {
        const ag_tnode *x = &t->nodes[v];
        if (x->kind == AG_NODE_COMPONENT)
            st = AG_ARRAY_RESERVE(comps, cap_comps, ncomps + 1);
        else if (x->kind == AG_NODE_PATTERN)
            st = AG_ARRAY_RESERVE(pats, cap_pats, npats + 1);
        else
            continue;
        if (st)
            break;
        if (x->kind == AG_NODE_COMPONENT)
            comps[ncomps++] = (int32_t)v;
        else
            pats[npats++] = (int32_t)v;
        if (v > 0 && x->parent >= 0)
            st = ag_splittree_rechain(t, (int32_t)v);
    }
    if (!st)
        order = component_order(in, t, source, comps, ncomps, &n);
    free(comps);
    comps = NULL;
    if (!order) {
        st = nomem(err);
        goto fail;
    }
    compact_patterns(t);
    if ((st = emit(in, t, source, order, n, &mesh, err)))
        goto fail;
    if (!(L = labels_new(mesh->ncomponents, OL->nlabels, OL->nvariants))) {
        st = nomem(err);
        goto fail;
    }
    for (size_t i = 0; i < n; i++) {
        ag_tnode *x = &t->nodes[order[i]];
        int32_t oc = ot->nodes[source[order[i]]].component;
        x->component = (int32_t)i;
        int ok = oc >= 0 && (size_t)oc < OL->ncomponents;
        L->label[i] = ok ? OL->label[oc] : -1;
        L->rot[i] = ok ? OL->rot[oc] : 0;
        L->variant[i] = ok ? OL->variant[oc] : -1;
        L->vrot[i] = ok ? OL->vrot[oc] : 0;
        L->mirror[i] = ok && OL->mirror ? OL->mirror[oc] : 0;
        L->turn[i] = ok && OL->turn ? OL->turn[oc] : 0;
    }
    memcpy(L->variant_label, OL->variant_label, OL->nvariants * sizeof *L->variant_label);
    if (OL->variant_deviation)
        memcpy(L->variant_deviation, OL->variant_deviation,
               OL->nvariants * sizeof *L->variant_deviation);
    L->exact_copies = OL->exact_copies;
    L->units = OL->units; /* a resize changes sizes, not the unit */
    /* tolerances follow the model's size */
    double od = ag_box_diagonal(&ot->nodes[0].box), nd = ag_box_diagonal(&t->nodes[0].box);
    double scale = od > 0 && nd > 0 ? nd / od : 1;
    L->diagonal = OL->diagonal * scale;
    L->tol = OL->tol * scale;
    L->exact = OL->exact * scale;
    L->share = OL->share * scale;
    t->tol = L->exact;
    t->eps = ot->eps * scale;
    free(source);
    source = NULL;
    live_nodes live = {order, n, pats, npats};
    st = finish(mesh, L, t, 1, popt, &live, out, err);
    free(order);
    free(pats);
    return st;
fail:
    free(order);
    free(pats);
    free(source);
    ag_mesh_free(mesh);
    ag_labels_free(L);
    ag_splittree_free(t);
    return st;
}

ag_status ag_rebuild_finish(ag_mesh *mesh, ag_splittree *tree, const ag_rebuild_classes *c,
                            ag_proceduralize_result **out, ag_error *err)
{
    *out = NULL;
    if (c->ncomponents != mesh->ncomponents) {
        ag_mesh_free(mesh);
        ag_splittree_free(tree);
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the kept classes name %zu components, the mesh has %zu",
                            c->ncomponents, mesh->ncomponents);
    }
    ag_labels *L = labels_new(mesh->ncomponents, c->nlabels, c->nvariants);
    if (!L) {
        ag_mesh_free(mesh);
        ag_splittree_free(tree);
        return nomem(err);
    }
    memcpy(L->label, c->label, c->ncomponents * sizeof *L->label);
    memcpy(L->variant, c->variant, c->ncomponents * sizeof *L->variant);
    memcpy(L->rot, c->rot, c->ncomponents);
    memcpy(L->vrot, c->vrot, c->ncomponents);
    memcpy(L->variant_label, c->variant_label, c->nvariants * sizeof *L->variant_label);
    if (c->mirror)
        memcpy(L->mirror, c->mirror, c->ncomponents);
    if (c->turn)
        memcpy(L->turn, c->turn, c->ncomponents * sizeof *L->turn);
    else
        for (size_t i = 0; i < c->ncomponents; i++)
            L->turn[i] = c->rot[i] * 1.5707963267948966;
    if (c->variant_deviation)
        memcpy(L->variant_deviation, c->variant_deviation,
               c->nvariants * sizeof *L->variant_deviation);
    L->diagonal = c->diagonal;
    L->tol = c->tol;
    L->exact = c->exact;
    L->share = c->share;
    L->exact_copies = c->exact_copies;
    return finish(mesh, L, tree, 0, NULL, NULL, out, err);
}

/* ---- label names ------------------------------------------------------------------------- */

/* k for a group named "L<k>" (k >= 1), else 0. */
static size_t label_number(const char *name)
{
    if (!name || name[0] != 'L' || name[1] < '1' || name[1] > '9')
        return 0;
    char *end;
    unsigned long k = strtoul(name + 1, &end, 10);
    return *end || k > (1ul << 24) ? 0 : (size_t)k;
}

ag_status ag_rebuild_name_labels(ag_proceduralize_result *r, ag_error *err)
{
    ag_labels *L = r->labels;
    const ag_mesh *m = r->mesh;
    size_t nl = L->nlabels;
    if (!nl)
        return AG_OK;
    size_t *claim = calloc(nl, sizeof *claim);
    uint8_t *mixed = calloc(nl, 1);
    if (!claim || !mixed) {
        free(claim);
        free(mixed);
        return nomem(err);
    }
    /* the group name every component of a label has, if it names a label */
    for (size_t c = 0; c < L->ncomponents && c < m->ncomponents; c++) {
        int32_t l = L->label[c], g = m->component_group[c];
        if (l < 0 || (size_t)l >= nl)
            continue;
        size_t k = g >= 0 && (size_t)g < m->ngroups ? label_number(m->group_names[g]) : 0;
        if (!k || (claim[l] && claim[l] != k))
            mixed[l] = 1;
        else
            claim[l] = k;
    }
    size_t top = 0, moved = 0;
    for (size_t l = 0; l < nl; l++) {
        if (mixed[l])
            claim[l] = 0;
        for (size_t j = 0; j < l && claim[l]; j++) /* a number claimed twice goes to the first */
            if (claim[j] == claim[l])
                claim[l] = 0;
        if (claim[l] > top)
            top = claim[l];
        moved |= claim[l] != l + 1;
    }
    free(mixed);
    if (!moved) {
        free(claim);
        return AG_OK;
    }
    size_t nn = top;
    int32_t *to = malloc(nl * sizeof *to);
    for (size_t l = 0; to && l < nl; l++)
        to[l] = claim[l] ? (int32_t)(claim[l] - 1) : (int32_t)nn++;
    free(claim);
    uint32_t *ex = to ? calloc(nn + 1, sizeof *ex) : NULL, *cnt = ex ? calloc(nn + 1, sizeof *cnt) : NULL;
    if (!cnt) {
        free(to);
        free(ex);
        return nomem(err);
    }
    for (size_t l = 0; l < nl; l++) {
        ex[to[l]] = L->exemplar[l];
        cnt[to[l]] = L->count[l];
    }
    free(L->exemplar);
    free(L->count);
    L->exemplar = ex;
    L->count = cnt;
    L->nlabels = nn;
    for (size_t c = 0; c < L->ncomponents; c++)
        if (L->label[c] >= 0 && (size_t)L->label[c] < nl)
            L->label[c] = to[L->label[c]];
    for (size_t v = 0; v < L->nvariants; v++)
        if (L->variant_label[v] >= 0 && (size_t)L->variant_label[v] < nl)
            L->variant_label[v] = to[L->variant_label[v]];
    ag_splittree *t = r->tree;
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].label >= 0 && (size_t)t->nodes[n].label < nl)
            t->nodes[n].label = to[t->nodes[n].label];
    free(to);
    /* the grammar names its terminals' labels anew */
    ag_grammar_free(r->grammar);
    r->grammar = NULL;
    ag_grammar_export_info_free(&r->info);
    return ag_grammar_export(r->mesh, r->labels, r->tree, &r->grammar, &r->info, err);
}

size_t ag__rebuild_label_number(const char *name)
{
    return label_number(name);
}
