/* The solve of a built resize system for one target (a drag solves again and again with the
 * factorization kept): target values, right-hand side and least squares, the boxes of the
 * unknowns, then the boxes of every other node derived from them. */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "resize_internal.h"

/* Turns box deltas (dmin, dmax) by k quarter turns about +z. */
static void turn_delta(int k, double dmin[3], double dmax[3])
{
    for (int i = 0; i < (k & 3); i++) {
        double nx0 = -dmax[1], nx1 = -dmin[1], ny0 = dmin[0], ny1 = dmax[0];
        dmin[0] = nx0;
        dmax[0] = nx1;
        dmin[1] = ny0;
        dmax[1] = ny1;
    }
}

/* Boxes of nodes that are not unknowns: mapped with their parent (top-down), then the
 * invisible nodes above a moved node span their children again (bottom-up). */
static void derive_boxes(const ag_splittree *t, ag_box *boxes, const uint8_t *set)
{
    size_t nn = t->nnodes;
    int32_t *stack = malloc((nn + 1) * sizeof *stack);
    int32_t *order = malloc((nn + 1) * sizeof *order);
    if (!stack || !order) {
        free(stack);
        free(order);
        return;
    }
    size_t sp = 0, no = 0;
    stack[sp++] = 0;
    while (sp) {
        int32_t n = stack[--sp];
        assert(no < nn); /* a tree: every node is reached once */
        order[no++] = n;
        const ag_tnode *x = &t->nodes[n];
        if (x->first_child < 0)
            continue;
        ag__resize_map m = ag__resize_map_between(&x->box, &boxes[n]);
        for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling) {
            if (!set[c])
                boxes[c] = ag__resize_map_box(&m, &t->nodes[c].box);
            stack[sp++] = c;
        }
    }
    for (size_t i = no; i-- > 0;) {
        int32_t n = order[i];
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_COMPONENT || x->first_child < 0 || set[n])
            continue;
        ag_box u = boxes[x->first_child];
        for (int32_t c = t->nodes[x->first_child].next_sibling; c >= 0;
             c = t->nodes[c].next_sibling)
            ag_box_extend_box(&u, &boxes[c]);
        if (n == 0 || x->kind == AG_NODE_SPLIT || x->kind == AG_NODE_PATTERN)
            boxes[n] = u;
    }
    free(stack);
    free(order);
}

/* The root or an invisible node: its subtree follows its box (kept inside its visible
 * ancestor), no solve. */
static void solve_affine(const ag_edit_resize_solver *s, const ag_edit_op *op, ag_box target,
                         ag_box *boxes, uint8_t *set)
{
    const ag_splittree *t = s->in->tree;
    if (op->node != 0) {
        int32_t va = ag__resize_visible_ancestor(t, op->node);
        if (va > 0)
            ag_box_clamp(&target, &t->nodes[va].box);
    }
    boxes[op->node] = target;
    set[op->node] = 1;
    derive_boxes(t, boxes, set);
}

/* The target classes' values: every edited node moves as the op's node does (turned with
 * it), kept inside its nearest visible ancestor. */
static void set_targets(ag_edit_resize_solver *s, const ag_edit_op *op, const ag_box *target)
{
    const ag_splittree *t = s->in->tree;
    const ag_box *old = &t->nodes[op->node].box;
    double dmin[3], dmax[3];
    for (int a = 0; a < 3; a++) {
        dmin[a] = target->min[a] - old->min[a];
        dmax[a] = target->max[a] - old->max[a];
    }
    for (size_t e = 0; e < s->nedit; e++) {
        int32_t n = s->edit[e];
        ag_box tb = t->nodes[n].box;
        double d0[3], d1[3];
        memcpy(d0, dmin, sizeof d0);
        memcpy(d1, dmax, sizeof d1);
        turn_delta(s->edit_turn[e], d0, d1);
        for (int a = 0; a < 3; a++) {
            tb.min[a] += d0[a];
            tb.max[a] += d1[a];
            if (tb.max[a] < tb.min[a])
                tb.max[a] = tb.min[a];
        }
        if (s->va[n] > 0)
            ag_box_clamp(&tb, &t->nodes[s->va[n]].box);
        uint32_t base = 6 * (uint32_t)s->slot[n];
        for (int c = 0; c < 6; c++)
            s->val[base + c] = ag_box_coord(&tb, c); /* targets are roots */
    }
}

/* The value of every coordinate of the area (into xv, 6 * nslots) for the current targets. */
static ag_status solve_coordinates(ag_edit_resize_solver *s, double *xv, ag_error *err)
{
    memcpy(s->b, s->b0, s->nrows * sizeof *s->b);
    for (size_t k = 0; k < s->nterms_t; k++)
        s->b[s->trow[k]] -= s->tcoef[k] * s->val[s->troot[k]];
    ag_status st;
    if (s->lsq && (st = ag_lsq_solve(s->lsq, s->b, s->x, err)))
        return st;
    size_t nc = 6 * s->nslots;
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = s->croot[i];
        xv[i] = (s->fix[r] ? s->val[r] : s->x[s->col[r]]) + s->coff[i];
    }
    return AG_OK;
}

/* How far the solution is from the hard equalities (0 when they all hold). */
static double hard_residual(const ag_edit_resize_solver *s, const double *xv)
{
    double maxres = 0;
    for (size_t h = 0; h < s->nhard; h++) {
        const ag__resize_hard *q = &s->hard[h];
        double other = q->other_coord == AG__RESIZE_CONST    ? q->d
                       : q->other_coord == AG__RESIZE_TARGET ? s->val[q->coord]
                                                             : xv[q->other_coord] + q->d;
        double r = fabs(xv[q->coord] - other);
        if (r > maxres)
            maxres = r;
    }
    return maxres;
}

/* The unknowns' boxes from their coordinates: a flip collapses rather than inverts, and a
 * box stays inside its nearest visible ancestor. */
static void unknown_boxes(const ag_edit_resize_solver *s, const double *xv, ag_box *boxes,
                          uint8_t *set)
{
    const ag_splittree *t = s->in->tree;
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t n = s->slot_node[q];
        ag_box b;
        for (int c = 0; c < 6; c++)
            ag_box_set_coord(&b, c, xv[6 * q + c]);
        for (int a = 0; a < 3; a++)
            if (b.max[a] < b.min[a]) {
                double mid = ag_box_centre_axis(&b, a);
                b.min[a] = b.max[a] = mid;
            }
        if (s->va[n] > 0)
            ag_box_clamp(&b, &t->nodes[s->va[n]].box);
        boxes[n] = b;
        set[n] = 1;
    }
}

ag_status ag_edit_resize_solver_solve(ag_edit_resize_solver *s, const ag_edit_op *op,
                                      ag_box *boxes, ag_edit_report *rep, ag_error *err)
{
    const ag_splittree *t = s->in->tree;
    size_t nn = t->nnodes;
    double t0 = ag_clock_ms();
    ag_box target;
    ag_status st = ag__resize_target(s->in, op, &target, err);
    if (st)
        return st;
    uint8_t *set = calloc(nn, 1);
    if (!set)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t n = 0; n < nn; n++)
        boxes[n] = t->nodes[n].box;
    if (s->affine) {
        solve_affine(s, op, target, boxes, set);
        free(set);
        if (rep) {
            rep->equations = rep->unknowns = 0;
            rep->solve_ms = ag_clock_ms() - t0;
            rep->max_residual = rep->max_residual_rel = 0;
        }
        return AG_OK;
    }
    set_targets(s, op, &target);
    double *xv = malloc(6 * s->nslots * sizeof *xv + 1); /* every coordinate's value */
    if (!xv) {
        free(set);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if ((st = solve_coordinates(s, xv, err))) {
        free(xv);
        free(set);
        return st;
    }
    double maxres = hard_residual(s, xv);
    unknown_boxes(s, xv, boxes, set);
    derive_boxes(t, boxes, set);
    free(xv);
    free(set);
    if (rep) {
        rep->equations = s->nrows;
        rep->unknowns = s->ncols;
        rep->solve_ms = ag_clock_ms() - t0;
        rep->max_residual = maxres;
        rep->max_residual_rel = s->diag > 0 ? maxres / s->diag : 0;
    }
    return AG_OK;
}
