/* The resize solver's life (its units and the system of the edited level), the edited level's
 * solve, and the one-call resizes; the system's phases are in resize_system.c, the layout
 * below the edited level in resize_layout.c (see resize_internal.h). */
#include "resize.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "../base/tolerance.h"
#include "rebuild.h"
#include "resize_internal.h"

int32_t ag__resize_visible_ancestor(const ag_splittree *t, int32_t n)
{
    assert(n >= 0 && (size_t)n < t->nnodes);
    for (int32_t p = t->nodes[n].parent; p >= 0; p = t->nodes[p].parent)
        if (t->nodes[p].kind == AG_NODE_COMPONENT)
            return p;
    return 0;
}

ag_status ag__resize_target(const ag_proceduralize_result *in, const ag_edit_op *op, ag_box *t,
                            ag_error *err)
{
    const ag_box *old = &in->tree->nodes[op->node].box;
    if (op->has_box) {
        *t = op->box;
    } else if (op->has_scale) {
        for (int a = 0; a < 3; a++) {
            if (!(op->scale[a] > 0) || !isfinite(op->scale[a]))
                return ag_error_set(err, AG_ERR_INVALID, 0, "scale: must be positive");
            t->min[a] = old->min[a];
            t->max[a] = old->min[a] + ag_box_extent(old, a) * op->scale[a];
        }
    } else {
        return ag_error_set(err, AG_ERR_INVALID, 0, "box: a resize needs a box or a scale");
    }
    for (int a = 0; a < 3; a++) {
        if (!isfinite(t->min[a]) || !isfinite(t->max[a]))
            return ag_error_set(err, AG_ERR_INVALID, 0, "box: not finite");
        if (t->max[a] < t->min[a])
            return ag_error_set(err, AG_ERR_INVALID, 0, "box: min exceeds max on %c",
                                "xyz"[a]);
    }
    return AG_OK;
}

ag__resize_map ag__resize_map_between(const ag_box *from, const ag_box *to)
{
    ag__resize_map m;
    for (int a = 0; a < 3; a++) {
        double w = ag_box_extent(from, a), w2 = ag_box_extent(to, a);
        m.s[a] = w > AG_EDIT_FLAT ? w2 / w : 1;
        m.t[a] = to->min[a] - m.s[a] * from->min[a];
        if (!(w > AG_EDIT_FLAT)) /* a flat axis lands on the centre of `to` */
            m.t[a] = ag_box_centre_axis(to, a) - from->min[a];
    }
    return m;
}

ag_box ag__resize_map_box(const ag__resize_map *m, const ag_box *b)
{
    ag_box r;
    for (int a = 0; a < 3; a++) {
        r.min[a] = m->s[a] * b->min[a] + m->t[a];
        r.max[a] = m->s[a] * b->max[a] + m->t[a];
    }
    return r;
}

void ag_edit_resize_solver_free(ag_edit_resize_solver *s)
{
    if (!s)
        return;
    ag__resize_units_free(&s->units);
    ag__resize_system_free(&s->sys);
    free(s->edit);
    free(s->edit_turn);
    free(s->edit_mirror);
    free(s->level);
    free(s->held);
    free(s->old);
    free(s);
}

int ag_edit_resize_solver_matches(const ag_edit_resize_solver *s, const ag_edit_op *op)
{
    if (!s || op->kind != AG_EDIT_RESIZE || op->node != s->node || op->mode != s->mode ||
        !op->has_region != !s->has_region)
        return 0;
    return !s->has_region || !memcmp(&op->region, &s->region, sizeof op->region);
}

/* The labeling's record of component c (label.h): a mirror image of its label's exemplar
 * (x -> -x in the exemplar's frame) and the quarter turns after that; 0 for a component the
 * labels do not hold. */
static int label_mirror(const ag_labels *L, int32_t c, int *turns)
{
    *turns = 0;
    if (!L || c < 0 || (size_t)c >= L->ncomponents)
        return 0;
    *turns = L->rot ? L->rot[c] & 3 : 0;
    return L->mirror ? L->mirror[c] != 0 : 0;
}

/* The edited units: the op's node (a split node stands for the node its chain ends in), and in
 * global mode every visible node of its rule with the quarter turns from the op's node to it,
 * and every mirror image of it: a node of its label of the other hand (a handed window's twin
 * is another rule of the same label, so only the labeling knows them for one element). The
 * labeling records a member as its label's exemplar E mirrored or not, then turned: R^a M^p E
 * (M: x -> -x). For the op's node R^a M^p E and a member R^b M^q E with q != p, the member is
 * R^b M^q (R^a M^p)^-1 = R^(a+b) M applied to the op's node: its change is the op's node's
 * reflected along x, then turned a + b quarter turns. */
static void gather_edited(ag_edit_resize_solver *s, const ag_edit_op *op)
{
    const ag_splittree *t = s->in->tree;
    const ag_labels *L = s->in->labels;
    int32_t n = op->node;
    if (t->nodes[n].kind == AG_NODE_SPLIT)
        n = ag_splittree_chain_end(t, n);
    s->edit[s->nedit] = n;
    s->edit_mirror[s->nedit] = 0;
    s->edit_turn[s->nedit++] = 0;
    const ag_tnode *en = &t->nodes[n];
    if (op->mode != AG_EDIT_GLOBAL || en->kind != AG_NODE_COMPONENT || en->rule < 0)
        return;
    int ea, ep = label_mirror(L, en->component, &ea);
    for (size_t k = 0; k < t->nnodes; k++) {
        const ag_tnode *x = &t->nodes[k];
        if ((int32_t)k == n || x->kind != AG_NODE_COMPONENT)
            continue;
        int xb = 0, xq = x->label >= 0 && x->label == en->label
                             ? label_mirror(L, x->component, &xb)
                             : ep; /* another label: never a mirror image */
        if (x->rule == en->rule) {
            s->edit_mirror[s->nedit] = 0;
            s->edit_turn[s->nedit] = (x->rule_rot - en->rule_rot) & 3;
        } else if (xq != ep) {
            s->edit_mirror[s->nedit] = 1;
            s->edit_turn[s->nedit] = (ea + xb) & 3;
        } else {
            continue;
        }
        s->edit[s->nedit++] = (int32_t)k;
    }
}

/* Does b hold the region on two axes or more (a wall or slab the edited element stands on or
 * in)? A local edit happens on such a unit, which the edited element does not pull along. */
static int holds_region(const ag_box *b, const ag_box *region, double eps)
{
    int axes = 0;
    for (int a = 0; a < 3; a++)
        axes += b->min[a] <= region->min[a] + eps && b->max[a] >= region->max[a] - eps;
    return axes >= 2;
}

/* The units of the edited level, breadth-first from the edited units over the adjacency of
 * units with the same nearest visible ancestor (the edited root: every unit right below it);
 * local mode keeps only units meeting the region (given, or the edited node's old and new
 * boxes); those holding it (the wall behind a window) are held: no ratio to an edited unit
 * moves them. */
static ag_status edited_level(ag_edit_resize_solver *s, const ag_edit_op *op, ag_error *err)
{
    const ag_splittree *t = s->in->tree;
    const ag__resize_units *u = &s->units;
    size_t nn = t->nnodes;
    double eps = ag__resize_touch(t, s->diag);
    ag_box region = op->region;
    if (op->mode == AG_EDIT_LOCAL && !op->has_region) {
        ag_box tb;
        ag_status st = ag__resize_target(s->in, op, &tb, err);
        if (st)
            return st;
        region = t->nodes[op->node].box;
        ag_box_extend_box(&region, &tb);
    }
    int32_t *slot = malloc((nn + 1) * sizeof *slot);
    uint8_t *peer = calloc(nn + 1, 1);
    s->level = malloc((nn + 1) * sizeof *s->level);
    s->held = calloc(nn + 1, 1);
    s->old = malloc((nn + 1) * sizeof *s->old);
    if (!slot || !peer || !s->level || !s->held || !s->old) {
        free(slot);
        free(peer);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t n = 0; n < nn; n++)
        slot[n] = -1;
    if (s->root) {
        for (size_t n = 1; n < nn; n++)
            if (u->unit[n] == (int32_t)n && u->va[n] == 0 &&
                (op->mode != AG_EDIT_LOCAL || ag_box_meets(&t->nodes[n].box, &region, eps))) {
                slot[n] = (int32_t)s->nunits;
                s->level[s->nunits++] = (int32_t)n;
            }
    } else {
        for (size_t e = 0; e < s->nedit; e++) {
            int32_t n = s->edit[e];
            peer[u->va[n]] = 1;
            if (slot[n] < 0) {
                slot[n] = (int32_t)s->nunits;
                s->level[s->nunits++] = n;
            }
        }
        for (size_t q = 0; q < s->nunits; q++) {
            int32_t a = s->level[q];
            for (uint32_t k = u->adj_start[a]; k < u->adj_start[a + 1]; k++) {
                int32_t v = (int32_t)u->adj_list[k];
                if (slot[v] >= 0 || !peer[u->va[v]])
                    continue;
                if (op->mode == AG_EDIT_LOCAL && !ag_box_meets(&t->nodes[v].box, &region, eps))
                    continue;
                if (op->mode == AG_EDIT_LOCAL && holds_region(&t->nodes[v].box, &region, eps))
                    s->held[s->nunits] = 1;
                slot[v] = (int32_t)s->nunits;
                s->level[s->nunits++] = v;
            }
        }
    }
    for (size_t q = 0; q < s->nunits; q++)
        s->old[q] = t->nodes[s->level[q]].box;
    free(slot);
    free(peer);
    return AG_OK;
}

double ag__resize_touch(const ag_splittree *t, double diag)
{
    double eps = t->eps > 0 ? t->eps : AG_EDIT_COINCIDENT * (diag > 0 ? diag : 1);
    return fmax(eps, t->tol);
}

ag_status ag_edit_resize_solver_create(const ag_proceduralize_result *in, const ag_edit_op *op,
                                       ag_edit_resize_solver **out, ag_error *err)
{
    *out = NULL;
    ag_status st = ag_edit_check_node(in, op->node, "node", err);
    if (st)
        return st;
    const ag_splittree *t = in->tree;
    ag_edit_resize_solver *s = calloc(1, sizeof *s);
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    s->in = in;
    s->node = op->node;
    s->mode = op->mode;
    s->has_region = op->has_region;
    s->region = op->region;
    s->split_ratio = op->split_ratio > 1 ? op->split_ratio : AG_EDIT_SPLIT_RATIO;
    s->join_ratio = 1.0 / s->split_ratio;
    s->thin_ratio = op->thin_share > 0 ? op->thin_share : AG_EDIT_THIN_RATIO;
    s->diag = ag_box_diagonal(&t->nodes[0].box);
    s->root = op->node == AG_EDIT_ROOT;
    s->frame_node = -1;
    s->edit = malloc((t->nnodes + 1) * sizeof *s->edit);
    s->edit_turn = malloc((t->nnodes + 1) * sizeof *s->edit_turn);
    s->edit_mirror = malloc(t->nnodes + 1);
    if (!s->edit || !s->edit_turn || !s->edit_mirror) {
        ag_edit_resize_solver_free(s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (!s->root)
        gather_edited(s, op);
    if ((st = ag__resize_units_build(&s->units, t, s->edit, s->nedit, err)) ||
        (st = edited_level(s, op, err))) {
        ag_edit_resize_solver_free(s);
        return st;
    }
    ag__resize_spec spec = {.nunits = s->nunits,
                            .units = s->level,
                            .nedit = s->nedit,
                            .frame_node = -1,
                            .outside = 1,
                            .old = s->old,
                            .held = s->held};
    if (s->root) {
        spec.frame = AG__FRAME_TARGETED;
        spec.frame_old = spec.frame_new = t->nodes[0].box;
        spec.frame_node = 0;
        s->frame_node = 0;
    } else {
        /* one visible ancestor for every edited unit: the level lies in it, unchanged */
        int32_t va = s->units.va[s->edit[0]];
        for (size_t e = 1; e < s->nedit && va > 0; e++)
            if (s->units.va[s->edit[e]] != va)
                va = 0;
        if (va > 0) {
            spec.frame = AG__FRAME_FIXED;
            spec.frame_old = spec.frame_new = t->nodes[va].box;
            spec.frame_node = va;
            s->frame_node = va;
        }
    }
    if ((st = ag__resize_system_build(&s->sys, in, &s->units, &spec, err))) {
        ag_edit_resize_solver_free(s);
        return st;
    }
    *out = s;
    return AG_OK;
}

/* Reflects box deltas (dmin, dmax) along x when mirror is set, then turns them by k quarter
 * turns about +z: a mirror image's min side moves as the original's max side does. */
static void turn_delta(int k, int mirror, double dmin[3], double dmax[3])
{
    if (mirror) {
        double x0 = -dmax[0];
        dmax[0] = -dmin[0];
        dmin[0] = x0;
    }
    for (int i = 0; i < (k & 3); i++) {
        double nx0 = -dmax[1], nx1 = -dmin[1], ny0 = dmin[0], ny1 = dmax[0];
        dmin[0] = nx0;
        dmax[0] = nx1;
        dmin[1] = ny0;
        dmax[1] = ny1;
    }
}

ag_status ag__resize_solve_level(ag_edit_resize_solver *s, const ag_edit_op *op,
                                 ag_box *unit_boxes, ag_box *frame_box, ag_edit_report *rep,
                                 ag_error *err)
{
    const ag_splittree *t = s->in->tree;
    ag_box target;
    ag_status st = ag__resize_target(s->in, op, &target, err);
    if (st)
        return st;
    ag_box *targets = malloc((s->nedit + 1) * sizeof *targets);
    ag_box *boxes = malloc((s->sys.nslots + 1) * sizeof *boxes);
    if (!targets || !boxes) {
        free(targets);
        free(boxes);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (!s->root) {
        /* every edited unit moves as the op's node does (turned with it); a split node's target
         * carries the node its chain ends in along */
        ag_box opold = t->nodes[op->node].box;
        ag_box head = target;
        if (t->nodes[op->node].kind == AG_NODE_SPLIT) {
            ag__resize_map m = ag__resize_map_between(&opold, &target);
            opold = t->nodes[s->edit[0]].box;
            head = ag__resize_map_box(&m, &opold);
        }
        double dmin[3], dmax[3];
        for (int a = 0; a < 3; a++) {
            dmin[a] = head.min[a] - opold.min[a];
            dmax[a] = head.max[a] - opold.max[a];
        }
        for (size_t e = 0; e < s->nedit; e++) {
            int32_t n = s->edit[e];
            ag_box tb = t->nodes[n].box;
            double d0[3], d1[3];
            memcpy(d0, dmin, sizeof d0);
            memcpy(d1, dmax, sizeof d1);
            turn_delta(s->edit_turn[e], s->edit_mirror[e], d0, d1);
            for (int a = 0; a < 3; a++) {
                tb.min[a] += d0[a];
                tb.max[a] += d1[a];
                if (tb.max[a] < tb.min[a])
                    tb.max[a] = tb.min[a];
            }
            int32_t va = s->units.va[n];
            if (va > 0)
                ag_box_clamp(&tb, &t->nodes[va].box);
            targets[e] = tb;
        }
    }
    double res = 0;
    st = ag__resize_system_solve(&s->sys, s->nedit, targets, &target, boxes, &res, err);
    if (!st) {
        for (size_t q = 0; q < s->nunits; q++) {
            ag_box b = boxes[q];
            int32_t va = s->units.va[s->level[q]];
            if (va > 0) /* a window never leaves its wall */
                ag_box_clamp(&b, &t->nodes[va].box);
            else if (s->root)
                ag_box_clamp(&b, &target);
            unit_boxes[q] = b;
        }
        *frame_box = s->root ? target : s->sys.frame ? boxes[s->nunits] : t->nodes[0].box;
        if (rep) {
            rep->equations = s->sys.nrows;
            rep->unknowns = s->sys.ncols;
            rep->max_residual = res;
            rep->max_residual_rel = s->diag > 0 ? res / s->diag : 0;
        }
    }
    free(targets);
    free(boxes);
    return st;
}

ag_status ag_edit_resize_solver_solve(ag_edit_resize_solver *s, const ag_edit_op *op,
                                      ag_box *boxes, ag_edit_report *rep, ag_error *err)
{
    double t0 = ag_clock_ms();
    ag_box *ub = malloc((s->nunits + 1) * sizeof *ub), frame;
    if (!ub)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = ag__resize_solve_level(s, op, ub, &frame, rep, err);
    if (!st)
        st = ag__resize_layout(s, ub, &frame, 0, boxes, NULL, NULL, NULL, err);
    free(ub);
    if (rep)
        rep->solve_ms = ag_clock_ms() - t0;
    return st;
}

/* What the edited tree would place, against the op's budget: refused before it is made. */
static ag_status check_budget(const ag_proceduralize_result *in, const ag_splittree *t,
                              const int32_t *source, const ag_edit_budget *b, ag_error *err)
{
    size_t max_tris = AG_EDIT_MAX_TRIANGLES, max_comps = SIZE_MAX;
    if (b && b->max_triangles && b->max_triangles < max_tris)
        max_tris = b->max_triangles;
    if (b && b->max_components)
        max_comps = b->max_components;
    const ag_labels *L = in->labels;
    size_t ncomps = 0, ntris = 0;
    for (size_t n = 0; n < t->nnodes; n++) {
        if (t->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        int32_t oc = in->tree->nodes[source[n]].component;
        if (oc < 0 || (size_t)oc >= L->ncomponents)
            continue;
        ncomps++;
        ntris += L->tri_start[oc + 1] - L->tri_start[oc];
    }
    if (ncomps > max_comps)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "resize: the result would place more than %zu terminals, the most "
                            "this server takes",
                            max_comps);
    if (ntris > max_tris)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "resize: the result would have more than %zu triangles, the most "
                            "this server takes",
                            max_tris);
    if (ag_edit_budget_cancelled(b))
        return ag_error_set(err, AG_ERR_CANCELLED, 0, "resize: stopped");
    return AG_OK;
}

static void shift_box(ag_box *b, const double d[3])
{
    for (int a = 0; a < 3; a++) {
        b->min[a] += d[a];
        b->max[a] += d[a];
    }
}

static ag_status resize_tree_at_origin(const ag_proceduralize_result *in, const ag_edit_op *op,
                                       ag_splittree **tree, int32_t **source,
                                       ag_edit_report *rep, ag_error *err);

/* Far from the origin (UTM coordinates) the least squares would lose the digits a window's
 * size lives in: the resize runs on the tree moved so that its root's min corner is the
 * origin (every equation is one of differences, sizes or positions, so it moves with it), and
 * the result moves back. */
ag_status ag_edit_resize_tree(const ag_proceduralize_result *in, const ag_edit_op *op,
                              ag_splittree **tree, int32_t **source, ag_edit_report *rep,
                              ag_error *err)
{
    *tree = NULL;
    *source = NULL;
    double back[3], to[3];
    for (int a = 0; a < 3; a++) {
        back[a] = in->tree->nodes[0].box.min[a];
        to[a] = -back[a];
    }
    ag_splittree *moved = ag_splittree_copy(in->tree);
    if (!moved)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t n = 0; n < moved->nnodes; n++)
        shift_box(&moved->nodes[n].box, to);
    ag_proceduralize_result at = *in;
    at.tree = moved;
    ag_edit_op mop = *op;
    shift_box(&mop.box, to);
    shift_box(&mop.region, to);
    ag_status st = resize_tree_at_origin(&at, &mop, tree, source, rep, err);
    if (!st)
        for (size_t n = 0; n < (*tree)->nnodes; n++)
            shift_box(&(*tree)->nodes[n].box, back);
    ag_splittree_free(moved);
    return st;
}

static ag_status resize_tree_at_origin(const ag_proceduralize_result *in, const ag_edit_op *op,
                                       ag_splittree **tree, int32_t **source,
                                       ag_edit_report *rep, ag_error *err)
{
    ag_edit_resize_solver *s;
    double t0 = ag_clock_ms();
    ag_status st = ag_edit_resize_solver_create(in, op, &s, err);
    if (st)
        return st;
    ag_box *ub = malloc((s->nunits + 1) * sizeof *ub), frame;
    if (!ub) {
        ag_edit_resize_solver_free(s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    st = ag__resize_solve_level(s, op, ub, &frame, rep, err);
    if (rep)
        rep->solve_ms = ag_clock_ms() - t0; /* equations, factorization and solve */
    s->budget = op->budget;
    if (!st)
        st = ag__resize_layout(s, ub, &frame, 1, NULL, tree, source, rep, err);
    if (!st && (st = check_budget(in, *tree, *source, op->budget, err))) {
        ag_splittree_free(*tree);
        free(*source);
        *tree = NULL;
        *source = NULL;
    }
    free(ub);
    ag_edit_resize_solver_free(s);
    return st;
}

ag_status ag_edit_resize(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_splittree *tree = NULL;
    int32_t *source = NULL;
    ag_status st = ag_edit_resize_tree(in, op, &tree, &source, rep, err);
    if (!st)
        st = ag_rebuild_mesh(in, tree, source, out, err);
    ag_splittree_free(tree);
    free(source);
    return st;
}
