/* Emission of a resized model: every visible node's component mapped affinely from its old box
 * to its new one, walking the tree from the root. On the way:
 *
 *   emit_node        a visible node stretched past AG_EDIT_SPLIT_RATIO on an axis becomes two
 *                    copies of its subtree, each half as long (recursively)
 *   emit_pattern     a grid pattern whose cells pass the split ratio or fall under
 *                    AG_EDIT_JOIN_RATIO doubles or halves its count on that axis
 *                    (pattern_layout), keeping each cell's share of its period
 *   join_siblings    plain siblings of one rule squeezed under AG_EDIT_JOIN_RATIO join with
 *                    their nearest same-rule sibling along that axis
 *   emit_component   the triangles of one node under one map, grouped by label
 *
 * A subtree below a node with a map of its own (a copy, a cell, a joined group) follows that
 * map; otherwise every node takes its solved box. The op may set another split ratio (point
 * clouds split past 1.5, see ag_edit_op.split_ratio); the join ratio is its inverse. */
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../base/tolerance.h"
#include "resize_internal.h"

/* Work limits: a pattern count doubles at most up to this; the count search stops after this
 * many halvings or doublings; emission recurses at most this deep (copies of copies); a huge
 * stretch splits exponentially, so the result's components are bounded by the tree's size. */
#define PATTERN_MAX_COUNT (1u << 20)
#define PATTERN_MAX_STEPS 40
#define EMIT_MAX_DEPTH (4 * AG_SPLITTREE_MAX_NESTING + 64)
#define EMIT_MAX_COMPONENTS(nnodes) (64 * ((nnodes) + 16) + (1u << 20))

typedef struct {
    const ag_proceduralize_result *in;
    const ag_box *boxes;
    ag_mesh *out;
    int32_t *group_of_label;
    uint32_t *vmap;  /* per input vertex: output index, valid when stamp matches */
    uint32_t *stamp;
    uint32_t emission;
    size_t splits, joins;
    size_t max_components, max_triangles;
    /* a first pass only counts what would be placed, so a result past the limits is refused
     * before any of it is made */
    int count_only;
    size_t ncomponents, ntris;
    const ag_edit_budget *budget;
    unsigned since_poll;
    double split, join; /* the split ratio and its inverse */
    double thin_share;  /* axes thinner than this share of a node's largest are not split */
    ag_status st;
    ag_error *err;
} emitter;

/* Components placed between two polls of the budget's callback. */
#define EMIT_POLL 1024

static void emit_node(emitter *E, int32_t n, const ag__resize_map *g, int depth);

/* The output group of a label ("L<n>"), made on first use; -1 for no label. */
static int32_t group_of(emitter *E, int32_t lab)
{
    const ag_labels *L = E->in->labels;
    if (lab < 0 || (size_t)lab >= L->nlabels)
        return -1;
    if (E->group_of_label[lab] < 0) {
        char name[32];
        snprintf(name, sizeof name, "L%d", lab + 1);
        size_t ix;
        if ((E->st = ag_mesh_add_group(E->out, name, &ix)))
            return -1;
        E->group_of_label[lab] = (int32_t)ix;
    }
    return E->group_of_label[lab];
}

static void emit_component(emitter *E, int32_t n, const ag__resize_map *m)
{
    const ag_tnode *x = &E->in->tree->nodes[n];
    const ag_labels *L = E->in->labels;
    const ag_mesh *src = E->in->mesh;
    if (x->component < 0 || (size_t)x->component >= L->ncomponents)
        return;
    size_t tris = L->tri_start[x->component + 1] - L->tri_start[x->component];
    if (E->ncomponents >= E->max_components) {
        E->st = ag_error_set(E->err, AG_ERR_RESULT_TOO_LARGE, 0,
                             "resize: the result would place more than %zu terminals, the "
                             "most this server takes",
                             E->max_components);
        return;
    }
    if (E->ntris + tris > E->max_triangles) {
        E->st = ag_error_set(E->err, AG_ERR_RESULT_TOO_LARGE, 0,
                             "resize: the result would have more than %zu triangles, the most "
                             "this server takes",
                             E->max_triangles);
        return;
    }
    if (++E->since_poll >= EMIT_POLL) {
        E->since_poll = 0;
        if (ag_edit_budget_cancelled(E->budget)) {
            E->st = ag_error_set(E->err, AG_ERR_CANCELLED, 0, "resize: stopped");
            return;
        }
    }
    E->ncomponents++;
    E->ntris += tris;
    if (E->count_only)
        return;
    int32_t gi = group_of(E, x->label >= 0 ? x->label : L->label[x->component]);
    if (E->st)
        return;
    size_t comp;
    if ((E->st = ag_mesh_add_component(E->out, gi, &comp)))
        return;
    E->emission++;
    for (uint32_t k = L->tri_start[x->component]; k < L->tri_start[x->component + 1]; k++) {
        uint32_t tr = L->tris[k], v[3];
        for (int j = 0; j < 3; j++) {
            uint32_t sv = src->tri[3 * tr + j];
            assert(sv < src->nverts);
            if (E->stamp[sv] != E->emission) {
                const double *p = &src->pos[3 * sv];
                E->stamp[sv] = E->emission;
                E->vmap[sv] = (uint32_t)E->out->nverts;
                if ((E->st = ag_mesh_add_vertex(E->out, m->s[0] * p[0] + m->t[0],
                                                m->s[1] * p[1] + m->t[1],
                                                m->s[2] * p[2] + m->t[2])))
                    return;
            }
            v[j] = E->vmap[sv];
        }
        if ((E->st = ag_mesh_add_triangle(E->out, v[0], v[1], v[2], (uint32_t)comp)))
            return;
    }
}

/* New box of node c: through the override map when one is given, else its solved box. */
static ag_box new_box(emitter *E, int32_t c, const ag__resize_map *g)
{
    return g ? ag__resize_map_box(g, &E->in->tree->nodes[c].box) : E->boxes[c];
}

/* ---- joins of squeezed siblings ---------------------------------------------------------- */

/* A child slot of a node and the group it joins (join_siblings). */
typedef struct {
    int32_t slot, end; /* the child and the node its split chain ends in */
    int32_t leader;    /* index of the group's first member; -1: takes no part */
    size_t members;    /* at the leader: how many */
    int stuck;         /* at the leader: squeezed but no neighbour to join */
    double w[3];       /* at the leader: the group's new size per axis */
    ag_box box;        /* at the leader: the group's new box */
} sibling;

/* The most squeezed group that may still join (index, axis), or m when none is squeezed. */
static size_t most_squeezed(const ag_splittree *t, const sibling *s, size_t m, double join,
                            int *axis)
{
    size_t best = m;
    double worst = join;
    for (size_t i = 0; i < m; i++) {
        if (s[i].leader != (int32_t)i || s[i].stuck)
            continue;
        const ag_box *ob = &t->nodes[s[i].end].box;
        for (int a = 0; a < 3; a++) {
            double ow = ag_box_extent(ob, a);
            if (ow <= AG_EDIT_FLAT)
                continue;
            double r = s[i].w[a] / ow;
            if (r < worst) {
                worst = r;
                best = i;
                *axis = a;
            }
        }
    }
    return best;
}

/* The nearest group of the same rule and turn along axis that overlaps group best on the two
 * other axes, or m when there is none. */
static size_t nearest_peer(const ag_splittree *t, const sibling *s, size_t m, size_t best,
                           int axis, double eps)
{
    const ag_tnode *bn = &t->nodes[s[best].end];
    const ag_box *bb = &s[best].box;
    size_t other = m;
    double gap = INFINITY;
    for (size_t j = 0; j < m; j++) {
        if (j == best || s[j].leader != (int32_t)j)
            continue;
        const ag_tnode *jn = &t->nodes[s[j].end];
        if (jn->rule != bn->rule || jn->rule_rot != bn->rule_rot)
            continue;
        const ag_box *jb = &s[j].box;
        if (!ag_box_meets_axis(bb, jb, (axis + 1) % 3, eps) ||
            !ag_box_meets_axis(bb, jb, (axis + 2) % 3, eps))
            continue;
        double d = fmax(0, -ag_box_overlap_axis(bb, jb, axis));
        if (d < gap) {
            gap = d;
            other = j;
        }
    }
    return other;
}

/* Joins groups a and b along axis; the earlier sibling leads (its subtree is the one kept).
 * The group's size on that axis is the members' sizes summed (at most the span they cover),
 * centred on that span. */
static void merge_groups(sibling *s, size_t m, size_t a, size_t b, int axis)
{
    size_t lead = a < b ? a : b, gone = a < b ? b : a;
    sibling *L = &s[lead], *G = &s[gone];
    ag_box u = L->box;
    ag_box_extend_box(&u, &G->box);
    double span = ag_box_extent(&u, axis);
    double w = fmin(L->w[axis] + G->w[axis], span), mid = ag_box_centre_axis(&u, axis);
    u.min[axis] = mid - 0.5 * w;
    u.max[axis] = mid + 0.5 * w;
    L->box = u;
    for (int k = 0; k < 3; k++)
        L->w[k] = k == axis ? w : ag_box_extent(&u, k);
    L->members += G->members;
    L->stuck = 0;
    for (size_t i = 0; i < m; i++)
        if (s[i].leader == (int32_t)gone)
            s[i].leader = (int32_t)lead;
}

/* Plain siblings of one rule (children of n not gathered into a grid pattern) squeezed under
 * AG_EDIT_JOIN_RATIO on an axis join with their nearest sibling of the same rule and turn
 * along that axis, recursively, until no group is squeezed or none has a neighbour: the group
 * becomes one copy of its first member's subtree whose size on that axis is the members' sizes
 * summed (at most the span they cover), centred on that span, so two windows squeezed to 0.4×
 * become one of 0.8×. Emits n's children and returns 1 when anything joined, else emits
 * nothing and returns 0. */
static int join_siblings(emitter *E, int32_t n, const ag__resize_map *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    size_t m = 0;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling)
        m++;
    /* each round is linear in m: bound the quadratic worst case of huge flat levels */
    if (m < 2 || m > AG_EDIT_JOIN_SIBLINGS_MAX)
        return 0;
    sibling *s = malloc(m * sizeof *s);
    if (!s) {
        E->st = ag_error_set(E->err, AG_ERR_NOMEM, 0, "out of memory");
        return 1;
    }
    size_t k = 0;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling, k++) {
        sibling *x = &s[k];
        x->slot = c;
        x->end = ag_splittree_chain_end(t, c);
        x->leader = (int32_t)k;
        x->members = 1;
        x->stuck = 0;
        if (x->end >= 0 && t->nodes[x->end].kind == AG_NODE_COMPONENT &&
            t->nodes[x->end].rule >= 0) {
            x->box = new_box(E, x->end, g);
            ag_box_extents(&x->box, x->w);
        } else {
            x->leader = -1;
        }
    }
    double eps = AG_EDIT_COINCIDENT * (1 + ag_box_diagonal(&t->nodes[0].box));
    size_t joined = 0;
    /* every round joins two groups or gives up on one (until a join frees it again) */
    for (size_t round = 0; round < 4 * m; round++) {
        int axis = -1;
        size_t best = most_squeezed(t, s, m, E->join, &axis);
        if (best == m)
            break;
        size_t other = nearest_peer(t, s, m, best, axis, eps);
        if (other == m) {
            s[best].stuck = 1;
            continue;
        }
        merge_groups(s, m, best, other, axis);
        joined++;
    }
    if (!joined) {
        free(s);
        return 0;
    }
    E->joins += joined;
    for (size_t i = 0; i < m && !E->st; i++) {
        if (s[i].leader < 0 || (s[i].leader == (int32_t)i && s[i].members == 1)) {
            emit_node(E, s[i].slot, g, depth + 1);
        } else if (s[i].leader == (int32_t)i) {
            ag__resize_map jm = ag__resize_map_between(&t->nodes[s[i].end].box, &s[i].box);
            emit_node(E, s[i].end, &jm, depth + 1);
        } /* else joined into an earlier sibling */
    }
    free(s);
    return 1;
}

static void emit_children(emitter *E, int32_t n, const ag__resize_map *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    if (t->nodes[n].kind != AG_NODE_SPLIT && join_siblings(E, n, g, depth))
        return;
    for (int32_t c = t->nodes[n].first_child; c >= 0 && !E->st; c = t->nodes[c].next_sibling)
        emit_node(E, c, g, depth + 1);
}

/* ---- patterns ---------------------------------------------------------------------------- */

/* A grid pattern's old and new layout, per axis. */
typedef struct {
    ag_box span_old, span_new; /* the cells' old and new union */
    size_t ncells;             /* cells under the pattern node */
    uint32_t cnt[3], ncnt[3];  /* old and new count */
    double w[3];               /* old cell size */
    double nw[3], np[3];       /* new cell size and period, on axes whose count changes */
    size_t total, ntotal;      /* old and new number of cells */
    int changed;               /* some count changes */
} pattern_layout;

/* The new count per axis: the cells keep their share of the period (rho, cell size over
 * period) while the count doubles as long as a cell would pass the split ratio and halves as
 * long as it would fall under the join ratio. */
static void layout_pattern(emitter *E, const ag_pattern *P, int32_t first,
                           const ag__resize_map *g, pattern_layout *l)
{
    const ag_splittree *t = E->in->tree;
    l->ncells = 0;
    l->span_old = t->nodes[first].box;
    l->span_new = new_box(E, first, g);
    for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling) {
        l->ncells++;
        ag_box nb = new_box(E, c, g);
        ag_box_extend_box(&l->span_old, &t->nodes[c].box);
        ag_box_extend_box(&l->span_new, &nb);
    }
    l->total = l->ntotal = 1;
    l->changed = 0;
    ag_box fo = t->nodes[first].box, fnew = new_box(E, first, g);
    for (int a = 0; a < 3; a++) {
        l->cnt[a] = P->counts[a] ? P->counts[a] : 1;
        l->total *= l->cnt[a];
        l->w[a] = ag_box_extent(&fo, a);
        double nwa = ag_box_extent(&fnew, a);
        double Lnew = ag_box_extent(&l->span_new, a);
        l->ncnt[a] = l->cnt[a];
        l->nw[a] = nwa;
        l->np[a] = 0;
        if (l->cnt[a] < 2 || l->w[a] <= AG_EDIT_FLAT || nwa <= AG_EDIT_FLAT * (1 + fabs(Lnew))) {
            /* no repetition on this axis, or cells collapsed: the count stays */
            l->ntotal *= l->ncnt[a];
            continue;
        }
        double pold = (ag_box_extent(&l->span_old, a) - l->w[a]) / (l->cnt[a] - 1);
        double pnew = (Lnew - nwa) / (l->cnt[a] - 1);
        double rho = pnew > AG_EDIT_FLAT   ? nwa / pnew
                     : pold > AG_EDIT_FLAT ? l->w[a] / pold
                                           : 1;
        if (!(rho > AG_EDIT_MIN_RATIO) || !isfinite(rho)) {
            l->ntotal *= l->ncnt[a];
            continue;
        }
        uint32_t k = l->cnt[a];
        for (int it = 0; it < PATTERN_MAX_STEPS; it++) {
            double p = Lnew / (k - 1 + rho);
            double cw = rho * p;
            if (cw / l->w[a] > E->split && k < PATTERN_MAX_COUNT)
                k *= 2;
            else if (cw / l->w[a] < E->join && k > 1)
                k = k / 2;
            else
                break;
        }
        l->ncnt[a] = k;
        l->np[a] = Lnew / (k - 1 + rho);
        l->nw[a] = rho * l->np[a];
        if (k != l->cnt[a])
            l->changed = 1;
        l->ntotal *= k;
    }
}

/* Old grid index (x fastest) of every cell node into cell (l->total entries). */
static void index_cells(const ag_splittree *t, int32_t first, const pattern_layout *l,
                        int32_t *cell)
{
    for (size_t i = 0; i < l->total; i++)
        cell[i] = first;
    for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling) {
        size_t idx = 0, mul = 1;
        for (int a = 0; a < 3; a++) {
            long ia = 0;
            if (l->cnt[a] > 1) {
                double pold = (ag_box_extent(&l->span_old, a) - l->w[a]) / (l->cnt[a] - 1);
                ia = pold > AG_EDIT_FLAT
                         ? lround((t->nodes[c].box.min[a] - l->span_old.min[a]) / pold)
                         : 0;
                if (ia < 0)
                    ia = 0;
                if (ia >= (long)l->cnt[a])
                    ia = l->cnt[a] - 1;
            }
            idx += (size_t)ia * mul;
            mul *= l->cnt[a];
        }
        assert(idx < l->total);
        cell[idx] = c;
    }
}

static void emit_pattern(emitter *E, int32_t n, const ag__resize_map *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    const ag_tnode *x = &t->nodes[n];
    const ag_pattern *P = x->pattern >= 0 && (size_t)x->pattern < t->npatterns
                              ? &t->patterns[x->pattern]
                              : NULL;
    if (!P || P->nvec || x->first_child < 0) {
        emit_children(E, n, g, depth);
        return;
    }
    int32_t first = x->first_child;
    pattern_layout l;
    layout_pattern(E, P, first, g, &l);
    if (!l.changed || l.ncells != l.total) {
        emit_children(E, n, g, depth);
        return;
    }
    if (l.ntotal > l.total)
        E->splits += l.ntotal - l.total;
    else
        E->joins += l.total - l.ntotal;
    int32_t *cell = malloc(l.total * sizeof *cell);
    if (!cell) {
        E->st = ag_error_set(E->err, AG_ERR_NOMEM, 0, "out of memory");
        return;
    }
    index_cells(t, first, &l, cell);
    /* each new cell copies the old cell at its share of the old grid */
    for (size_t i = 0; i < l.ntotal && !E->st; i++) {
        size_t rest = i, src = 0, mul = 1, ia[3];
        for (int a = 0; a < 3; a++) {
            ia[a] = rest % l.ncnt[a];
            rest /= l.ncnt[a];
            src += (ia[a] * l.cnt[a] / l.ncnt[a]) * mul;
            mul *= l.cnt[a];
        }
        int32_t c = cell[src];
        ag_box nb = new_box(E, c, g); /* axes whose count stays: the cell as mapped */
        for (int a = 0; a < 3; a++)
            if (l.ncnt[a] != l.cnt[a]) {
                nb.min[a] = l.span_new.min[a] + ia[a] * l.np[a];
                nb.max[a] = nb.min[a] + l.nw[a];
            }
        ag__resize_map m = ag__resize_map_between(&t->nodes[c].box, &nb);
        emit_node(E, c, &m, depth + 1);
    }
    free(cell);
}

/* ---- nodes ------------------------------------------------------------------------------- */

/* The axis on which node x stretched most past the split ratio from its old box to nb, or -1. */
static int split_axis(const ag_tnode *x, const ag_box *nb, double split, double thin_share)
{
    int axis = -1;
    double best = split;
    double largest = fmax(ag_box_extent(&x->box, 0),
                          fmax(ag_box_extent(&x->box, 1), ag_box_extent(&x->box, 2)));
    for (int a = 0; a < 3; a++) {
        double w = ag_box_extent(&x->box, a);
        if (w <= AG_EDIT_FLAT || w < thin_share * largest)
            continue;
        double r = ag_box_extent(nb, a) / w;
        if (r > best) {
            best = r;
            axis = a;
        }
    }
    return axis;
}

static void emit_node(emitter *E, int32_t n, const ag__resize_map *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    assert(n >= 0 && (size_t)n < t->nnodes);
    const ag_tnode *x = &t->nodes[n];
    if (x->kind == AG_NODE_DEAD || depth > EMIT_MAX_DEPTH)
        return;
    if (x->kind == AG_NODE_PATTERN) {
        emit_pattern(E, n, g, depth);
        return;
    }
    if (x->kind != AG_NODE_COMPONENT) {
        emit_children(E, n, g, depth);
        return;
    }
    ag_box nb = new_box(E, n, g);
    ag__resize_map m = ag__resize_map_between(&x->box, &nb);
    /* stretched past the split ratio on an axis: two copies of the subtree, each half */
    int axis = split_axis(x, &nb, E->split, E->thin_share);
    if (axis >= 0) {
        E->splits++;
        double mid = ag_box_centre_axis(&nb, axis);
        for (int h = 0; h < 2 && !E->st; h++) {
            ag_box hb = nb;
            if (h == 0)
                hb.max[axis] = mid;
            else
                hb.min[axis] = mid;
            ag__resize_map hm = ag__resize_map_between(&x->box, &hb);
            emit_node(E, n, &hm, depth + 1);
        }
        return;
    }
    emit_component(E, n, &m);
    if (E->st)
        return;
    /* the subtree follows this node's map when it was overridden, else its own boxes */
    emit_children(E, n, g ? &m : NULL, depth);
}

ag_status ag_edit_resize_emit(const ag_proceduralize_result *in, const ag_box *boxes,
                              const ag_edit_budget *budget, ag_mesh **out, ag_edit_report *rep,
                              ag_error *err)
{
    return ag_edit_resize_emit_ratio(in, boxes, 0, 0, budget, out, rep, err);
}

ag_status ag_edit_resize_emit_ratio(const ag_proceduralize_result *in, const ag_box *boxes,
                                    double split_ratio, double thin_share,
                                    const ag_edit_budget *budget, ag_mesh **out,
                                    ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    emitter E = {.in = in, .boxes = boxes, .err = err, .budget = budget};
    E.split = split_ratio > 1 ? split_ratio : AG_EDIT_SPLIT_RATIO;
    E.join = 1 / E.split;
    E.thin_share = thin_share;
    const ag_labels *L = in->labels;
    E.out = ag_mesh_create();
    E.group_of_label = malloc((L->nlabels + 1) * sizeof *E.group_of_label);
    E.vmap = malloc((in->mesh->nverts + 1) * sizeof *E.vmap);
    E.stamp = calloc(in->mesh->nverts + 1, sizeof *E.stamp);
    E.max_components = EMIT_MAX_COMPONENTS(in->tree->nnodes);
    E.max_triangles = AG_EDIT_MAX_TRIANGLES;
    if (budget && budget->max_components && budget->max_components < E.max_components)
        E.max_components = budget->max_components;
    if (budget && budget->max_triangles && budget->max_triangles < E.max_triangles)
        E.max_triangles = budget->max_triangles;
    if (!E.out || !E.group_of_label || !E.vmap || !E.stamp) {
        E.st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < L->nlabels; i++)
        E.group_of_label[i] = -1;
    /* count first: a stretch that splits exponentially is refused having made nothing */
    E.count_only = 1;
    emit_node(&E, 0, NULL, 0);
    if (E.st)
        goto done;
    size_t ntris = E.ntris;
    E.count_only = 0;
    E.ncomponents = E.ntris = 0;
    E.splits = E.joins = 0;
    if ((E.st = ag_mesh_reserve(E.out, 0, ntris))) {
        ag_error_set(err, E.st, 0, "out of memory");
        goto done;
    }
    emit_node(&E, 0, NULL, 0);
done:
    free(E.group_of_label);
    free(E.vmap);
    free(E.stamp);
    if (E.st) {
        ag_mesh_free(E.out);
        return E.st;
    }
    if (rep) {
        rep->splits += E.splits;
        rep->joins += E.joins;
    }
    *out = E.out;
    return AG_OK;
}
