/* System assembly of a resize, in named phases run in this order by ag__resize_system_build:
 *
 *   gather_nodes       the edited nodes, the area of effect (its nodes get slots: they are the
 *                      unknowns) and the nodes moving with it (their descendants)
 *   add_targets        the edited nodes' coordinates become target classes
 *   add_attachments    ground and shared coordinates (hard: merged into classes), overlap
 *                      ratios between adjacent nodes (soft rows)
 *   add_size_terms     size where an axis is attached at one end only, position everywhere
 *   factorize          free classes become columns; rows without a free term are dropped;
 *                      the matrix is factorized (its structure only: targets are not in it)
 *   add_target_terms   each row's right-hand side split into its fixed part and the terms on
 *                      target classes, so a solve for new targets does no lookups
 *
 * A phase reads what the earlier ones built (the solver, and the scratch of `build`) and
 * adds its own part; changing what one phase does leaves the others as they are. */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "attach.h"
#include "resize_internal.h"

/* Scratch of the assembly, freed once the system is built. */
typedef struct {
    const ag_splittree *t;
    double eps;          /* coincidence of box faces */
    uint8_t *peer_level; /* per node: the edited nodes' nearest visible ancestors */
    uint8_t *moving;     /* per node: in the area of effect or below a node in it */
    uint32_t *adj_start; /* adjacency of visible nodes, CSR: nnodes + 1 offsets */
    uint32_t *adj_list;
} build;

static void build_free(build *b)
{
    free(b->peer_level);
    free(b->moving);
    free(b->adj_start);
    free(b->adj_list);
}

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

static ag_status add_hard(ag_edit_resize_solver *s, uint32_t coord, uint32_t other, double d)
{
    ag_status st = AG_ARRAY_RESERVE(s->hard, s->cap_hard, s->nhard + 1);
    if (st)
        return st;
    s->hard[s->nhard++] = (ag__resize_hard){coord, other, d};
    return AG_OK;
}

static ag__resize_row *new_row(ag_edit_resize_solver *s)
{
    assert(s->nrows < s->cap_rows); /* cap_rows bounds every row the phases add */
    return &s->rows[s->nrows++];
}

/* Ties coordinates i and j: value(i) - value(j) = d. A target class keeps its root, then a
 * fixed one (their values are stored at the root); two targets both stay (the equality is
 * only checked afterwards). */
static void tie(ag_edit_resize_solver *s, uint32_t i, uint32_t j, double d)
{
    uint32_t ri = ag_uf_find(&s->classes, i), rj = ag_uf_find(&s->classes, j);
    if (ri == rj)
        return;
    double rel = ag_uf_offset(&s->classes, j) + d - ag_uf_offset(&s->classes, i); /* ri - rj */
    if (s->fix[ri] == AG__RESIZE_TARGETED && s->fix[rj] == AG__RESIZE_TARGETED)
        return;
    if (s->fix[ri] == AG__RESIZE_TARGETED ||
        (s->fix[ri] == AG__RESIZE_FIXED && s->fix[rj] != AG__RESIZE_TARGETED))
        ag_uf_link(&s->classes, rj, ri, -rel);
    else
        ag_uf_link(&s->classes, ri, rj, rel);
}

/* Fixes coordinate i's class to value(i) = v, unless it is fixed or targeted already. */
static void fix_const(ag_edit_resize_solver *s, uint32_t i, double v)
{
    uint32_t r = ag_uf_find(&s->classes, i);
    if (s->fix[r])
        return;
    s->fix[r] = AG__RESIZE_FIXED;
    s->val[r] = v - ag_uf_offset(&s->classes, i);
}

static uint32_t coord_id(size_t slot, int c)
{
    return 6 * (uint32_t)slot + (uint32_t)c;
}

/* ---- gather nodes ------------------------------------------------------------------------ */

/* The edited nodes: the op's node, and in global mode every visible node of its rule (with
 * the quarter turns from the op's node to it). */
static void gather_edited(ag_edit_resize_solver *s, build *b, const ag_edit_op *op)
{
    const ag_splittree *t = b->t;
    const ag_tnode *en = &t->nodes[op->node];
    s->edit[s->nedit] = op->node;
    s->edit_turn[s->nedit++] = 0;
    if (op->mode == AG_EDIT_GLOBAL && en->rule >= 0) {
        for (size_t n = 0; n < t->nnodes; n++) {
            const ag_tnode *x = &t->nodes[n];
            if ((int32_t)n == op->node || x->kind != AG_NODE_COMPONENT || x->rule != en->rule)
                continue;
            s->edit[s->nedit] = (int32_t)n;
            s->edit_turn[s->nedit++] = (x->rule_rot - en->rule_rot) & 3;
        }
    }
    for (size_t e = 0; e < s->nedit; e++)
        b->peer_level[s->va[s->edit[e]]] = 1;
}

/* The tree's adjacency pairs as lists per node (CSR). */
static ag_status adjacency_lists(build *b)
{
    const ag_splittree *t = b->t;
    size_t nn = t->nnodes;
    for (size_t k = 0; k < t->nadj; k++) {
        b->adj_start[t->adj[2 * k] + 1]++;
        b->adj_start[t->adj[2 * k + 1] + 1]++;
    }
    for (size_t n = 0; n < nn; n++)
        b->adj_start[n + 1] += b->adj_start[n];
    uint32_t *fill = malloc((nn + 1) * sizeof *fill);
    if (!fill)
        return AG_ERR_NOMEM;
    memcpy(fill, b->adj_start, (nn + 1) * sizeof *fill);
    for (size_t k = 0; k < t->nadj; k++) {
        uint32_t u = t->adj[2 * k], v = t->adj[2 * k + 1];
        b->adj_list[fill[u]++] = v;
        b->adj_list[fill[v]++] = u;
    }
    free(fill);
    return AG_OK;
}

/* The area of effect, breadth-first from the edited nodes over the adjacency of visible nodes
 * with the same nearest visible ancestor; local mode keeps only nodes meeting the region
 * (given, or the edited node's old and new boxes). Slot order is queue order. */
static ag_status area_of_effect(ag_edit_resize_solver *s, build *b, const ag_edit_op *op,
                                ag_error *err)
{
    const ag_splittree *t = b->t;
    ag_box region = op->region;
    if (op->mode == AG_EDIT_LOCAL && !op->has_region) {
        ag_box tb;
        ag_status st = ag__resize_target(s->in, op, &tb, err);
        if (st)
            return st;
        region = t->nodes[op->node].box;
        ag_box_extend_box(&region, &tb);
    }
    for (size_t e = 0; e < s->nedit; e++) {
        int32_t n = s->edit[e];
        if (s->slot[n] < 0) {
            s->slot[n] = (int32_t)s->nslots;
            s->slot_node[s->nslots++] = n;
        }
    }
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t u = s->slot_node[q];
        for (uint32_t k = b->adj_start[u]; k < b->adj_start[u + 1]; k++) {
            int32_t v = (int32_t)b->adj_list[k];
            const ag_tnode *x = &t->nodes[v];
            if (s->slot[v] >= 0 || x->kind != AG_NODE_COMPONENT || !b->peer_level[s->va[v]])
                continue;
            if (op->mode == AG_EDIT_LOCAL && !ag_box_meets(&x->box, &region, b->eps))
                continue;
            s->slot[v] = (int32_t)s->nslots;
            s->slot_node[s->nslots++] = v;
        }
    }
    return AG_OK;
}

/* Moving: in the area or below a node in it (those below are re-derived, not unknowns). */
static void mark_moving(const ag_edit_resize_solver *s, build *b)
{
    const ag_splittree *t = b->t;
    for (size_t n = 1; n < t->nnodes; n++) {
        /* parents precede children in index order only for the build; walk up instead */
        for (int32_t p = (int32_t)n; p > 0; p = t->nodes[p].parent)
            if (s->slot[p] >= 0) {
                b->moving[n] = 1;
                break;
            }
    }
}

static ag_status gather_nodes(ag_edit_resize_solver *s, build *b, const ag_edit_op *op,
                              ag_error *err)
{
    const ag_splittree *t = b->t;
    size_t nn = t->nnodes;
    s->slot = malloc(nn * sizeof *s->slot);
    s->va = malloc(nn * sizeof *s->va);
    s->slot_node = malloc(nn * sizeof *s->slot_node);
    s->edit = malloc(nn * sizeof *s->edit);
    s->edit_turn = malloc(nn * sizeof *s->edit_turn);
    b->peer_level = calloc(nn, 1);
    b->moving = calloc(nn, 1);
    b->adj_start = calloc(nn + 1, sizeof *b->adj_start);
    b->adj_list = malloc((2 * t->nadj + 1) * sizeof *b->adj_list);
    if (!s->slot || !s->va || !s->slot_node || !s->edit || !s->edit_turn || !b->peer_level ||
        !b->moving || !b->adj_start || !b->adj_list)
        return nomem(err);
    for (size_t n = 0; n < nn; n++) {
        s->slot[n] = -1;
        s->va[n] = n ? ag__resize_visible_ancestor(t, (int32_t)n) : -1;
    }
    gather_edited(s, b, op);
    if (adjacency_lists(b))
        return nomem(err);
    ag_status st = area_of_effect(s, b, op, err);
    if (st)
        return st;
    mark_moving(s, b);
    if (s->nslots > UINT32_MAX / 6 - 1)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "resize: too many nodes move");
    return AG_OK;
}

/* ---- targets ----------------------------------------------------------------------------- */

/* The classes (every coordinate its own) and room for the rows; then the edited nodes'
 * coordinates become targets first: they win over every other hard attachment. */
static ag_status add_targets(ag_edit_resize_solver *s, build *b, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    s->fix = calloc(nc + 1, 1);
    s->val = calloc(nc + 1, sizeof *s->val);
    s->col = malloc((nc + 1) * sizeof *s->col);
    /* per pair at most one ratio per axis, per slot three sizes and six positions */
    s->cap_rows = 6 * s->nslots + 3 * s->nslots + 3 * (b->adj_start[b->t->nnodes] + 1);
    s->rows = malloc(s->cap_rows * sizeof *s->rows);
    if (ag_uf_init(&s->classes, nc, 1) || !s->fix || !s->val || !s->col || !s->rows)
        return nomem(err);
    for (size_t e = 0; e < s->nedit; e++) {
        size_t slot = (size_t)s->slot[s->edit[e]];
        for (int c = 0; c < 6; c++) {
            s->fix[coord_id(slot, c)] = AG__RESIZE_TARGETED;
            if (add_hard(s, coord_id(slot, c), AG__RESIZE_TARGET, 0))
                return nomem(err);
        }
    }
    return AG_OK;
}

/* ---- attachment equations ---------------------------------------------------------------- */

/* A node on the ground stays there. */
static ag_status add_ground(ag_edit_resize_solver *s, build *b)
{
    double ground = b->t->nodes[0].box.min[2];
    for (size_t q = 0; q < s->nslots; q++) {
        const ag_tnode *x = &b->t->nodes[s->slot_node[q]];
        if (fabs(x->box.min[2] - ground) <= b->eps) {
            fix_const(s, coord_id(q, 2), ground);
            ag_status st = add_hard(s, coord_id(q, 2), AG__RESIZE_CONST, ground);
            if (st)
                return st;
        }
    }
    return AG_OK;
}

/* A shared coordinate stays shared: with a node in the area the two classes merge, with one
 * outside it the class is fixed to that node's coordinate. */
static ag_status add_corner(ag_edit_resize_solver *s, size_t q, int vs, const ag_box *bv,
                            const ag_attach *at)
{
    uint32_t cu = coord_id(q, at->ci);
    if (vs >= 0) {
        uint32_t cv = coord_id((size_t)vs, at->cj);
        tie(s, cu, cv, at->k);
        return add_hard(s, cu, cv, at->k);
    }
    double value = ag_box_coord(bv, at->cj) + at->k;
    fix_const(s, cu, value);
    return add_hard(s, cu, AG__RESIZE_CONST, value);
}

/* An overlap keeps its ratio (attach.h): one row over aL, bL, aS, bS, where L is the longer
 * box on the axis; terms on a node outside the area go to the right-hand side. */
static void add_ratio(ag_edit_resize_solver *s, size_t q, int vs, const ag_box *bu,
                      const ag_box *bv, const ag_attach *at)
{
    int a = at->ci, l_is_u = !at->swap;
    double w = ag_attach_weight(at->type), k = at->k;
    int32_t ls = l_is_u ? (int32_t)q : vs, ss = l_is_u ? vs : (int32_t)q;
    const ag_box *bl = l_is_u ? bu : bv, *bs = l_is_u ? bv : bu;
    double coefs[4];
    if (at->form == 0) { /* centre of S at k along L */
        coefs[0] = k - 1, coefs[1] = -k, coefs[2] = 0.5, coefs[3] = 0.5;
    } else if (at->form == 1) { /* bS - aL - k (bS - aS) */
        coefs[0] = -1, coefs[1] = 0, coefs[2] = k, coefs[3] = 1 - k;
    } else { /* bL - aS - k (bS - aS) */
        coefs[0] = 0, coefs[1] = 1, coefs[2] = k - 1, coefs[3] = -k;
    }
    int cc[4] = {a, a + 3, a, a + 3};
    int32_t sl[4] = {ls, ls, ss, ss};
    const ag_box *bb[4] = {bl, bl, bs, bs};
    ag__resize_row *row = new_row(s);
    row->nterms = 0;
    row->rhs = 0;
    row->type = at->type;
    for (int z = 0; z < 4; z++) {
        if (coefs[z] == 0)
            continue;
        if (sl[z] >= 0) {
            row->coord[row->nterms] = coord_id((size_t)sl[z], cc[z]);
            row->coef[row->nterms++] = w * coefs[z];
        } else {
            row->rhs -= w * coefs[z] * ag_box_coord(bb[z], cc[z]);
        }
    }
    if (!row->nterms)
        s->nrows--; /* nothing in the area: no equation */
}

/* Every adjacent pair with a node in the area, once: ground, corners and ratios. */
static ag_status add_attachments(ag_edit_resize_solver *s, build *b, ag_error *err)
{
    if (add_ground(s, b))
        return nomem(err);
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t u = s->slot_node[q];
        const ag_box *bu = &b->t->nodes[u].box;
        for (uint32_t k = b->adj_start[u]; k < b->adj_start[u + 1]; k++) {
            int32_t v = (int32_t)b->adj_list[k];
            int vs = s->slot[v];
            if (vs >= 0 && vs < (int)q)
                continue; /* the pair was done from v */
            if (vs < 0 && b->moving[v])
                continue; /* a descendant: re-derived, not attached */
            const ag_box *bv = &b->t->nodes[v].box;
            ag_attach at[12];
            size_t na = ag_attach_detect(bu, bv, b->eps, at);
            for (size_t m = 0; m < na; m++) {
                if (at[m].type == AG_ATTACH_CORNER) {
                    if (add_corner(s, q, vs, bv, &at[m]))
                        return nomem(err);
                } else {
                    add_ratio(s, q, vs, bu, bv, &at[m]);
                }
            }
        }
    }
    return AG_OK;
}

/* ---- size equations ---------------------------------------------------------------------- */

/* Size where an axis is attached at one end only (it keeps its length), position everywhere
 * (weakly: it keeps the system definite and picks the solution closest to the original). */
static ag_status add_size_terms(ag_edit_resize_solver *s, build *b, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    uint32_t *members = calloc(nc + 1, sizeof *members);
    if (!members)
        return nomem(err);
    for (size_t i = 0; i < nc; i++)
        members[ag_uf_find(&s->classes, (uint32_t)i)]++;
    double ws = ag_attach_weight(AG_ATTACH_SIZE), wp = ag_attach_weight(AG_ATTACH_POSITION);
    for (size_t q = 0; q < s->nslots; q++) {
        const ag_box *bx = &b->t->nodes[s->slot_node[q]].box;
        for (int a = 0; a < 3; a++) {
            uint32_t ca = coord_id(q, a), cb = ca + 3;
            uint32_t ra = ag_uf_find(&s->classes, ca), rb = ag_uf_find(&s->classes, cb);
            int att_a = s->fix[ra] || members[ra] > 1, att_b = s->fix[rb] || members[rb] > 1;
            if (att_a == att_b)
                continue;
            *new_row(s) = (ag__resize_row){.coord = {cb, ca},
                                           .coef = {ws, -ws},
                                           .nterms = 2,
                                           .type = AG_ATTACH_SIZE,
                                           .rhs = ws * ag_box_extent(bx, a)};
        }
        for (int c = 0; c < 6; c++)
            *new_row(s) = (ag__resize_row){.coord = {coord_id(q, c)},
                                           .coef = {wp},
                                           .nterms = 1,
                                           .type = AG_ATTACH_POSITION,
                                           .rhs = wp * ag_box_coord(bx, c)};
    }
    free(members);
    return AG_OK;
}

/* ---- columns and factorization ----------------------------------------------------------- */

static int is_free(ag_edit_resize_solver *s, uint32_t coord)
{
    return !s->fix[ag_uf_find(&s->classes, coord)];
}

static ag_status factorize(ag_edit_resize_solver *s, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    /* columns: the free roots, in the order of their first coordinate */
    for (size_t i = 0; i < nc; i++)
        s->col[i] = -1;
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = ag_uf_find(&s->classes, (uint32_t)i);
        if (!s->fix[r] && s->col[r] < 0)
            s->col[r] = (int32_t)s->ncols++;
    }
    /* rows without a free term say nothing about the unknowns */
    size_t keep = 0, nnz = 0;
    for (size_t i = 0; i < s->nrows; i++) {
        int free_terms = 0;
        for (int z = 0; z < s->rows[i].nterms; z++)
            free_terms += is_free(s, s->rows[i].coord[z]);
        if (free_terms) {
            s->rows[keep++] = s->rows[i];
            nnz += (size_t)free_terms;
        }
    }
    s->nrows = keep;
    s->b = malloc((s->nrows + 1) * sizeof *s->b);
    s->x = malloc((s->ncols + 1) * sizeof *s->x);
    if (!s->b || !s->x)
        return nomem(err);
    if (!s->ncols)
        return AG_OK;
    uint32_t *ri = malloc((nnz + 1) * sizeof *ri), *ci = malloc((nnz + 1) * sizeof *ci);
    double *vv = malloc((nnz + 1) * sizeof *vv);
    if (!ri || !ci || !vv) {
        free(ri);
        free(ci);
        free(vv);
        return nomem(err);
    }
    size_t p = 0;
    for (size_t i = 0; i < s->nrows; i++)
        for (int z = 0; z < s->rows[i].nterms; z++) {
            uint32_t r = ag_uf_find(&s->classes, s->rows[i].coord[z]);
            if (s->fix[r])
                continue;
            ri[p] = (uint32_t)i;
            ci[p] = (uint32_t)s->col[r];
            vv[p++] = s->rows[i].coef[z];
        }
    assert(p == nnz);
    ag_status st = ag_lsq_create(s->nrows, s->ncols, p, ri, ci, vv, &s->lsq, err);
    free(ri);
    free(ci);
    free(vv);
    return st;
}

/* ---- target terms ------------------------------------------------------------------------ */

/* Classes resolved (root and offset per coordinate) and each right-hand side split into its
 * part without the targets (b0) and its terms on target classes. */
static ag_status add_target_terms(ag_edit_resize_solver *s, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    s->croot = malloc((nc + 1) * sizeof *s->croot);
    s->coff = malloc((nc + 1) * sizeof *s->coff);
    s->b0 = malloc((s->nrows + 1) * sizeof *s->b0);
    size_t nt = 0;
    for (size_t i = 0; i < s->nrows; i++)
        for (int z = 0; z < s->rows[i].nterms; z++)
            nt += s->fix[ag_uf_find(&s->classes, s->rows[i].coord[z])] == AG__RESIZE_TARGETED;
    s->trow = malloc((nt + 1) * sizeof *s->trow);
    s->troot = malloc((nt + 1) * sizeof *s->troot);
    s->tcoef = malloc((nt + 1) * sizeof *s->tcoef);
    if (!s->croot || !s->coff || !s->b0 || !s->trow || !s->troot || !s->tcoef)
        return nomem(err);
    for (size_t i = 0; i < nc; i++) {
        s->croot[i] = ag_uf_find(&s->classes, (uint32_t)i);
        s->coff[i] = ag_uf_offset(&s->classes, (uint32_t)i);
    }
    for (size_t i = 0; i < s->nrows; i++) {
        const ag__resize_row *row = &s->rows[i];
        double b = row->rhs;
        for (int z = 0; z < row->nterms; z++) {
            uint32_t c = row->coord[z], r = s->croot[c];
            b -= row->coef[z] * (s->coff[c] + (s->fix[r] == AG__RESIZE_FIXED ? s->val[r] : 0));
            if (s->fix[r] == AG__RESIZE_TARGETED) {
                assert(s->nterms_t < nt);
                s->trow[s->nterms_t] = (uint32_t)i;
                s->troot[s->nterms_t] = r;
                s->tcoef[s->nterms_t++] = row->coef[z];
            }
        }
        s->b0[i] = b;
    }
    return AG_OK;
}

ag_status ag__resize_system_build(ag_edit_resize_solver *s, const ag_edit_op *op,
                                  ag_error *err)
{
    assert(s && s->in && !s->affine);
    const ag_splittree *t = s->in->tree;
    build b = {.t = t, .eps = t->eps > 0 ? t->eps : AG_EDIT_COINCIDENT * s->diag};
    ag_status st = gather_nodes(s, &b, op, err);
    if (!st)
        st = add_targets(s, &b, err);
    if (!st)
        st = add_attachments(s, &b, err);
    if (!st)
        st = add_size_terms(s, &b, err);
    if (!st)
        st = factorize(s, err);
    if (!st)
        st = add_target_terms(s, err);
    build_free(&b);
    return st;
}
