/* The layout of a resize below the edited level (resize_internal.h), on a copy of the tree:
 *
 *   layout_node      a node whose box changed lays out its children: moved as a whole when
 *                    the box only moved, else its child units solved in its new box
 *                    (resize_system.c with the node as a fixed frame: faces on its faces
 *                    follow them, what floats keeps its place relative to it, a unique element
 *                    keeps its size, repetitions follow it)
 *   layout_units     the new boxes of one level of siblings, then (a commit) squeezed
 *                    siblings of one rule joined and leaves stretched past the split ratio
 *                    split, patterns laid out again, and every changed unit's own children
 *   layout_patterns  a pattern's cells are its lattice periods: the pattern's new length in
 *                    periods of the original size, doubled or halved while a period would pass
 *                    the split ratio or fall under the join ratio (a facade stretched 2x holds
 *                    twice the windows at the original size and spacing, held inside what
 *                    holds the pattern, one fewer when they would not fit); cells of a new
 *                    count keep their size, cells of the same count their share of the new
 *                    box, except along an axis that is thin for them (they keep their size
 *                    and are spaced out); patterns of one parent whose lattices
 *                    interleave (the pieces of composite windows, windows alternating with
 *                    their mirror images) share one lattice, placed as one; new cells
 *                    copy the cell at their place in the old grid, cells no new cell copies go
 *
 * A node of the copy keeps its index (its id); copies are appended, removed nodes become
 * dead. Every node knows the node of the input tree it copies (source): its old box is that
 * node's box, and it places that node's component. Before a node is laid out, its descendants
 * still have their old boxes. */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "resize_internal.h"
#include "treeedit.h"

/* Work limits: a pattern count doubles at most up to this; the count search stops after this
 * many halvings or doublings; the layout recurses at most this deep; a huge stretch splits
 * exponentially, so the new tree is bounded by the old one's size. */
#define PATTERN_MAX_COUNT (1u << 20)
#define PATTERN_MAX_STEPS 40
#define LAYOUT_MAX_DEPTH (4 * AG_SPLITTREE_MAX_NESTING + 64)
#define LAYOUT_MAX_NODES(nnodes) (64 * ((size_t)(nnodes) + 16) + ((size_t)1 << 20))

typedef struct {
    const ag_edit_resize_solver *s;
    const ag_splittree *ot;   /* the input tree */
    ag_splittree *nt;         /* the copy being laid out */
    int32_t *src;             /* per node of nt: the node of ot it copies */
    size_t cap_src;
    int structural;
    double eps;
    size_t splits, joins;
    size_t max_nodes;         /* the new tree's bound (the budget's, when it sets a lower one) */
    unsigned since_poll;      /* copies since the budget's callback was last asked */
    int32_t *walk;            /* the one stack of the subtree walks (none nests in another) */
    size_t cap_walk;
    ag_status st;
    ag_error *err;
} lay;

/* Copies made between two polls of the budget's callback. */
#define LAYOUT_POLL 1024

static void layout_node(lay *L, int32_t x, int depth);
static void layout_patterns(lay *L, const int32_t *pats, size_t n, int depth);

static void fail_nomem(lay *L)
{
    if (!L->st)
        L->st = ag_error_set(L->err, AG_ERR_NOMEM, 0, "out of memory");
}

/* The walks' stack, room for n entries: one buffer for the whole layout, since a walk per cell
 * that allocated the tree's size made a large pattern quadratic. */
static int32_t *walk_stack(lay *L, size_t n)
{
    if (AG_ARRAY_RESERVE(L->walk, L->cap_walk, n)) {
        fail_nomem(L);
        return NULL;
    }
    return L->walk;
}

static ag_box oldb(const lay *L, int32_t x)
{
    return L->ot->nodes[L->src[x]].box;
}

static int same_box(const ag_box *a, const ag_box *b, double eps)
{
    for (int k = 0; k < 3; k++)
        if (fabs(a->min[k] - b->min[k]) > eps || fabs(a->max[k] - b->max[k]) > eps)
            return 0;
    return 1;
}

/* ---- tree edits -------------------------------------------------------------------------- */

/* A new node copying node y (fields and source; box: its old box; linked to nothing). */
static int32_t copy_node(lay *L, int32_t y)
{
    if (L->st)
        return -1;
    if (L->nt->nnodes >= L->max_nodes) {
        L->st = ag_error_set(L->err, AG_ERR_RESULT_TOO_LARGE, 0,
                             "resize: the result would have more than %zu nodes, the most this "
                             "server takes",
                             L->max_nodes);
        return -1;
    }
    if (++L->since_poll >= LAYOUT_POLL) {
        L->since_poll = 0;
        if (ag_edit_budget_cancelled(L->s->budget)) {
            L->st = ag_error_set(L->err, AG_ERR_CANCELLED, 0, "resize: stopped");
            return -1;
        }
    }
    int32_t c = ag_splittree_add_node(L->nt, AG_NODE_DEAD);
    if (c < 0 || AG_ARRAY_RESERVE(L->src, L->cap_src, (size_t)c + 1)) {
        fail_nomem(L);
        return -1;
    }
    ag_tnode *n = &L->nt->nodes[c];
    *n = L->nt->nodes[y];
    n->parent = n->first_child = n->last_child = n->next_sibling = -1;
    L->src[c] = L->src[y];
    n->box = oldb(L, c);
    if (n->kind == AG_NODE_PATTERN && n->pattern >= 0) {
        ag_splittree *t = L->nt;
        if (AG_ARRAY_RESERVE(t->patterns, t->cap_patterns, t->npatterns + 1)) {
            fail_nomem(L);
            return -1;
        }
        t->patterns[t->npatterns] = t->patterns[t->nodes[c].pattern];
        t->patterns[t->npatterns].node = c;
        t->nodes[c].pattern = (int32_t)t->npatterns++;
    }
    return c;
}

/* A copy of y's subtree (before y is laid out: old boxes) appended to parent's children. */
static int32_t copy_subtree(lay *L, int32_t y, int32_t parent, int depth)
{
    int32_t c = copy_node(L, y);
    if (c < 0)
        return -1;
    ag_splittree_attach(L->nt, parent, c);
    if (depth > LAYOUT_MAX_DEPTH)
        return c;
    for (int32_t k = L->nt->nodes[y].first_child; k >= 0 && !L->st; k = L->nt->nodes[k].next_sibling)
        copy_subtree(L, k, c, depth + 1);
    return c;
}

/* x and its subtree are removed (dead, linked to nothing), with the split chain x hangs by. */
static void kill_subtree(lay *L, int32_t x)
{
    int32_t *stack = walk_stack(L, L->nt->nnodes + 1);
    if (stack)
        ag_treeedit_kill_subtree(L->nt, x, stack);
}

/* Everything below x moves by d. */
static void translate_below(lay *L, int32_t x, const double d[3])
{
    ag_splittree *t = L->nt;
    int32_t *stack = walk_stack(L, t->nnodes + 1);
    if (!stack)
        return;
    size_t sp = 0;
    for (int32_t c = t->nodes[x].first_child; c >= 0; c = t->nodes[c].next_sibling)
        stack[sp++] = c;
    while (sp) {
        int32_t v = stack[--sp];
        for (int a = 0; a < 3; a++) {
            t->nodes[v].box.min[a] += d[a];
            t->nodes[v].box.max[a] += d[a];
        }
        for (int32_t c = t->nodes[v].first_child; c >= 0; c = t->nodes[c].next_sibling)
            stack[sp++] = c;
    }
}

/* The node whose child list holds x's split chain (x's parent, or its intermediate's). */
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

/* ---- joins of squeezed siblings ---------------------------------------------------------- */

/* A unit of one level and the group it joins. */
typedef struct {
    int32_t node;
    int32_t parent;   /* the node whose children it is among */
    int32_t leader;   /* index of the group's first member; -1: takes no part */
    size_t members;   /* at the leader: how many */
    int stuck;        /* at the leader: squeezed but no neighbour to join */
    double w[3];      /* at the leader: the group's new size per axis */
    ag_box box;       /* at the leader: the group's new box */
} sibling;

/* The most squeezed group that may still join (index, axis), or m when none is squeezed. */
static size_t most_squeezed(const lay *L, const sibling *s, size_t m, int *axis)
{
    size_t best = m;
    double worst = L->s->join_ratio;
    for (size_t i = 0; i < m; i++) {
        if (s[i].leader != (int32_t)i || s[i].stuck)
            continue;
        ag_box ob = oldb(L, s[i].node);
        for (int a = 0; a < 3; a++) {
            double ow = ag_box_extent(&ob, a);
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

/* The nearest group of the same rule and turn under the same parent along axis that overlaps
 * group best on the two other axes, or m when there is none. */
static size_t nearest_peer(const lay *L, const sibling *s, size_t m, size_t best, int axis)
{
    const ag_tnode *bn = &L->nt->nodes[s[best].node];
    const ag_box *bb = &s[best].box;
    double eps = L->eps;
    size_t other = m;
    double gap = INFINITY;
    for (size_t j = 0; j < m; j++) {
        if (j == best || s[j].leader != (int32_t)j || s[j].parent != s[best].parent)
            continue;
        const ag_tnode *jn = &L->nt->nodes[s[j].node];
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

/* Joins groups a and b along axis; the earlier leads. The group's size on that axis is the
 * members' sizes summed (at most the span they cover), centred on that span. */
static void merge_groups(sibling *s, size_t m, size_t a, size_t b, int axis)
{
    size_t lead = a < b ? a : b, gone = a < b ? b : a;
    sibling *Ld = &s[lead], *G = &s[gone];
    ag_box u = Ld->box;
    ag_box_extend_box(&u, &G->box);
    double span = ag_box_extent(&u, axis);
    double w = fmin(Ld->w[axis] + G->w[axis], span), mid = ag_box_centre_axis(&u, axis);
    u.min[axis] = mid - 0.5 * w;
    u.max[axis] = mid + 0.5 * w;
    Ld->box = u;
    for (int k = 0; k < 3; k++)
        Ld->w[k] = k == axis ? w : ag_box_extent(&u, k);
    Ld->members += G->members;
    Ld->stuck = 0;
    for (size_t i = 0; i < m; i++)
        if (s[i].leader == (int32_t)gone)
            s[i].leader = (int32_t)lead;
}

/* Plain siblings of one rule (not cells of a pattern) squeezed under the join ratio on an
 * axis join with their nearest sibling of the same rule and turn along that axis, recursively,
 * until no group is squeezed or none has a neighbour: the group becomes its first member with
 * the members' sizes summed on that axis (at most the span they cover), centred on that span,
 * so two windows squeezed to 0.4x become one of 0.8x; the others go. */
static void join_siblings(lay *L, const int32_t *units, size_t n)
{
    if (n < 2 || n > AG_EDIT_JOIN_SIBLINGS_MAX)
        return;
    sibling *s = malloc(n * sizeof *s);
    if (!s) {
        fail_nomem(L);
        return;
    }
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const ag_tnode *x = &L->nt->nodes[units[i]];
        if (x->kind != AG_NODE_COMPONENT || x->rule < 0)
            continue;
        int32_t slot;
        int32_t p = chain_parent(L->nt, units[i], &slot);
        if (p >= 0 && L->nt->nodes[p].kind == AG_NODE_PATTERN)
            continue;
        sibling *y = &s[m];
        y->node = units[i];
        y->parent = p;
        y->leader = (int32_t)m;
        y->members = 1;
        y->stuck = 0;
        y->box = x->box;
        ag_box_extents(&y->box, y->w);
        m++;
    }
    size_t joined = 0;
    for (size_t round = 0; round < 4 * m; round++) {
        int axis = -1;
        size_t best = most_squeezed(L, s, m, &axis);
        if (best == m)
            break;
        size_t other = nearest_peer(L, s, m, best, axis);
        if (other == m) {
            s[best].stuck = 1;
            continue;
        }
        merge_groups(s, m, best, other, axis);
        joined++;
    }
    if (joined) {
        L->joins += joined;
        for (size_t i = 0; i < m; i++) {
            if (s[i].leader == (int32_t)i)
                L->nt->nodes[s[i].node].box = s[i].box;
            else
                kill_subtree(L, s[i].node);
        }
    }
    free(s);
}

/* ---- splits of stretched leaves ---------------------------------------------------------- */

/* The axis on which a leaf stretched most past the split ratio from old box o to nb, -1 when
 * none did; thin axes never split. */
static int split_axis(const lay *L, const ag_box *o, const ag_box *nb)
{
    double e[3], emax = 0;
    ag_box_extents(o, e);
    for (int a = 0; a < 3; a++)
        emax = fmax(emax, e[a]);
    int axis = -1;
    double best = L->s->split_ratio;
    for (int a = 0; a < 3; a++) {
        if (e[a] <= AG_EDIT_FLAT || e[a] < L->s->thin_ratio * emax)
            continue;
        double r = ag_box_extent(nb, a) / e[a];
        if (r > best) {
            best = r;
            axis = a;
        }
    }
    return axis;
}

/* A leaf stretched past the split ratio becomes two copies, each half as long (recursively):
 * the node itself keeps the first half, a copy after it in its parent takes the second. */
static void split_leaf(lay *L, int32_t c, int depth)
{
    if (L->st || depth > LAYOUT_MAX_DEPTH)
        return;
    ag_box ob = oldb(L, c), nb = L->nt->nodes[c].box;
    int axis = split_axis(L, &ob, &nb);
    if (axis < 0)
        return;
    int32_t slot, p = chain_parent(L->nt, c, &slot);
    if (p < 0)
        return;
    int32_t k = copy_node(L, c);
    if (k < 0)
        return;
    double mid = ag_box_centre_axis(&nb, axis);
    ag_box lo = nb, hi = nb;
    lo.max[axis] = mid;
    hi.min[axis] = mid;
    L->nt->nodes[c].box = lo;
    L->nt->nodes[k].box = hi;
    ag_splittree_attach_after(L->nt, p, slot, k);
    L->splits++;
    split_leaf(L, c, depth + 1);
    split_leaf(L, k, depth + 1);
}

/* ---- one level of siblings --------------------------------------------------------------- */

static void layout_units(lay *L, const int32_t *units, size_t n, const ag_box *boxes, int depth)
{
    ag_splittree *t = L->nt;
    for (size_t i = 0; i < n; i++)
        t->nodes[units[i]].box = boxes[i];
    int32_t *list = malloc((n + 1) * sizeof *list);
    if (!list) {
        fail_nomem(L);
        return;
    }
    memcpy(list, units, n * sizeof *list);
    if (L->structural) {
        join_siblings(L, list, n);
        for (size_t i = 0; i < n && !L->st; i++) {
            const ag_tnode *x = &t->nodes[list[i]];
            if (x->kind == AG_NODE_COMPONENT && x->first_child < 0 &&
                (x->parent < 0 || t->nodes[x->parent].kind != AG_NODE_PATTERN))
                split_leaf(L, list[i], depth);
        }
    }
    size_t np = 0;
    int32_t *pats = malloc((n + 1) * sizeof *pats);
    if (!pats) {
        free(list);
        fail_nomem(L);
        return;
    }
    for (size_t i = 0; i < n; i++)
        if (t->nodes[list[i]].kind == AG_NODE_PATTERN)
            pats[np++] = list[i];
    if (np)
        layout_patterns(L, pats, np, depth);
    free(pats);
    /* the units and the copies splits added after them */
    for (size_t i = 0; i < n && !L->st; i++) {
        int32_t x = list[i];
        if (t->nodes[x].kind == AG_NODE_COMPONENT)
            layout_node(L, x, depth + 1);
    }
    free(list);
}

/* The child units of x in the copy: the ends of its split chains. */
static size_t child_units(const lay *L, int32_t x, int32_t *out, size_t cap)
{
    const ag_splittree *t = L->nt;
    size_t k = 0;
    for (int32_t c = t->nodes[x].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, c);
        if (e < 0 || (t->nodes[e].kind != AG_NODE_COMPONENT && t->nodes[e].kind != AG_NODE_PATTERN))
            continue;
        if (k < cap)
            out[k] = e;
        k++;
    }
    return k;
}

/* Children moved by the map of their parent (when no system can be made for them). */
static void map_children(lay *L, int32_t x, const int32_t *units, size_t n, ag_box *boxes)
{
    ag_box ob = oldb(L, x);
    ag__resize_map m = ag__resize_map_between(&ob, &L->nt->nodes[x].box);
    for (size_t i = 0; i < n; i++) {
        ag_box b = oldb(L, units[i]);
        boxes[i] = ag__resize_map_box(&m, &b);
    }
}

static void layout_node(lay *L, int32_t x, int depth)
{
    ag_splittree *t = L->nt;
    if (L->st || depth > LAYOUT_MAX_DEPTH || t->nodes[x].kind == AG_NODE_DEAD)
        return;
    ag_box ob = oldb(L, x), nb = t->nodes[x].box;
    double tiny = 1e-3 * L->eps;
    if (same_box(&ob, &nb, tiny))
        return;
    double d[3], e0[3], e1[3];
    ag_box_extents(&ob, e0);
    ag_box_extents(&nb, e1);
    int moved = 1;
    for (int a = 0; a < 3; a++) {
        d[a] = nb.min[a] - ob.min[a];
        moved &= fabs(e1[a] - e0[a]) <= tiny;
    }
    if (moved) {
        translate_below(L, x, d);
        return;
    }
    if (t->nodes[x].kind == AG_NODE_PATTERN) {
        layout_patterns(L, &x, 1, depth);
        return;
    }
    size_t n = child_units(L, x, NULL, 0);
    if (!n)
        return;
    int32_t *units = malloc(n * sizeof *units), *srcs = malloc(n * sizeof *srcs);
    ag_box *old = malloc(n * sizeof *old), *boxes = malloc((n + 1) * sizeof *boxes);
    if (!units || !srcs || !old || !boxes) {
        fail_nomem(L);
        goto done;
    }
    child_units(L, x, units, n);
    int distinct = 1;
    for (size_t i = 0; i < n; i++) {
        srcs[i] = L->src[units[i]];
        old[i] = L->ot->nodes[srcs[i]].box;
        for (size_t j = 0; j < i && distinct; j++)
            distinct = srcs[j] != srcs[i];
        distinct &= L->s->units.unit[srcs[i]] == srcs[i];
    }
    int solved = 0;
    if (distinct) {
        ag__resize_spec spec = {.nunits = n,
                                .units = srcs,
                                .frame = AG__FRAME_FIXED,
                                .frame_old = ob,
                                .frame_new = nb,
                                .frame_node = L->src[x],
                                .old = old};
        ag__resize_system sys;
        ag_error e;
        ag_error_clear(&e);
        double res;
        if (ag__resize_system_build(&sys, L->s->in, &L->s->units, &spec, &e) == AG_OK &&
            ag__resize_system_solve(&sys, 0, NULL, NULL, boxes, &res, &e) == AG_OK)
            solved = 1;
        else if (e.code == AG_ERR_NOMEM)
            fail_nomem(L);
        ag__resize_system_free(&sys);
    }
    if (L->st)
        goto done;
    if (!solved)
        map_children(L, x, units, n, boxes);
    for (size_t i = 0; i < n; i++)
        ag_box_clamp(&boxes[i], &nb); /* children stay inside */
    layout_units(L, units, n, boxes, depth);
done:
    free(units);
    free(srcs);
    free(old);
    free(boxes);
}

/* ---- patterns ---------------------------------------------------------------------------- */

/* A grid pattern's layout along one axis. */
typedef struct {
    uint32_t n, k;   /* old and new count */
    uint32_t kset;   /* the new count of the set it leads (lattice_set) */
    double p, pn;    /* old and new period */
    double w, wn;    /* old and new cell size */
    double o, on;    /* old and new min of the first cell */
    double f;        /* the pattern's stretch along the axis */
    int lattice;     /* repeats along this axis */
} axis_layout;

typedef struct {
    int32_t node;
    int grid;              /* a complete axis-aligned grid: laid out by periods */
    axis_layout ax[3];
    ag__resize_map map;    /* otherwise: its cells follow this map */
    ag_box nb;             /* its new box */
    ag_box cont;           /* what holds it (its holder's box, grown to hold nb) */
    int thin[3];           /* its cells are thin along the axis */
} pattern_layout;

/* Along one axis, the patterns that share a lattice laid out by the first of them (the
 * pieces of composite windows, windows and their mirror images alternating): where the
 * count changes they are placed as one, so that the set stays centred and inside what holds
 * it (each pattern alone is off-centre by its offset in the set). */
#define LATTICE_SET_MAX 8
typedef struct {
    ag_box nb;     /* the union of their new boxes */
    ag_box cont;   /* the union of what holds them */
    double lo, hi; /* the lowest and highest old min of their first cells */
    uint32_t cells; /* of all members along the axis */
    size_t m, rank; /* members; the rank of the pattern being laid out (by first cell) */
    /* alternating: members whose cells lie apart and take turns (a window, its mirror
     * image, the window again: 3 and 2 cells), counted as one sequence of cells; d: the
     * members' offsets from lo by rank */
    int alternating;
    double d[LATTICE_SET_MAX];
} lattice_set;

/* Cells of the member of rank q when an alternating set holds `cells` cells in all. */
static uint32_t member_cells(const lattice_set *set, uint32_t cells, size_t q)
{
    return (uint32_t)((cells - q + set->m - 1) / set->m);
}

/* The extent of an alternating set of `cells` cells at period pn, cells w long. */
static double set_span(const lattice_set *set, uint32_t cells, double pn, double w)
{
    return (double)((cells - 1) / set->m) * pn + set->d[(cells - 1) % set->m] + w;
}

/* Along axis a, the pattern's new count and period from its stretch f, unless a reference
 * pattern ref (interleaved with it: the same period and stretch) fixes them; set: the
 * patterns it is the reference of, itself included. An alternating set is counted as one
 * sequence of cells (kset), which its members take turns in. */
static void layout_axis(const lay *L, axis_layout *x, const ag_box *nb, const lattice_set *set,
                        int a, int thin, const axis_layout *ref)
{
    int alt = set->alternating;
    uint32_t n = alt ? set->cells : x->n, k = n;
    if (ref) {
        k = ref->kset;
    } else if (L->structural && !thin) { /* thin elements are spaced out, never added */
        for (int it = 0; it < PATTERN_MAX_STEPS; it++) {
            double r = x->f * n / k;
            if (r > L->s->split_ratio && k < PATTERN_MAX_COUNT)
                k *= 2;
            else if (r < L->s->join_ratio && k > 1)
                k /= 2;
            else
                break;
        }
    }
    int changed = k != n;
    if (alt && k < set->m)
        k = (uint32_t)set->m; /* every member keeps a cell */
    x->kset = k;
    x->k = alt ? member_cells(set, k, set->rank) : k;
    if (ref && changed) { /* cells of a new count keep their size and offset */
        x->pn = ref->pn;
        x->wn = x->w;
        x->on = ref->on + (x->o - ref->o);
    } else if (ref) {
        x->pn = ref->pn;
        x->wn = thin ? x->w : x->w * x->pn / x->p;
        x->on = ref->on + (x->o - ref->o) * x->pn / x->p;
    } else if (!changed) {
        /* the count stays: the cells span the pattern's new box (thin ones spaced out) */
        x->wn = thin ? x->w : x->w * x->f;
        x->pn = (ag_box_extent(nb, a) - x->wn) / (x->k - 1);
        x->on = nb->min[a];
    } else {
        /* the pattern's length in periods; the cells keep their size (a facade stretched 2x
         * holds twice the windows at the original size and spacing, 1.9x slightly closer) */
        x->pn = x->f * n * x->p / k;
        x->wn = x->w;
        /* k periods span one spacing more than the stretched cells did: the cells stay inside
         * what holds the pattern, one fewer when they would not fit (a facade of 6 windows
         * stretched twice as long with less than half a spacing at its ends holds 11) */
        const ag_box *cont = &set->cont;
        double room = ag_box_extent(cont, a) + L->eps, spread = set->hi - set->lo, span;
        if (alt) {
            while (k > set->m && set_span(set, k, x->pn, x->wn) > room)
                k--;
            span = set_span(set, k, x->pn, x->wn);
        } else {
            while (k > 1 && (k - 1) * x->pn + x->wn + spread > room)
                k--;
            span = (k - 1) * x->pn + x->wn + spread;
        }
        x->kset = k;
        x->k = alt ? member_cells(set, k, set->rank) : k;
        double lo = ag_box_centre_axis(&set->nb, a) - 0.5 * span;
        if (lo + span > cont->max[a])
            lo = cont->max[a] - span;
        if (lo < cont->min[a])
            lo = cont->min[a];
        x->on = lo + (x->o - set->lo);
    }
}

/* Do two patterns' lattices interleave along an axis (counts at most one apart, the same
 * period and stretch, first cells less than a period apart)? */
static int interleaved(const axis_layout *x, const axis_layout *y, double tol)
{
    return x->lattice && y->lattice && x->n + 1 >= y->n && y->n + 1 >= x->n &&
           fabs(x->p - y->p) <= tol &&
           fabs(x->f - y->f) <= 1e-9 * fmax(1, fabs(x->f)) && fabs(x->o - y->o) < x->p - tol;
}

/* Does cell c's subtree have the shape of cell c0's (kinds, children, old places relative to
 * the cell)? Then c's new boxes are c0's moved. */
static int parallel(lay *L, int32_t c0, int32_t c, double tol)
{
    const ag_splittree *t = L->nt;
    ag_box b0 = oldb(L, c0), b1 = oldb(L, c);
    int32_t *st = walk_stack(L, 2 * (t->nnodes + 1));
    if (!st)
        return 0;
    size_t sp = 0;
    int ok = 1;
    for (int32_t x = t->nodes[c0].first_child, y = t->nodes[c].first_child; ok;
         x = t->nodes[x].next_sibling, y = t->nodes[y].next_sibling) {
        if ((x < 0) != (y < 0))
            ok = 0;
        if (x < 0 || y < 0)
            break;
        st[sp++] = x;
        st[sp++] = y;
    }
    while (ok && sp) {
        int32_t y = st[--sp], x = st[--sp];
        if (t->nodes[x].kind != t->nodes[y].kind) {
            ok = 0;
            break;
        }
        ag_box ox = oldb(L, x), oy = oldb(L, y);
        for (int a = 0; a < 3 && ok; a++)
            ok = fabs((ox.min[a] - b0.min[a]) - (oy.min[a] - b1.min[a])) <= tol &&
                 fabs((ox.max[a] - b0.min[a]) - (oy.max[a] - b1.min[a])) <= tol;
        for (int32_t p = t->nodes[x].first_child, q = t->nodes[y].first_child; ok;
             p = t->nodes[p].next_sibling, q = t->nodes[q].next_sibling) {
            if ((p < 0) != (q < 0))
                ok = 0;
            if (p < 0 || q < 0)
                break;
            st[sp++] = p;
            st[sp++] = q;
        }
    }
    return ok;
}

/* c's subtree takes c0's new boxes, moved with c. */
static void copy_layout(lay *L, int32_t c0, int32_t c)
{
    ag_splittree *t = L->nt;
    double d[3];
    for (int a = 0; a < 3; a++)
        d[a] = t->nodes[c].box.min[a] - t->nodes[c0].box.min[a];
    int32_t *st = walk_stack(L, 2 * (t->nnodes + 1));
    if (!st)
        return;
    size_t sp = 0;
    for (int32_t x = t->nodes[c0].first_child, y = t->nodes[c].first_child; x >= 0 && y >= 0;
         x = t->nodes[x].next_sibling, y = t->nodes[y].next_sibling) {
        st[sp++] = x;
        st[sp++] = y;
    }
    while (sp) {
        int32_t y = st[--sp], x = st[--sp];
        for (int a = 0; a < 3; a++) {
            t->nodes[y].box.min[a] = t->nodes[x].box.min[a] + d[a];
            t->nodes[y].box.max[a] = t->nodes[x].box.max[a] + d[a];
        }
        for (int32_t p = t->nodes[x].first_child, q = t->nodes[y].first_child; p >= 0 && q >= 0;
             p = t->nodes[p].next_sibling, q = t->nodes[q].next_sibling) {
            st[sp++] = p;
            st[sp++] = q;
        }
    }
}

/* Lays out the cells of pattern P (its new box set) with layout pl: new cells, their boxes,
 * then their subtrees (the first cell's laid out, the others' copied from it when they have
 * its shape). */
static void place_cells(lay *L, const pattern_layout *pl, int depth)
{
    ag_splittree *t = L->nt;
    int32_t P = pl->node;
    ag_pattern *pp = &t->patterns[t->nodes[P].pattern];
    size_t ncells = 0;
    for (int32_t c = t->nodes[P].first_child; c >= 0; c = t->nodes[c].next_sibling)
        ncells++;
    int32_t *cells = malloc((ncells + 1) * sizeof *cells);
    if (!cells) {
        fail_nomem(L);
        return;
    }
    size_t i = 0;
    for (int32_t c = t->nodes[P].first_child; c >= 0; c = t->nodes[c].next_sibling)
        cells[i++] = c;
    int32_t *order = cells;
    size_t nnew = ncells;
    int changed = 0;
    if (pl->grid)
        for (int a = 0; a < 3; a++)
            changed |= pl->ax[a].k != pl->ax[a].n;
    if (pl->grid && changed) {
        /* each new cell copies the old cell at its place in the old grid */
        nnew = (size_t)pl->ax[0].k * pl->ax[1].k * pl->ax[2].k;
        order = malloc((nnew + 1) * sizeof *order);
        uint8_t *used = calloc(ncells + 1, 1);
        if (!order || !used) {
            free(used);
            if (order != cells)
                free(order);
            free(cells);
            fail_nomem(L);
            return;
        }
        for (size_t j = 0; j < nnew && !L->st; j++) {
            size_t rest = j, srci = 0, mul = 1;
            for (int a = 0; a < 3; a++) {
                size_t ia = rest % pl->ax[a].k;
                rest /= pl->ax[a].k;
                srci += (ia * pl->ax[a].n / pl->ax[a].k) * mul;
                mul *= pl->ax[a].n;
            }
            if (!used[srci]) {
                used[srci] = 1;
                order[j] = cells[srci];
            } else {
                order[j] = copy_subtree(L, cells[srci], P, depth);
            }
        }
        for (size_t j = 0; j < ncells && !L->st; j++)
            if (!used[j])
                kill_subtree(L, cells[j]);
        free(used);
        if (L->st) {
            if (order != cells)
                free(order);
            free(cells);
            return;
        }
        /* the pattern's children in cell order */
        t->nodes[P].first_child = t->nodes[P].last_child = -1;
        for (size_t j = 0; j < nnew; j++)
            ag_splittree_attach(t, P, order[j]);
        pp = &t->patterns[t->nodes[P].pattern];
        L->splits += nnew > ncells ? nnew - ncells : 0;
        L->joins += ncells > nnew ? ncells - nnew : 0;
    }
    if (pl->grid) {
        for (int a = 0; a < 3; a++) {
            pp->counts[a] = pl->ax[a].k;
            if (pl->ax[a].lattice)
                pp->step[a] = pl->ax[a].pn;
        }
    } else {
        for (int v = 0; v < pp->nvec; v++)
            for (int a = 0; a < 3; a++)
                pp->vec[v][a] *= pl->map.s[a];
    }
    for (size_t j = 0; j < nnew; j++) {
        int32_t c = order[j];
        ag_box ob = oldb(L, c), nb;
        if (pl->grid) {
            size_t rest = j;
            for (int a = 0; a < 3; a++) {
                const axis_layout *x = &pl->ax[a];
                size_t ia = rest % x->k;
                rest /= x->k;
                if (x->lattice) {
                    nb.min[a] = x->on + (double)ia * x->pn;
                    nb.max[a] = nb.min[a] + x->wn;
                } else { /* one cell across: where the pattern's box went */
                    nb.min[a] = pl->map.s[a] * ob.min[a] + pl->map.t[a];
                    nb.max[a] = pl->map.s[a] * ob.max[a] + pl->map.t[a];
                }
            }
        } else {
            nb = ag__resize_map_box(&pl->map, &ob);
        }
        t->nodes[c].box = nb;
    }
    double tol = t->tol > 0 ? t->tol : L->eps;
    for (size_t j = 0; j < nnew && !L->st; j++) {
        if (j && parallel(L, order[0], order[j], tol))
            copy_layout(L, order[0], order[j]);
        else
            layout_node(L, order[j], depth + 1);
    }
    if (order != cells)
        free(order);
    free(cells);
}

/* The pattern whose lattice pattern i follows along axis a: the first earlier one
 * interleaved with it, followed to the one that follows none; i itself when none. */
static size_t lattice_root(const pattern_layout *pl, size_t i, int a, double tol)
{
    for (size_t j = 0; j < i; j++)
        if (pl[j].grid && pl[j].ax[a].lattice && interleaved(&pl[j].ax[a], &pl[i].ax[a], tol))
            return lattice_root(pl, j, a, tol);
    return i;
}

static int member_of(const pattern_layout *pl, size_t j, size_t r, int a, double tol)
{
    return j == r || (pl[j].grid && pl[j].ax[a].lattice && lattice_root(pl, j, a, tol) == r);
}

/* The set of patterns that follow pattern r's lattice along axis a, as pattern i sees it.
 * Members whose cells lie apart (each in its own place in the period: windows and their
 * mirror images) alternate when the member of rank q holds ceil((cells - q) / m) cells; a
 * set whose counts differ and do not alternate gives *ok = 0 (each pattern goes alone). */
static lattice_set lattice_set_of(const pattern_layout *pl, size_t n, size_t r, size_t i,
                                  int a, double tol, int *ok)
{
    lattice_set set = {.nb = pl[r].nb, .cont = pl[r].cont, .lo = pl[r].ax[a].o,
                       .hi = pl[r].ax[a].o};
    int differ = 0;
    double w = 0;
    for (size_t j = r; j < n; j++) {
        if (!member_of(pl, j, r, a, tol))
            continue;
        ag_box_extend_box(&set.nb, &pl[j].nb);
        ag_box_extend_box(&set.cont, &pl[j].cont);
        set.lo = fmin(set.lo, pl[j].ax[a].o);
        set.hi = fmax(set.hi, pl[j].ax[a].o);
        set.cells += pl[j].ax[a].n;
        differ |= pl[j].ax[a].n != pl[r].ax[a].n;
        w = fmax(w, pl[j].ax[a].w);
        set.m++;
    }
    *ok = !differ;
    if (set.m < 2 || set.m > LATTICE_SET_MAX)
        return set;
    int apart = 1, regular = 1;
    for (size_t j = r; j < n; j++) {
        if (!member_of(pl, j, r, a, tol))
            continue;
        size_t q = 0; /* its rank: the members whose first cell comes before */
        for (size_t h = r; h < n; h++)
            q += h != j && member_of(pl, h, r, a, tol) &&
                 (pl[h].ax[a].o < pl[j].ax[a].o || (pl[h].ax[a].o == pl[j].ax[a].o && h < j));
        set.d[q] = pl[j].ax[a].o - set.lo;
        regular = regular && pl[j].ax[a].n == member_cells(&set, set.cells, q);
        if (j == i)
            set.rank = q;
    }
    for (size_t q = 0; q < set.m; q++) {
        double next = q + 1 < set.m ? set.d[q + 1] : pl[r].ax[a].p;
        apart = apart && next - set.d[q] >= w - tol;
    }
    set.alternating = apart && regular;
    *ok = *ok || set.alternating;
    return set;
}

static void layout_patterns(lay *L, const int32_t *pats, size_t n, int depth)
{
    ag_splittree *t = L->nt;
    pattern_layout *pl = calloc(n + 1, sizeof *pl);
    if (!pl) {
        fail_nomem(L);
        return;
    }
    double tol = t->tol > 0 ? t->tol : L->eps;
    /* each pattern's old lattice, new box and holder */
    for (size_t i = 0; i < n; i++) {
        int32_t P = pats[i];
        pattern_layout *x = &pl[i];
        x->node = P;
        ag_box ob = oldb(L, P), nb = t->nodes[P].box;
        x->map = ag__resize_map_between(&ob, &nb);
        x->nb = nb;
        const ag_tnode *pn = &t->nodes[P];
        const ag_pattern *pp = pn->pattern >= 0 && (size_t)pn->pattern < t->npatterns
                                   ? &t->patterns[pn->pattern]
                                   : NULL;
        int32_t first = pn->first_child;
        size_t ncells = 0;
        for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling)
            ncells++;
        x->grid = pp && !pp->nvec && first >= 0 &&
                  ncells == (size_t)pp->counts[0] * pp->counts[1] * pp->counts[2];
        if (!x->grid)
            continue;
        /* what holds the pattern: its nearest visible ancestor (or the root), already laid out */
        int32_t holder = pn->parent;
        while (holder > 0 && t->nodes[holder].kind != AG_NODE_COMPONENT)
            holder = t->nodes[holder].parent;
        ag_box cont = holder >= 0 ? t->nodes[holder].box : nb;
        ag_box_extend_box(&cont, &nb); /* a pattern already past its holder keeps its own box */
        x->cont = cont;
        ag_box cb = oldb(L, first);
        double e[3], emax = 0;
        ag_box_extents(&cb, e);
        for (int a = 0; a < 3; a++)
            emax = fmax(emax, e[a]);
        for (int a = 0; a < 3; a++) {
            axis_layout *ax = &x->ax[a];
            ax->n = pp->counts[a] ? pp->counts[a] : 1;
            ax->k = ax->n;
            ax->w = e[a];
            ax->o = cb.min[a];
            x->thin[a] = e[a] < L->s->thin_ratio * emax;
            double span = ag_box_extent(&ob, a);
            ax->lattice = ax->n >= 2 && span > AG_EDIT_FLAT;
            if (!ax->lattice)
                continue;
            ax->p = (span - ax->w) / (ax->n - 1);
            ax->f = x->map.s[a];
            if (!(ax->p > AG_EDIT_FLAT) || !(ax->f > AG_EDIT_MIN_RATIO) || !isfinite(ax->f))
                ax->lattice = 0;
        }
    }
    /* the new lattices, a shared one from the pattern that leads it */
    for (size_t i = 0; i < n; i++) {
        if (!pl[i].grid)
            continue;
        for (int a = 0; a < 3; a++) {
            axis_layout *ax = &pl[i].ax[a];
            if (!ax->lattice)
                continue;
            size_t r = lattice_root(pl, i, a, tol);
            int ok;
            lattice_set set = lattice_set_of(pl, n, r, i, a, tol, &ok);
            if (!ok) { /* counts that differ and do not alternate: alone */
                r = i;
                set = (lattice_set){.nb = pl[i].nb, .cont = pl[i].cont, .lo = ax->o, .hi = ax->o};
            }
            layout_axis(L, ax, &pl[i].nb, &set, a, pl[i].thin[a], r < i ? &pl[r].ax[a] : NULL);
        }
    }
    for (size_t i = 0; i < n && !L->st; i++)
        place_cells(L, &pl[i], depth);
    free(pl);
}

/* ---- the whole layout -------------------------------------------------------------------- */

ag_status ag__resize_layout(const ag_edit_resize_solver *s, const ag_box *unit_boxes,
                            const ag_box *frame_box, int structural, ag_box *boxes,
                            ag_splittree **out, int32_t **source, ag_edit_report *rep,
                            ag_error *err)
{
    const ag_splittree *ot = s->in->tree;
    lay L = {.s = s, .ot = ot, .structural = structural, .err = err};
    L.eps = ag__resize_touch(ot, s->diag);
    /* a tree within the budget has at most three nodes per terminal (its split chain and a
     * pattern) besides the input's nodes, so a larger one is refused before it is made */
    L.max_nodes = LAYOUT_MAX_NODES(ot->nnodes);
    if (s->budget && s->budget->max_components &&
        ot->nnodes + 3 * s->budget->max_components + 16 < L.max_nodes)
        L.max_nodes = ot->nnodes + 3 * s->budget->max_components + 16;
    L.nt = ag_splittree_copy(ot);
    if (!L.nt || AG_ARRAY_RESERVE(L.src, L.cap_src, ot->nnodes + 1)) {
        ag_splittree_free(L.nt);
        free(L.src);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t n = 0; n < ot->nnodes; n++)
        L.src[n] = (int32_t)n;
    if (s->root)
        L.nt->nodes[0].box = *frame_box;
    layout_units(&L, s->level, s->nunits, unit_boxes, 0);
    free(L.walk);
    if (!L.st && ag_treeedit_span_invisible(L.nt))
        fail_nomem(&L);
    if (L.st) {
        ag_splittree_free(L.nt);
        free(L.src);
        return L.st;
    }
    if (boxes) {
        assert(L.nt->nnodes == ot->nnodes || structural);
        for (size_t n = 0; n < ot->nnodes; n++)
            boxes[n] = L.nt->nodes[n].box;
    }
    if (rep) {
        rep->splits += L.splits;
        rep->joins += L.joins;
    }
    if (out) {
        *out = L.nt;
        *source = L.src;
    } else {
        ag_splittree_free(L.nt);
        free(L.src);
    }
    return AG_OK;
}
