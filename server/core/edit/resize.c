/* The resize solver's life and the one-call resize; the phases are in resize_system.c,
 * resize_solve.c and resize_emit.c (see resize_internal.h). */
#include "resize.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "../base/tolerance.h"
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
    free(s->edit);
    free(s->edit_turn);
    free(s->slot);
    free(s->slot_node);
    free(s->va);
    ag_uf_free(&s->classes);
    free(s->fix);
    free(s->val);
    free(s->col);
    free(s->rows);
    free(s->hard);
    free(s->croot);
    free(s->coff);
    free(s->b0);
    free(s->trow);
    free(s->troot);
    free(s->tcoef);
    ag_lsq_free(s->lsq);
    free(s->b);
    free(s->x);
    free(s);
}

int ag_edit_resize_solver_matches(const ag_edit_resize_solver *s, const ag_edit_op *op)
{
    if (!s || op->kind != AG_EDIT_RESIZE || op->node != s->node || op->mode != s->mode ||
        !op->has_region != !s->has_region)
        return 0;
    return !s->has_region || !memcmp(&op->region, &s->region, sizeof op->region);
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
    s->diag = ag_box_diagonal(&t->nodes[0].box);
    /* the root or an invisible node: its subtree follows its box, nothing to solve */
    s->affine = t->nodes[op->node].kind != AG_NODE_COMPONENT;
    if (!s->affine && (st = ag__resize_system_build(s, op, err))) {
        ag_edit_resize_solver_free(s);
        return st;
    }
    *out = s;
    return AG_OK;
}

ag_status ag_edit_resize(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_edit_resize_solver *s;
    double t0 = ag_clock_ms();
    ag_status st = ag_edit_resize_solver_create(in, op, &s, err);
    if (st)
        return st;
    ag_box *boxes = malloc((in->tree->nnodes + 1) * sizeof *boxes);
    if (!boxes) {
        ag_edit_resize_solver_free(s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    st = ag_edit_resize_solver_solve(s, op, boxes, rep, err);
    if (rep)
        rep->solve_ms = ag_clock_ms() - t0; /* equations, factorization and solve */
    if (!st)
        st = ag_edit_resize_emit_ratio(in, boxes, op->split_ratio, op->thin_share, op->budget,
                                       out, rep, err);
    free(boxes);
    ag_edit_resize_solver_free(s);
    return st;
}
