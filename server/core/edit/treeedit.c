/* The edited trees of split, join, paste and remove (treeedit.h). */
#include "treeedit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "place.h"

/* The tree being edited: a copy of the input's, with a source per node. */
typedef struct {
    const ag_splittree *ot; /* the input tree (what copies are made from) */
    ag_splittree *t;
    int32_t *src;
    size_t cap_src;
    ag_status st;
} edited;

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while editing the split tree");
}

static ag_status edited_begin(edited *E, const ag_splittree *ot)
{
    memset(E, 0, sizeof *E);
    E->ot = ot;
    E->t = ag_splittree_copy(ot);
    if (!E->t || AG_ARRAY_RESERVE(E->src, E->cap_src, ot->nnodes + 1)) {
        ag_splittree_free(E->t);
        free(E->src);
        return AG_ERR_NOMEM;
    }
    for (size_t n = 0; n < ot->nnodes; n++)
        E->src[n] = (int32_t)n;
    return AG_OK;
}

static void edited_drop(edited *E)
{
    ag_splittree_free(E->t);
    free(E->src);
    E->t = NULL;
    E->src = NULL;
}

/* What copies are made of when they are not the input's own nodes unturned (a paste turned or
 * from another model): per component of the tree copied from, the view's node that places
 * it, turned, with its view label and variant; NULL for plain copies. */
typedef struct {
    const ag_splittree *from; /* the tree copied from */
    const int32_t *view_node; /* per component of `from` (-1: not copied) */
    const int32_t *view_comp; /* per component of `from`: the view's component */
    const ag_labels *labels;  /* the view's */
    int turns;
} copy_source;

static ag_box map_box(const ag_place_map *m, const ag_box *b)
{
    return ag_place_apply_box(m, b);
}

/* A pattern's lattice moved by m (a turned axis grid whose cells no longer follow its axes is
 * dissolved by the rebuild). */
static void map_pattern(const ag_place_map *m, ag_pattern *p, int turns)
{
    double step[3];
    for (int a = 0; a < 3; a++)
        step[a] = m->M[a][0] * p->step[0] + m->M[a][1] * p->step[1] + m->M[a][2] * p->step[2];
    memcpy(p->step, step, sizeof step);
    for (int k = 0; k < 3; k++) {
        double v[3];
        for (int a = 0; a < 3; a++)
            v[a] = m->M[a][0] * p->vec[k][0] + m->M[a][1] * p->vec[k][1] + m->M[a][2] * p->vec[k][2];
        memcpy(p->vec[k], v, sizeof v);
    }
    if (turns & 1 && !p->nvec) {
        uint32_t c = p->counts[0];
        p->counts[0] = p->counts[1];
        p->counts[1] = c;
    }
    p->rot = (uint8_t)((p->rot + turns) & 3);
}

/* Every box (and pattern lattice) of x's subtree in E's tree mapped by m (no turn). */
static void map_subtree(edited *E, int32_t x, const ag_place_map *m)
{
    ag_splittree *t = E->t;
    int32_t *stack = malloc((t->nnodes + 1) * sizeof *stack);
    if (!stack) {
        E->st = AG_ERR_NOMEM;
        return;
    }
    size_t sp = 0;
    stack[sp++] = x;
    while (sp) {
        int32_t v = stack[--sp];
        ag_tnode *n = &t->nodes[v];
        n->box = map_box(m, &n->box);
        if (n->kind == AG_NODE_PATTERN && n->pattern >= 0 && (size_t)n->pattern < t->npatterns)
            map_pattern(m, &t->patterns[n->pattern], 0);
        for (int32_t c = n->first_child; c >= 0; c = t->nodes[c].next_sibling)
            stack[sp++] = c;
    }
    free(stack);
}

/* A new node copying node y of the tree copied from (the input's, or cs's), its box mapped by m,
 * linked to nothing. */
static int32_t copy_node(edited *E, const copy_source *cs, int32_t y, const ag_place_map *m)
{
    if (E->st)
        return -1;
    const ag_splittree *from = cs ? cs->from : E->ot;
    ag_splittree *t = E->t;
    int32_t c = ag_splittree_add_node(t, AG_NODE_DEAD);
    if (c < 0 || AG_ARRAY_RESERVE(E->src, E->cap_src, (size_t)c + 1)) {
        E->st = AG_ERR_NOMEM;
        return -1;
    }
    ag_tnode *n = &t->nodes[c];
    *n = from->nodes[y];
    n->parent = n->first_child = n->last_child = n->next_sibling = -1;
    n->box = map_box(m, &n->box);
    E->src[c] = y;
    if (cs) {
        /* invisible nodes place nothing: any source will do */
        E->src[c] = 0;
        if (n->kind == AG_NODE_COMPONENT) {
            int32_t vn = n->component >= 0 ? cs->view_node[n->component] : -1;
            if (vn < 0) {
                E->st = AG_ERR_INTERNAL;
                return -1;
            }
            E->src[c] = vn;
            int32_t vc = cs->view_comp[n->component];
            n->label = cs->labels->label[vc];
            n->variant = cs->labels->variant[vc];
            n->rot = (uint8_t)((n->rot + cs->turns) & 3);
        }
    }
    if (n->kind == AG_NODE_PATTERN && n->pattern >= 0 && (size_t)n->pattern < from->npatterns) {
        if (AG_ARRAY_RESERVE(t->patterns, t->cap_patterns, t->npatterns + 1)) {
            E->st = AG_ERR_NOMEM;
            return -1;
        }
        ag_pattern p = from->patterns[n->pattern];
        map_pattern(m, &p, cs ? cs->turns : 0);
        p.node = c;
        t->patterns[t->npatterns] = p;
        t->nodes[c].pattern = (int32_t)t->npatterns++;
    }
    return c;
}

/* A copy of the subtree of y (of the input, or of cs's tree), boxes mapped by m, hung in
 * parent's list after `after` (-1: at the end). Returns the copy of y. */
static int32_t copy_subtree(edited *E, const copy_source *cs, int32_t y, const ag_place_map *m,
                            int32_t parent, int32_t after)
{
    const ag_splittree *from = cs ? cs->from : E->ot;
    int32_t top = copy_node(E, cs, y, m);
    if (top < 0)
        return -1;
    ag_splittree_attach_after(E->t, parent, after, top);
    /* (node copied from, its copy) pairs whose children are still to copy */
    int32_t *stack = malloc(2 * (from->nnodes + 1) * sizeof *stack);
    if (!stack) {
        E->st = AG_ERR_NOMEM;
        return -1;
    }
    size_t sp = 0;
    stack[sp++] = y;
    stack[sp++] = top;
    while (sp && !E->st) {
        int32_t into = stack[--sp], at = stack[--sp];
        for (int32_t k = from->nodes[at].first_child; k >= 0 && !E->st;
             k = from->nodes[k].next_sibling) {
            int32_t c = copy_node(E, cs, k, m);
            if (c < 0)
                break;
            ag_splittree_attach(E->t, into, c);
            stack[sp++] = k;
            stack[sp++] = c;
        }
    }
    free(stack);
    return E->st ? -1 : top;
}

void ag_treeedit_kill_subtree(ag_splittree *t, int32_t x, int32_t *stack)
{
    int32_t p = t->nodes[x].parent;
    if (p >= 0 && t->nodes[p].kind == AG_NODE_SPLIT)
        x = p;
    ag_splittree_detach(t, x);
    size_t sp = 0;
    stack[sp++] = x;
    while (sp) {
        int32_t v = stack[--sp];
        for (int32_t c = t->nodes[v].first_child; c >= 0; c = t->nodes[c].next_sibling)
            stack[sp++] = c;
        ag_tnode *n = &t->nodes[v];
        n->kind = AG_NODE_DEAD;
        n->parent = n->first_child = n->last_child = n->next_sibling = -1;
    }
}

static void kill_subtree(edited *E, int32_t x)
{
    int32_t *stack = malloc((E->t->nnodes + 1) * sizeof *stack);
    if (!stack) {
        E->st = AG_ERR_NOMEM;
        return;
    }
    ag_treeedit_kill_subtree(E->t, x, stack);
    free(stack);
}

/* Takes x (a chain end) out of the split chain it hangs by: the chain's intermediate node is
 * dead. */
static void unhang(edited *E, int32_t x)
{
    ag_splittree *t = E->t;
    int32_t p = t->nodes[x].parent;
    ag_splittree_detach(t, x);
    if (p >= 0 && t->nodes[p].kind == AG_NODE_SPLIT) {
        ag_splittree_detach(t, p);
        ag_tnode *n = &t->nodes[p];
        n->kind = AG_NODE_DEAD;
        n->parent = n->first_child = n->last_child = n->next_sibling = -1;
    }
}

/* The node whose child list holds x's split chain, and the chain's head in it (*slot). */
static int32_t chain_parent(const ag_splittree *t, int32_t x, int32_t *slot)
{
    int32_t p = t->nodes[x].parent;
    *slot = x;
    if (p >= 0 && t->nodes[p].kind == AG_NODE_SPLIT) {
        *slot = p;
        p = t->nodes[p].parent;
    }
    return p;
}

/* The nearest node at or above x that holds components as children (visible, or the root). */
static int32_t holder_at_or_above(const ag_splittree *t, int32_t x)
{
    while (x > 0 && t->nodes[x].kind != AG_NODE_COMPONENT && t->nodes[x].kind != AG_NODE_ROOT)
        x = t->nodes[x].parent;
    return x < 0 ? 0 : x;
}

ag_status ag_treeedit_span_invisible(ag_splittree *t)
{
    size_t nn = t->nnodes;
    int32_t *stack = malloc((nn + 1) * sizeof *stack), *order = malloc((nn + 1) * sizeof *order);
    if (!stack || !order) {
        free(stack);
        free(order);
        return AG_ERR_NOMEM;
    }
    size_t sp = 0, no = 0;
    stack[sp++] = 0;
    while (sp && no < nn) {
        int32_t v = stack[--sp];
        order[no++] = v;
        for (int32_t c = t->nodes[v].first_child; c >= 0; c = t->nodes[c].next_sibling)
            stack[sp++] = c;
    }
    for (size_t i = no; i-- > 0;) {
        ag_tnode *x = &t->nodes[order[i]];
        if (x->kind == AG_NODE_COMPONENT || x->first_child < 0)
            continue;
        ag_box u = ag_box_empty();
        for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling)
            ag_box_extend_box(&u, &t->nodes[c].box);
        if (!ag_box_is_empty(&u))
            x->box = u;
    }
    free(stack);
    free(order);
    return AG_OK;
}

static ag_status edited_finish(edited *E, ag_splittree **tree, int32_t **source, ag_error *err)
{
    if (!E->st && ag_treeedit_span_invisible(E->t))
        E->st = AG_ERR_NOMEM;
    if (E->st) {
        ag_status st = E->st;
        edited_drop(E);
        return st == AG_ERR_NOMEM ? nomem(err)
                                  : ag_error_set(err, st, 0, "the edited split tree is inconsistent");
    }
    *tree = E->t;
    *source = E->src;
    return AG_OK;
}

void ag_treeedit_base_free(ag_treeedit_base *b)
{
    if (!b)
        return;
    if (b->owns) {
        free(b->labels.label);
        free(b->labels.rot);
        free(b->labels.variant);
        free(b->labels.vrot);
        free(b->labels.mirror);
        free(b->labels.turn);
        free(b->labels.tri_start);
        free(b->labels.tris);
        free(b->labels.variant_label);
        free(b->labels.variant_deviation);
        free(b->tree.nodes);
    }
    if (b->owns_mesh) {
        free(b->mesh.pos);
        free(b->mesh.tri);
    }
    memset(b, 0, sizeof *b);
}

static void base_of(ag_treeedit_base *b, const ag_proceduralize_result *in)
{
    memset(b, 0, sizeof *b);
    b->view = *in;
}

/* ---- split -------------------------------------------------------------------------------- */

ag_status ag_treeedit_split(const ag_proceduralize_result *in, const ag_edit_op *op,
                            ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                            ag_edit_report *rep, ag_error *err)
{
    *tree = NULL;
    *source = NULL;
    base_of(base, in);
    size_t n;
    ag_status st = ag_place_check_split(in, op, &n, err);
    if (st)
        return st;
    const ag_splittree *ot = in->tree;
    const ag_box B = ot->nodes[op->node].box;
    int a = op->axis;
    ag_box half[2] = {B, B};
    half[0].max[a] = op->at;
    half[1].min[a] = op->at;
    ag_place_map lo, hi;
    ag_place_boxes(&lo, &B, &half[0], 0);
    ag_place_boxes(&hi, &B, &half[1], 0);
    edited E;
    if (edited_begin(&E, ot))
        return nomem(err);
    if (op->node == AG_EDIT_ROOT) {
        /* the root stays one: each of its subtrees is halved */
        for (int32_t c = ot->nodes[0].first_child; c >= 0 && !E.st;
             c = ot->nodes[c].next_sibling) {
            copy_subtree(&E, NULL, c, &hi, 0, -1);
            if (!E.st)
                map_subtree(&E, c, &lo);
        }
    } else {
        int32_t slot, p = chain_parent(E.t, op->node, &slot);
        copy_subtree(&E, NULL, op->node, &hi, p, slot);
        if (!E.st)
            map_subtree(&E, op->node, &lo);
    }
    if ((st = edited_finish(&E, tree, source, err)))
        return st;
    if (rep) {
        rep->splits++;
        snprintf(rep->message, sizeof rep->message,
                 "split node %d at %c = %g: %zu components duplicated into both halves (node %d "
                 "keeps the lower half)",
                 (int)op->node, "xyz"[a], op->at, n, (int)op->node);
    }
    return AG_OK;
}

/* ---- remove ------------------------------------------------------------------------------- */

/* Triangles the visible nodes of t place (their sources' components in base). */
static size_t placed_triangles(const ag_proceduralize_result *base, const ag_splittree *t,
                               const int32_t *source)
{
    const ag_labels *L = base->labels;
    size_t n = 0;
    for (size_t v = 0; v < t->nnodes; v++) {
        if (t->nodes[v].kind != AG_NODE_COMPONENT)
            continue;
        int32_t c = base->tree->nodes[source[v]].component;
        if (c >= 0 && (size_t)c < L->ncomponents)
            n += L->tri_start[c + 1] - L->tri_start[c];
    }
    return n;
}

ag_status ag_treeedit_remove(const ag_proceduralize_result *in, const ag_edit_op *op,
                             ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                             ag_edit_report *rep, ag_error *err)
{
    *tree = NULL;
    *source = NULL;
    base_of(base, in);
    ag_status st = ag_place_check_selection(in, op, "remove", "at least one node", "removed", err);
    if (st)
        return st;
    const ag_splittree *ot = in->tree;
    uint8_t *mark = calloc(ot->ncomponents + 1, 1);
    if (!mark)
        return nomem(err);
    size_t n = 0;
    for (size_t i = 0; i < op->nnodes; i++)
        n += ag_place_mark_subtree(ot, op->nodes[i], mark);
    free(mark);
    edited E;
    if (edited_begin(&E, ot))
        return nomem(err);
    /* a node below another selected one is already gone with it */
    for (size_t i = 0; i < op->nnodes && !E.st; i++)
        if (E.t->nodes[op->nodes[i]].kind != AG_NODE_DEAD)
            kill_subtree(&E, op->nodes[i]);
    if (!E.st && placed_triangles(in, E.t, E.src) == 0) {
        edited_drop(&E);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "removing the selection would leave no geometry");
    }
    st = edited_finish(&E, tree, source, err);
    if (!st && rep)
        snprintf(rep->message, sizeof rep->message, "removed %zu components", n);
    return st;
}

/* ---- paste -------------------------------------------------------------------------------- */

/* Is a an ancestor of b (a != b)? */
static int above(const ag_splittree *t, int32_t a, int32_t b)
{
    for (int32_t x = t->nodes[b].parent; x >= 0; x = t->nodes[x].parent)
        if (x == a)
            return 1;
    return 0;
}

/* The view of in with the marked components of src appended, each turned by k quarter turns
 * in place (about its box's centre), held by one more node each: view_node and view_comp (per
 * component of src) get them. Another model's labels and variants become new ones. */
static ag_status base_paste(ag_treeedit_base *b, const ag_proceduralize_result *in,
                            const ag_proceduralize_result *src, const uint8_t *smark, int k,
                            int32_t *view_node, int32_t *view_comp)
{
    const ag_labels *IL = in->labels, *SL = src->labels;
    const ag_splittree *it = in->tree, *st = src->tree;
    const ag_mesh *im = in->mesh, *sm = src->mesh;
    int cross = src != in;
    size_t nc = IL->ncomponents, nl = IL->nlabels, nv = IL->nvariants;
    size_t extra = 0, xtris = 0;
    for (size_t c = 0; c < st->ncomponents && c < SL->ncomponents; c++)
        if (smark[c] && st->comp_node[c] >= 0) {
            extra++;
            xtris += SL->tri_start[c + 1] - SL->tri_start[c];
        }
    int32_t *lmap = malloc((SL->nlabels + 1) * sizeof *lmap);
    int32_t *vmap = malloc((SL->nvariants + 1) * sizeof *vmap);
    uint32_t *vtx = malloc((sm->nverts + 1) * sizeof *vtx);
    uint32_t *stamp = calloc(sm->nverts + 1, sizeof *stamp);
    ag_labels *L = &b->labels;
    *L = *IL;
    b->tree = *it;
    b->mesh = *im;
    b->owns = b->owns_mesh = 1;
    size_t nall = nc + extra, ntris = IL->tri_start[nc];
    L->label = malloc((nall + 1) * sizeof *L->label);
    L->variant = malloc((nall + 1) * sizeof *L->variant);
    L->rot = malloc(nall + 1);
    L->vrot = malloc(nall + 1);
    L->mirror = calloc(nall + 1, 1);
    L->turn = calloc(nall + 1, sizeof *L->turn);
    L->tri_start = malloc((nall + 1) * sizeof *L->tri_start);
    L->tris = malloc((ntris + xtris + 1) * sizeof *L->tris);
    L->variant_label = malloc((nv + SL->nvariants + 1) * sizeof *L->variant_label);
    L->variant_deviation = calloc(nv + SL->nvariants + 1, sizeof *L->variant_deviation);
    b->tree.nodes = malloc((it->nnodes + extra + 1) * sizeof *b->tree.nodes);
    b->mesh.pos = malloc(3 * (im->nverts + 3 * xtris + 1) * sizeof *b->mesh.pos);
    b->mesh.tri = malloc(3 * (im->ntris + xtris + 1) * sizeof *b->mesh.tri);
    ag_status status = AG_OK;
    if (!lmap || !vmap || !vtx || !stamp || !L->label || !L->variant || !L->rot || !L->vrot ||
        !L->mirror || !L->turn || !L->tri_start || !L->tris || !L->variant_label ||
        !L->variant_deviation || !b->tree.nodes || !b->mesh.pos || !b->mesh.tri) {
        status = AG_ERR_NOMEM;
        goto done;
    }
    memcpy(L->label, IL->label, nc * sizeof *L->label);
    memcpy(L->variant, IL->variant, nc * sizeof *L->variant);
    memcpy(L->rot, IL->rot, nc);
    memcpy(L->vrot, IL->vrot, nc);
    if (IL->mirror)
        memcpy(L->mirror, IL->mirror, nc);
    if (IL->turn)
        memcpy(L->turn, IL->turn, nc * sizeof *L->turn);
    memcpy(L->tri_start, IL->tri_start, (nc + 1) * sizeof *L->tri_start);
    memcpy(L->tris, IL->tris, ntris * sizeof *L->tris);
    memcpy(L->variant_label, IL->variant_label, nv * sizeof *L->variant_label);
    if (IL->variant_deviation)
        memcpy(L->variant_deviation, IL->variant_deviation, nv * sizeof *L->variant_deviation);
    memcpy(b->tree.nodes, it->nodes, it->nnodes * sizeof *b->tree.nodes);
    memcpy(b->mesh.pos, im->pos, 3 * im->nverts * sizeof *b->mesh.pos);
    memcpy(b->mesh.tri, im->tri, 3 * im->ntris * sizeof *b->mesh.tri);
    /* another model's labels and variants: new numbers after this model's */
    size_t nl2 = nl, nv2 = nv;
    for (size_t l = 0; l < SL->nlabels; l++)
        lmap[l] = cross ? -1 : (int32_t)l;
    for (size_t v = 0; v < SL->nvariants; v++)
        vmap[v] = cross ? -1 : (int32_t)v;
    size_t nvtx = im->nverts, ntri = im->ntris, ti = ntris, e = 0;
    for (size_t c = 0; c < st->ncomponents && c < SL->ncomponents; c++) {
        if (!smark[c] || st->comp_node[c] < 0)
            continue;
        int32_t l = SL->label[c], v = SL->variant[c];
        if (l >= 0 && lmap[l] < 0)
            lmap[l] = (int32_t)nl2++;
        if (v >= 0 && vmap[v] < 0) {
            vmap[v] = (int32_t)nv2++;
            int32_t vl = SL->variant_label[v];
            L->variant_label[vmap[v]] = vl >= 0 && lmap[vl] >= 0 ? lmap[vl] : lmap[l];
            L->variant_deviation[vmap[v]] = SL->variant_deviation ? SL->variant_deviation[v] : 0;
        }
        const ag_tnode *sn = &st->nodes[st->comp_node[c]];
        ag_box turned = sn->box;
        if (k & 1) {
            double cx = ag_box_centre_axis(&sn->box, 0), cy = ag_box_centre_axis(&sn->box, 1);
            double hx = 0.5 * ag_box_extent(&sn->box, 1), hy = 0.5 * ag_box_extent(&sn->box, 0);
            turned.min[0] = cx - hx;
            turned.max[0] = cx + hx;
            turned.min[1] = cy - hy;
            turned.max[1] = cy + hy;
        }
        ag_place_map R;
        ag_place_boxes(&R, &sn->box, &turned, k);
        size_t comp = nc + e;
        uint32_t emission = (uint32_t)e + 1;
        L->tri_start[comp] = (uint32_t)ti;
        for (uint32_t q = SL->tri_start[c]; q < SL->tri_start[c + 1]; q++) {
            uint32_t tr = SL->tris[q];
            for (int j = 0; j < 3; j++) {
                uint32_t sv = sm->tri[3 * (size_t)tr + j];
                if (stamp[sv] != emission) {
                    stamp[sv] = emission;
                    vtx[sv] = (uint32_t)nvtx;
                    ag_place_apply(&R, &sm->pos[3 * (size_t)sv], &b->mesh.pos[3 * nvtx]);
                    nvtx++;
                }
                b->mesh.tri[3 * ntri + j] = vtx[sv];
            }
            L->tris[ti++] = (uint32_t)ntri++;
        }
        L->label[comp] = l >= 0 ? lmap[l] : -1;
        L->variant[comp] = v >= 0 ? vmap[v] : -1;
        L->rot[comp] = (uint8_t)((SL->rot[c] + k) & 3);
        L->vrot[comp] = (uint8_t)((SL->vrot[c] + k) & 3);
        L->mirror[comp] = SL->mirror ? SL->mirror[c] : 0;
        L->turn[comp] = (SL->turn ? SL->turn[c] : SL->rot[c] * 1.5707963267948966) +
                        k * 1.5707963267948966;
        int32_t vn = (int32_t)(it->nnodes + e);
        ag_tnode *x = &b->tree.nodes[vn];
        *x = *sn;
        x->box = turned;
        x->parent = x->first_child = x->last_child = x->next_sibling = -1;
        x->component = (int32_t)comp;
        x->label = L->label[comp];
        x->variant = L->variant[comp];
        x->rot = (uint8_t)((sn->rot + k) & 3);
        x->rule = x->pattern = -1;
        view_node[c] = vn;
        view_comp[c] = (int32_t)comp;
        e++;
    }
    L->tri_start[nall] = (uint32_t)ti;
    L->ncomponents = nall;
    L->nlabels = nl2;
    L->nvariants = nv2;
    b->tree.nnodes = b->tree.cap = it->nnodes + extra;
    b->mesh.nverts = nvtx;
    b->mesh.ntris = ntri;
    b->view.labels = L;
    b->view.tree = &b->tree;
    b->view.mesh = &b->mesh;
done:
    free(lmap);
    free(vmap);
    free(vtx);
    free(stamp);
    return status;
}

ag_status ag_treeedit_paste(const ag_proceduralize_result *in, const ag_edit_op *op,
                            ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                            ag_edit_report *rep, ag_error *err)
{
    *tree = NULL;
    *source = NULL;
    base_of(base, in);
    const ag_proceduralize_result *src = op->source ? op->source : in;
    const ag_splittree *ot = in->tree, *ts = src->tree;
    uint8_t *smark = calloc(ts->ncomponents + 1, 1);
    if (!smark)
        return nomem(err);
    ag_place_paste_plan pl;
    ag_status st = ag_place_paste_plan_make(in, op, smark, &pl, err);
    if (st) {
        free(smark);
        return st;
    }
    /* copies of the input's own nodes unturned are plain copies; the others place the view's
     * components */
    copy_source cs = {.from = ts, .turns = pl.turns}, *csp = NULL;
    int32_t *view_node = NULL, *view_comp = NULL;
    if (src != in || pl.turns) {
        view_node = malloc((ts->ncomponents + 1) * sizeof *view_node);
        view_comp = malloc((ts->ncomponents + 1) * sizeof *view_comp);
        for (size_t c = 0; view_node && view_comp && c < ts->ncomponents; c++)
            view_node[c] = view_comp[c] = -1;
        if (!view_node || !view_comp ||
            base_paste(base, in, src, smark, pl.turns, view_node, view_comp)) {
            free(smark);
            free(view_node);
            free(view_comp);
            ag_treeedit_base_free(base);
            base_of(base, in);
            return nomem(err);
        }
        cs.view_node = view_node;
        cs.view_comp = view_comp;
        cs.labels = &base->labels;
        csp = &cs;
    }
    free(smark);
    edited E;
    if (edited_begin(&E, ot)) {
        free(view_node);
        free(view_comp);
        return nomem(err);
    }
    int32_t d = op->node, holder;
    if (op->placement == AG_EDIT_REPLACE && d != AG_EDIT_ROOT) {
        holder = holder_at_or_above(E.t, E.t->nodes[d].parent);
        kill_subtree(&E, d);
    } else if (op->placement == AG_EDIT_REPLACE) {
        holder = 0;
        while (E.t->nodes[0].first_child >= 0 && !E.st)
            kill_subtree(&E, E.t->nodes[0].first_child);
    } else {
        holder = ag_splittree_chain_end(E.t, d);
        holder = holder_at_or_above(E.t, holder >= 0 ? holder : d);
    }
    for (size_t z = 0; z < pl.counts[2] && !E.st; z++)
        for (size_t y = 0; y < pl.counts[1] && !E.st; y++)
            for (size_t x = 0; x < pl.counts[0] && !E.st; x++) {
                ag_box cell = ag_place_paste_cell(&pl, (unsigned)x, (unsigned)y, (unsigned)z);
                ag_place_map m;
                ag_place_boxes(&m, &pl.source_box, &cell, pl.turns);
                for (size_t i = 0; i < op->nnodes && !E.st; i++) {
                    int32_t s = op->nodes[i], dup = 0;
                    for (size_t j = 0; j < op->nnodes && !dup; j++)
                        dup = j != i && (op->nodes[j] == s ? j < i : above(ts, op->nodes[j], s));
                    if (dup)
                        continue;
                    if (s == AG_EDIT_ROOT) /* the whole model: what the root holds */
                        for (int32_t c = ts->nodes[0].first_child; c >= 0 && !E.st;
                             c = ts->nodes[c].next_sibling)
                            copy_subtree(&E, csp, c, &m, holder, -1);
                    else
                        copy_subtree(&E, csp, s, &m, holder, -1);
                }
            }
    free(view_node);
    free(view_comp);
    if ((st = edited_finish(&E, tree, source, err))) {
        ag_treeedit_base_free(base);
        base_of(base, in);
        return st;
    }
    if (rep)
        ag_place_paste_message(rep, &pl, op);
    return AG_OK;
}

/* ---- join --------------------------------------------------------------------------------- */

/* Adds the visible nodes at or directly below v (through invisible nodes only) to list. */
static void top_visible(const ag_splittree *t, int32_t v, uint8_t *seen, int32_t *list,
                        size_t *n)
{
    const ag_tnode *x = &t->nodes[v];
    if (x->kind == AG_NODE_COMPONENT) {
        if (x->component >= 0 && !seen[v]) {
            seen[v] = 1;
            list[(*n)++] = v;
        }
        return;
    }
    for (int32_t s = x->first_child; s >= 0; s = t->nodes[s].next_sibling)
        top_visible(t, s, seen, list, n);
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return x < y ? -1 : x > y;
}

/* The view of in with one more component (the members' triangles together, a label and a
 * variant of its own) held by one more node (box u): returns that node's index. */
static int32_t base_join(ag_treeedit_base *b, const ag_proceduralize_result *in,
                         const int32_t *members, size_t nm, const ag_box *u)
{
    const ag_labels *OL = in->labels;
    const ag_splittree *ot = in->tree;
    size_t nc = OL->ncomponents, nl = OL->nlabels, nv = OL->nvariants;
    size_t ntris = OL->tri_start[nc], extra = 0;
    for (size_t i = 0; i < nm; i++) {
        int32_t c = ot->nodes[members[i]].component;
        extra += OL->tri_start[c + 1] - OL->tri_start[c];
    }
    ag_labels *L = &b->labels;
    *L = *OL;
    b->tree = *ot;
    b->owns = 1;
    L->label = malloc((nc + 1) * sizeof *L->label);
    L->variant = malloc((nc + 1) * sizeof *L->variant);
    L->rot = malloc(nc + 1);
    L->vrot = malloc(nc + 1);
    L->mirror = calloc(nc + 1, 1);
    L->turn = calloc(nc + 1, sizeof *L->turn);
    L->tri_start = malloc((nc + 2) * sizeof *L->tri_start);
    L->tris = malloc((ntris + extra + 1) * sizeof *L->tris);
    L->variant_label = malloc((nv + 1) * sizeof *L->variant_label);
    L->variant_deviation = calloc(nv + 1, sizeof *L->variant_deviation);
    b->tree.nodes = malloc((ot->nnodes + 1) * sizeof *b->tree.nodes);
    if (!L->label || !L->variant || !L->rot || !L->vrot || !L->mirror || !L->turn ||
        !L->tri_start || !L->tris || !L->variant_label || !L->variant_deviation ||
        !b->tree.nodes)
        return -1;
    memcpy(L->label, OL->label, nc * sizeof *L->label);
    memcpy(L->variant, OL->variant, nc * sizeof *L->variant);
    memcpy(L->rot, OL->rot, nc);
    memcpy(L->vrot, OL->vrot, nc);
    if (OL->mirror)
        memcpy(L->mirror, OL->mirror, nc);
    if (OL->turn)
        memcpy(L->turn, OL->turn, nc * sizeof *L->turn);
    memcpy(L->tri_start, OL->tri_start, (nc + 1) * sizeof *L->tri_start);
    memcpy(L->tris, OL->tris, ntris * sizeof *L->tris);
    memcpy(L->variant_label, OL->variant_label, nv * sizeof *L->variant_label);
    if (OL->variant_deviation)
        memcpy(L->variant_deviation, OL->variant_deviation, nv * sizeof *L->variant_deviation);
    size_t k = ntris;
    for (size_t i = 0; i < nm; i++) {
        int32_t c = ot->nodes[members[i]].component;
        for (uint32_t s = OL->tri_start[c]; s < OL->tri_start[c + 1]; s++)
            L->tris[k++] = OL->tris[s];
    }
    L->tri_start[nc + 1] = (uint32_t)k;
    L->label[nc] = (int32_t)nl;
    L->variant[nc] = (int32_t)nv;
    L->rot[nc] = L->vrot[nc] = 0;
    L->variant_label[nv] = (int32_t)nl;
    L->ncomponents = nc + 1;
    L->nlabels = nl + 1;
    L->nvariants = nv + 1;
    memcpy(b->tree.nodes, ot->nodes, ot->nnodes * sizeof *b->tree.nodes);
    int32_t j = (int32_t)ot->nnodes;
    ag_tnode *x = &b->tree.nodes[j];
    memset(x, 0, sizeof *x);
    x->box = *u;
    x->parent = x->first_child = x->last_child = x->next_sibling = -1;
    x->component = (int32_t)nc;
    x->label = (int32_t)nl;
    x->variant = (int32_t)nv;
    x->kind = AG_NODE_COMPONENT;
    x->rule = x->pattern = -1;
    b->tree.nnodes = ot->nnodes + 1;
    b->tree.cap = b->tree.nnodes;
    b->view.labels = L;
    b->view.tree = &b->tree;
    return j;
}

ag_status ag_treeedit_join(const ag_proceduralize_result *in, const ag_edit_op *op,
                           ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                           ag_edit_report *rep, ag_error *err)
{
    *tree = NULL;
    *source = NULL;
    base_of(base, in);
    ag_status st = ag_place_check_selection(in, op, "join", "a selection of at least two nodes",
                                            "joined", err);
    if (st)
        return st;
    const ag_splittree *ot = in->tree;
    uint8_t *seen = calloc(ot->nnodes + 1, 1);
    int32_t *members = malloc((ot->nnodes + 1) * sizeof *members);
    if (!seen || !members) {
        free(seen);
        free(members);
        return nomem(err);
    }
    size_t nm = 0;
    for (size_t i = 0; i < op->nnodes; i++)
        top_visible(ot, op->nodes[i], seen, members, &nm);
    if (nm < 2) {
        free(seen);
        free(members);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "join needs at least two distinct visible nodes; the selection of "
                            "%zu node(s) names %zu",
                            op->nnodes, nm);
    }
    /* the joined geometry in component order, as the mesh of a join holds it */
    /* the kept node is the one nearest the root (then the smallest id), so no other member
     * lies above it */
    qsort(members, nm, sizeof *members, cmp_i32);
    size_t best = 0, best_depth = SIZE_MAX;
    for (size_t i = 0; i < nm; i++) {
        size_t depth = 0;
        for (int32_t x = ot->nodes[members[i]].parent; x >= 0; x = ot->nodes[x].parent)
            depth++;
        if (depth < best_depth) {
            best_depth = depth;
            best = i;
        }
    }
    int32_t keep = members[best];
    members[best] = members[0];
    members[0] = keep;
    ag_box u = ag_box_empty();
    for (size_t i = 0; i < nm; i++)
        ag_box_extend_box(&u, &ot->nodes[members[i]].box);
    int32_t *bycomp = malloc((nm + 1) * sizeof *bycomp);
    if (!bycomp) {
        free(seen);
        free(members);
        return nomem(err);
    }
    for (size_t i = 0; i < nm; i++)
        bycomp[i] = ot->nodes[members[i]].component;
    qsort(bycomp, nm, sizeof *bycomp, cmp_i32);
    for (size_t i = 0; i < nm; i++)
        bycomp[i] = ot->comp_node[bycomp[i]];
    int32_t joined = base_join(base, in, bycomp, nm, &u);
    free(bycomp);
    edited E;
    if (joined < 0 || edited_begin(&E, ot)) {
        free(seen);
        free(members);
        ag_treeedit_base_free(base);
        base_of(base, in);
        return nomem(err);
    }
    /* where it hangs: the nearest ancestor of the kept node that is no member, holds
     * components and holds the union */
    double eps = ot->eps > 0 ? ot->eps : AG_EDIT_COINCIDENT;
    int32_t P = E.t->nodes[keep].parent;
    for (; P > 0; P = E.t->nodes[P].parent) {
        const ag_tnode *x = &E.t->nodes[P];
        if (x->kind != AG_NODE_COMPONENT || seen[P])
            continue;
        int holds = 1;
        for (int a = 0; a < 3 && holds; a++)
            holds = x->box.min[a] <= u.min[a] + eps && x->box.max[a] >= u.max[a] - eps;
        if (holds)
            break;
    }
    if (P < 0)
        P = 0;
    /* the kept node leaves its chain; the other members' children hang under it; the
     * members go */
    unhang(&E, keep);
    for (size_t i = 1; i < nm && !E.st; i++) {
        int32_t c = E.t->nodes[members[i]].first_child;
        while (c >= 0) {
            int32_t next = E.t->nodes[c].next_sibling;
            int32_t end = ag_splittree_chain_end(E.t, c);
            if (end >= 0) {
                unhang(&E, end);
                ag_splittree_attach(E.t, keep, end);
            }
            c = next;
        }
    }
    for (size_t i = 1; i < nm && !E.st; i++)
        kill_subtree(&E, members[i]);
    ag_splittree_attach(E.t, P, keep);
    ag_tnode *k = &E.t->nodes[keep];
    k->box = u;
    k->label = base->labels.label[ot->ncomponents];
    k->variant = base->labels.variant[ot->ncomponents];
    k->rot = 0;
    k->rule = -1;
    k->rule_rot = 0;
    E.src[keep] = joined;
    free(seen);
    free(members);
    /* the sources index the view, whose first nodes are the input's */
    st = edited_finish(&E, tree, source, err);
    if (st) {
        ag_treeedit_base_free(base);
        base_of(base, in);
        return st;
    }
    if (rep) {
        rep->joins++;
        snprintf(rep->message, sizeof rep->message,
                 "joined %zu nodes into node %d (label L%zu)", nm, (int)keep,
                 base->labels.nlabels);
    }
    return AG_OK;
}
