#include "resize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "attach.h"
#include "lsq.h"

/* One soft equation before substitution: sum coef * coord = rhs, coords as AOE coordinate
 * ids (slot * 6 + c); terms on nodes outside the area are folded into rhs. */
typedef struct {
    uint32_t coord[4];
    double coef[4];
    uint8_t nterms, type;
    double rhs;
} soft_row;

/* A hard equality x[coord] - other = d, other being an AOE coordinate (other_coord), a
 * constant (other_coord = CONST_EQ, value in d) or the coordinate's target (TARGET_EQ). */
#define CONST_EQ UINT32_MAX
#define TARGET_EQ (UINT32_MAX - 1)
typedef struct {
    uint32_t coord, other_coord;
    double d;
} hard_eq;

struct ag_edit_resize_solver {
    const ag_proceduralize_result *in;
    int32_t node;
    int mode, has_region;
    ag_box region;
    int affine;             /* root or invisible node: no solve */
    size_t nedit;
    int32_t *edit;          /* edited nodes */
    int *edit_turn;         /* quarter turns from the op's node to each edited node */
    int32_t *slot;          /* per tree node: AOE slot or -1 */
    int32_t *slot_node;     /* per slot */
    size_t nslots;
    int32_t *va;            /* per node: nearest visible ancestor (0 = root) */
    /* classes */
    uint32_t *uf;           /* per coordinate: parent */
    double *off;            /* per coordinate: x = x_root + off */
    int8_t *fix;            /* per root: 0 free, 1 constant, 2 target */
    double *val;            /* per root: value when fixed */
    int32_t *col;           /* per root: column when free */
    size_t ncols;
    /* equations */
    soft_row *rows;
    size_t nrows;
    hard_eq *hard;
    size_t nhard, cap_hard;
    ag_lsq *lsq;
    double *b, *x;
    double diag;
    /* resolved once the classes are final, so a re-solve does no lookups */
    uint32_t *croot;        /* per coordinate: its class root */
    double *coff;           /* per coordinate: offset from the root */
    double *b0;             /* per row: right-hand side without the targets */
    uint32_t *trow, *troot; /* terms on target classes: row, root and coefficient */
    double *tcoef;
    size_t nterms_t;
};

static double coord_of(const ag_box *b, int c) { return (c < 3 ? b->min : b->max)[c % 3]; }
static void set_coord(ag_box *b, int c, double v) { (c < 3 ? b->min : b->max)[c % 3] = v; }

static uint32_t uf_find(ag_edit_resize_solver *s, uint32_t i)
{
    /* two passes: find the root and the offset, then compress */
    uint32_t r = i;
    double acc = 0;
    while (s->uf[r] != r) {
        acc += s->off[r];
        r = s->uf[r];
    }
    uint32_t c = i;
    double rest = acc;
    while (s->uf[c] != c) {
        uint32_t next = s->uf[c];
        double o = s->off[c];
        s->uf[c] = r;
        s->off[c] = rest;
        rest -= o;
        c = next;
    }
    return r;
}

/* x_i - x_j = d */
static void uf_union(ag_edit_resize_solver *s, uint32_t i, uint32_t j, double d)
{
    uint32_t ri = uf_find(s, i), rj = uf_find(s, j);
    if (ri == rj)
        return;
    double oi = i == ri ? 0 : s->off[i], oj = j == rj ? 0 : s->off[j];
    double rel = oj + d - oi; /* x_ri - x_rj */
    if (s->fix[ri] == 2 && s->fix[rj] == 2)
        return; /* two targets: both stay, the equality is checked afterwards */
    if (s->fix[ri] == 2 || (s->fix[ri] == 1 && s->fix[rj] != 2)) {
        s->uf[rj] = ri;
        s->off[rj] = -rel;
    } else {
        s->uf[ri] = rj;
        s->off[ri] = rel;
    }
}

static void fix_const(ag_edit_resize_solver *s, uint32_t i, double v)
{
    uint32_t r = uf_find(s, i);
    if (s->fix[r])
        return;
    s->fix[r] = 1;
    s->val[r] = v - (i == r ? 0 : s->off[i]);
}

static ag_status add_hard(ag_edit_resize_solver *s, uint32_t coord, uint32_t other, double d)
{
    if (s->nhard == s->cap_hard) {
        size_t cap = s->cap_hard ? 2 * s->cap_hard : 256;
        hard_eq *h = realloc(s->hard, cap * sizeof *h);
        if (!h)
            return AG_ERR_NOMEM;
        s->hard = h;
        s->cap_hard = cap;
    }
    s->hard[s->nhard++] = (hard_eq){coord, other, d};
    return AG_OK;
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
    free(s->uf);
    free(s->off);
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

static int boxes_meet(const ag_box *a, const ag_box *b, double eps)
{
    for (int k = 0; k < 3; k++)
        if (a->min[k] > b->max[k] + eps || b->min[k] > a->max[k] + eps)
            return 0;
    return 1;
}

static void clamp_into(ag_box *b, const ag_box *outer)
{
    for (int a = 0; a < 3; a++) {
        if (b->min[a] < outer->min[a])
            b->min[a] = outer->min[a];
        if (b->max[a] > outer->max[a])
            b->max[a] = outer->max[a];
        if (b->max[a] < b->min[a])
            b->max[a] = b->min[a];
    }
}

/* The op's target box for its node. */
static ag_status op_target(const ag_proceduralize_result *in, const ag_edit_op *op, ag_box *t,
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
            t->max[a] = old->min[a] + (old->max[a] - old->min[a]) * op->scale[a];
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

static int32_t visible_ancestor(const ag_splittree *t, int32_t n)
{
    for (int32_t p = t->nodes[n].parent; p >= 0; p = t->nodes[p].parent)
        if (t->nodes[p].kind == AG_NODE_COMPONENT)
            return p;
    return 0;
}

ag_status ag_edit_resize_solver_create(const ag_proceduralize_result *in, const ag_edit_op *op,
                                       ag_edit_resize_solver **out, ag_error *err)
{
    *out = NULL;
    ag_status st = ag_edit_check_node(in, op->node, "node", err);
    if (st)
        return st;
    const ag_splittree *t = in->tree;
    size_t nn = t->nnodes;
    ag_edit_resize_solver *s = calloc(1, sizeof *s);
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    s->in = in;
    s->node = op->node;
    s->mode = op->mode;
    s->has_region = op->has_region;
    s->region = op->region;
    s->diag = ag_box_diagonal(&t->nodes[0].box);
    const ag_tnode *en = &t->nodes[op->node];
    if (en->kind != AG_NODE_COMPONENT) {
        s->affine = 1;
        *out = s;
        return AG_OK;
    }
    double eps = t->eps > 0 ? t->eps : 1e-9 * s->diag;
    s->slot = malloc(nn * sizeof *s->slot);
    s->va = malloc(nn * sizeof *s->va);
    s->slot_node = malloc(nn * sizeof *s->slot_node);
    s->edit = malloc(nn * sizeof *s->edit);
    s->edit_turn = malloc(nn * sizeof *s->edit_turn);
    uint8_t *peer_level = calloc(nn, 1), *moving = calloc(nn, 1);
    uint32_t *adj_start = calloc(nn + 1, sizeof *adj_start);
    uint32_t *adj_list = malloc((2 * t->nadj + 1) * sizeof *adj_list);
    if (!s->slot || !s->va || !s->slot_node || !s->edit || !s->edit_turn || !peer_level ||
        !moving || !adj_start || !adj_list)
        goto nomem;
    for (size_t n = 0; n < nn; n++) {
        s->slot[n] = -1;
        s->va[n] = n ? visible_ancestor(t, (int32_t)n) : -1;
    }
    /* edited nodes */
    s->edit[s->nedit] = op->node;
    s->edit_turn[s->nedit++] = 0;
    if (op->mode == AG_EDIT_GLOBAL && en->rule >= 0) {
        for (size_t n = 0; n < nn; n++) {
            const ag_tnode *x = &t->nodes[n];
            if ((int32_t)n == op->node || x->kind != AG_NODE_COMPONENT || x->rule != en->rule)
                continue;
            s->edit[s->nedit] = (int32_t)n;
            s->edit_turn[s->nedit++] = (x->rule_rot - en->rule_rot) & 3;
        }
    }
    for (size_t e = 0; e < s->nedit; e++)
        peer_level[s->va[s->edit[e]]] = 1;
    /* adjacency lists (CSR) */
    for (size_t k = 0; k < t->nadj; k++) {
        adj_start[t->adj[2 * k] + 1]++;
        adj_start[t->adj[2 * k + 1] + 1]++;
    }
    for (size_t n = 0; n < nn; n++)
        adj_start[n + 1] += adj_start[n];
    {
        uint32_t *fill = malloc((nn + 1) * sizeof *fill);
        if (!fill)
            goto nomem;
        memcpy(fill, adj_start, (nn + 1) * sizeof *fill);
        for (size_t k = 0; k < t->nadj; k++) {
            uint32_t u = t->adj[2 * k], v = t->adj[2 * k + 1];
            adj_list[fill[u]++] = v;
            adj_list[fill[v]++] = u;
        }
        free(fill);
    }
    /* region of a local edit: given, or the edited node's old and new boxes */
    ag_box region = op->region;
    if (op->mode == AG_EDIT_LOCAL && !op->has_region) {
        ag_box tb;
        if ((st = op_target(in, op, &tb, err)))
            goto fail;
        region = en->box;
        for (int a = 0; a < 3; a++) {
            region.min[a] = fmin(region.min[a], tb.min[a]);
            region.max[a] = fmax(region.max[a], tb.max[a]);
        }
    }
    /* breadth-first area of effect; slot order = queue order */
    for (size_t e = 0; e < s->nedit; e++) {
        int32_t n = s->edit[e];
        if (s->slot[n] < 0) {
            s->slot[n] = (int32_t)s->nslots;
            s->slot_node[s->nslots++] = n;
        }
    }
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t u = s->slot_node[q];
        for (uint32_t k = adj_start[u]; k < adj_start[u + 1]; k++) {
            int32_t v = (int32_t)adj_list[k];
            const ag_tnode *x = &t->nodes[v];
            if (s->slot[v] >= 0 || x->kind != AG_NODE_COMPONENT || !peer_level[s->va[v]])
                continue;
            if (op->mode == AG_EDIT_LOCAL && !boxes_meet(&x->box, &region, eps))
                continue;
            s->slot[v] = (int32_t)s->nslots;
            s->slot_node[s->nslots++] = v;
        }
    }
    /* moving: in the area or below a node in it */
    for (size_t n = 1; n < nn; n++) {
        /* parents precede children in index order only for the build; walk up instead */
        for (int32_t p = (int32_t)n; p > 0; p = t->nodes[p].parent)
            if (s->slot[p] >= 0) {
                moving[n] = 1;
                break;
            }
    }
    size_t nc = 6 * s->nslots;
    s->uf = malloc(nc * sizeof *s->uf);
    s->off = calloc(nc, sizeof *s->off);
    s->fix = calloc(nc, 1);
    s->val = calloc(nc, sizeof *s->val);
    s->col = malloc(nc * sizeof *s->col);
    size_t cap_rows = 6 * s->nslots + 3 * s->nslots + 3 * (adj_start[nn] + 1);
    s->rows = malloc(cap_rows * sizeof *s->rows);
    if (!s->uf || !s->off || !s->fix || !s->val || !s->col || !s->rows)
        goto nomem;
    for (size_t i = 0; i < nc; i++)
        s->uf[i] = (uint32_t)i;
    /* targets first: they win over every other hard attachment */
    for (size_t e = 0; e < s->nedit; e++) {
        uint32_t base = 6 * (uint32_t)s->slot[s->edit[e]];
        for (int c = 0; c < 6; c++) {
            s->fix[base + c] = 2;
            if ((st = add_hard(s, base + c, TARGET_EQ, 0)))
                goto nomem;
        }
    }
    /* ground */
    double ground = t->nodes[0].box.min[2];
    for (size_t q = 0; q < s->nslots; q++) {
        const ag_tnode *x = &t->nodes[s->slot_node[q]];
        if (fabs(x->box.min[2] - ground) <= eps) {
            fix_const(s, 6 * (uint32_t)q + 2, ground);
            if ((st = add_hard(s, 6 * (uint32_t)q + 2, UINT32_MAX, ground)))
                goto nomem;
        }
    }
    /* pairs */
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t u = s->slot_node[q];
        const ag_box *bu = &t->nodes[u].box;
        for (uint32_t k = adj_start[u]; k < adj_start[u + 1]; k++) {
            int32_t v = (int32_t)adj_list[k];
            int vs = s->slot[v];
            if (vs >= 0 && vs < (int)q)
                continue; /* the pair was done from v */
            if (vs < 0 && moving[v])
                continue; /* a descendant: re-derived, not attached */
            const ag_box *bv = &t->nodes[v].box;
            ag_attach at[12];
            size_t na = ag_attach_detect(bu, bv, eps, at);
            for (size_t m = 0; m < na; m++) {
                uint32_t cu = 6 * (uint32_t)q + at[m].ci;
                if (at[m].type == AG_ATTACH_CORNER) {
                    if (vs >= 0) {
                        uint32_t cv = 6 * (uint32_t)vs + at[m].cj;
                        uf_union(s, cu, cv, at[m].k);
                        st = add_hard(s, cu, cv, at[m].k);
                    } else {
                        double value = coord_of(bv, at[m].cj) + at[m].k;
                        fix_const(s, cu, value);
                        st = add_hard(s, cu, UINT32_MAX, value);
                    }
                    if (st)
                        goto nomem;
                    continue;
                }
                /* ratio (attach.h): terms over aL, bL, aS, bS */
                int a = at[m].ci, l_is_u = !at[m].swap;
                double w = ag_attach_weight(at[m].type), k = at[m].k;
                int32_t ls = l_is_u ? (int32_t)q : vs, ss = l_is_u ? vs : (int32_t)q;
                const ag_box *bl = l_is_u ? bu : bv, *bs = l_is_u ? bv : bu;
                double coefs[4];
                if (at[m].form == 0) { /* centre of S at k along L */
                    coefs[0] = k - 1, coefs[1] = -k, coefs[2] = 0.5, coefs[3] = 0.5;
                } else if (at[m].form == 1) { /* bS - aL - k (bS - aS) */
                    coefs[0] = -1, coefs[1] = 0, coefs[2] = k, coefs[3] = 1 - k;
                } else { /* bL - aS - k (bS - aS) */
                    coefs[0] = 0, coefs[1] = 1, coefs[2] = k - 1, coefs[3] = -k;
                }
                int cc[4] = {a, a + 3, a, a + 3};
                int32_t sl[4] = {ls, ls, ss, ss};
                const ag_box *bb[4] = {bl, bl, bs, bs};
                soft_row *row = &s->rows[s->nrows];
                row->nterms = 0;
                row->rhs = 0;
                row->type = at[m].type;
                for (int z = 0; z < 4; z++) {
                    if (coefs[z] == 0)
                        continue;
                    if (sl[z] >= 0) {
                        row->coord[row->nterms] = 6 * (uint32_t)sl[z] + cc[z];
                        row->coef[row->nterms++] = w * coefs[z];
                    } else {
                        row->rhs -= w * coefs[z] * coord_of(bb[z], cc[z]);
                    }
                }
                if (row->nterms)
                    s->nrows++;
            }
        }
    }
    /* size where an axis is attached at one end only, position everywhere (weakly: it keeps
     * the system definite and picks the solution closest to the original) */
    {
        uint32_t *members = calloc(nc + 1, sizeof *members);
        if (!members)
            goto nomem;
        for (size_t i = 0; i < nc; i++)
            members[uf_find(s, (uint32_t)i)]++;
        double ws = ag_attach_weight(AG_ATTACH_SIZE), wp = ag_attach_weight(AG_ATTACH_POSITION);
        for (size_t q = 0; q < s->nslots; q++) {
            const ag_box *b = &t->nodes[s->slot_node[q]].box;
            for (int a = 0; a < 3; a++) {
                uint32_t ca = 6 * (uint32_t)q + a, cb = ca + 3;
                uint32_t ra = uf_find(s, ca), rb = uf_find(s, cb);
                int att_a = s->fix[ra] || members[ra] > 1, att_b = s->fix[rb] || members[rb] > 1;
                if (att_a == att_b)
                    continue;
                s->rows[s->nrows++] = (soft_row){.coord = {cb, ca},
                                                 .coef = {ws, -ws},
                                                 .nterms = 2,
                                                 .type = AG_ATTACH_SIZE,
                                                 .rhs = ws * (b->max[a] - b->min[a])};
            }
            for (int c = 0; c < 6; c++)
                s->rows[s->nrows++] = (soft_row){.coord = {6 * (uint32_t)q + c},
                                                 .coef = {wp},
                                                 .nterms = 1,
                                                 .type = AG_ATTACH_POSITION,
                                                 .rhs = wp * coord_of(b, c)};
        }
        free(members);
    }
    /* columns: free roots */
    for (size_t i = 0; i < nc; i++)
        s->col[i] = -1;
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = uf_find(s, (uint32_t)i);
        if (!s->fix[r] && s->col[r] < 0)
            s->col[r] = (int32_t)s->ncols++;
    }
    /* drop rows without a free term; build the matrix */
    size_t keep = 0, nnz = 0;
    for (size_t i = 0; i < s->nrows; i++) {
        int free_terms = 0;
        for (int z = 0; z < s->rows[i].nterms; z++)
            free_terms += !s->fix[uf_find(s, s->rows[i].coord[z])];
        if (free_terms) {
            s->rows[keep++] = s->rows[i];
            nnz += free_terms;
        }
    }
    s->nrows = keep;
    s->b = malloc((s->nrows + 1) * sizeof *s->b);
    s->x = malloc((s->ncols + 1) * sizeof *s->x);
    if (!s->b || !s->x)
        goto nomem;
    if (s->ncols) {
        uint32_t *ri = malloc((nnz + 1) * sizeof *ri), *ci = malloc((nnz + 1) * sizeof *ci);
        double *vv = malloc((nnz + 1) * sizeof *vv);
        if (!ri || !ci || !vv) {
            free(ri);
            free(ci);
            free(vv);
            goto nomem;
        }
        size_t p = 0;
        for (size_t i = 0; i < s->nrows; i++)
            for (int z = 0; z < s->rows[i].nterms; z++) {
                uint32_t r = uf_find(s, s->rows[i].coord[z]);
                if (s->fix[r])
                    continue;
                ri[p] = (uint32_t)i;
                ci[p] = (uint32_t)s->col[r];
                vv[p++] = s->rows[i].coef[z];
            }
        st = ag_lsq_create(s->nrows, s->ncols, p, ri, ci, vv, &s->lsq, err);
        free(ri);
        free(ci);
        free(vv);
        if (st)
            goto fail;
    }
    /* resolve classes and split each right-hand side into its fixed and target parts */
    s->croot = malloc((nc + 1) * sizeof *s->croot);
    s->coff = malloc((nc + 1) * sizeof *s->coff);
    s->b0 = malloc((s->nrows + 1) * sizeof *s->b0);
    size_t nt = 0;
    for (size_t i = 0; i < s->nrows; i++)
        for (int z = 0; z < s->rows[i].nterms; z++)
            nt += s->fix[uf_find(s, s->rows[i].coord[z])] == 2;
    s->trow = malloc((nt + 1) * sizeof *s->trow);
    s->troot = malloc((nt + 1) * sizeof *s->troot);
    s->tcoef = malloc((nt + 1) * sizeof *s->tcoef);
    if (!s->croot || !s->coff || !s->b0 || !s->trow || !s->troot || !s->tcoef)
        goto nomem;
    for (size_t i = 0; i < nc; i++) {
        s->croot[i] = uf_find(s, (uint32_t)i);
        s->coff[i] = s->croot[i] == i ? 0 : s->off[i];
    }
    for (size_t i = 0; i < s->nrows; i++) {
        const soft_row *row = &s->rows[i];
        double b = row->rhs;
        for (int z = 0; z < row->nterms; z++) {
            uint32_t c = row->coord[z], r = s->croot[c];
            b -= row->coef[z] * (s->coff[c] + (s->fix[r] == 1 ? s->val[r] : 0));
            if (s->fix[r] == 2) {
                s->trow[s->nterms_t] = (uint32_t)i;
                s->troot[s->nterms_t] = r;
                s->tcoef[s->nterms_t++] = row->coef[z];
            }
        }
        s->b0[i] = b;
    }
    free(peer_level);
    free(moving);
    free(adj_start);
    free(adj_list);
    *out = s;
    return AG_OK;
nomem:
    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
fail:
    free(peer_level);
    free(moving);
    free(adj_start);
    free(adj_list);
    ag_edit_resize_solver_free(s);
    return st;
}

/* Affine per-axis map taking box `from` onto box `to`. */
typedef struct {
    double s[3], t[3];
} amap;

static amap map_between(const ag_box *from, const ag_box *to)
{
    amap m;
    for (int a = 0; a < 3; a++) {
        double w = from->max[a] - from->min[a], w2 = to->max[a] - to->min[a];
        m.s[a] = w > 1e-12 ? w2 / w : 1;
        m.t[a] = to->min[a] - m.s[a] * from->min[a];
    }
    return m;
}

static ag_box map_box(const amap *m, const ag_box *b)
{
    ag_box r;
    for (int a = 0; a < 3; a++) {
        r.min[a] = m->s[a] * b->min[a] + m->t[a];
        r.max[a] = m->s[a] * b->max[a] + m->t[a];
    }
    return r;
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
        order[no++] = n;
        const ag_tnode *x = &t->nodes[n];
        if (x->first_child < 0)
            continue;
        amap m = map_between(&x->box, &boxes[n]);
        for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling) {
            if (!set[c])
                boxes[c] = map_box(&m, &t->nodes[c].box);
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
            for (int a = 0; a < 3; a++) {
                u.min[a] = fmin(u.min[a], boxes[c].min[a]);
                u.max[a] = fmax(u.max[a], boxes[c].max[a]);
            }
        if (n == 0 || x->kind == AG_NODE_SPLIT || x->kind == AG_NODE_PATTERN)
            boxes[n] = u;
    }
    free(stack);
    free(order);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

ag_status ag_edit_resize_solver_solve(ag_edit_resize_solver *s, const ag_edit_op *op,
                                      ag_box *boxes, ag_edit_report *rep, ag_error *err)
{
    const ag_splittree *t = s->in->tree;
    size_t nn = t->nnodes;
    double t0 = now_ms();
    ag_box target;
    ag_status st = op_target(s->in, op, &target, err);
    if (st)
        return st;
    uint8_t *set = calloc(nn, 1);
    if (!set)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t n = 0; n < nn; n++)
        boxes[n] = t->nodes[n].box;
    const ag_box *old = &t->nodes[op->node].box;
    if (s->affine) {
        /* the root or an invisible node: its subtree follows its box */
        if (op->node != 0) {
            int32_t va = visible_ancestor(t, op->node);
            if (va > 0)
                clamp_into(&target, &t->nodes[va].box);
        }
        boxes[op->node] = target;
        set[op->node] = 1;
        derive_boxes(t, boxes, set);
        free(set);
        if (rep) {
            rep->equations = rep->unknowns = 0;
            rep->solve_ms = now_ms() - t0;
            rep->max_residual = rep->max_residual_rel = 0;
        }
        return AG_OK;
    }
    /* target values of the edited nodes */
    double dmin[3], dmax[3];
    for (int a = 0; a < 3; a++) {
        dmin[a] = target.min[a] - old->min[a];
        dmax[a] = target.max[a] - old->max[a];
    }
    double *tv = malloc(6 * s->nslots * sizeof *tv + 1);
    if (!tv) {
        free(set);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
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
            clamp_into(&tb, &t->nodes[s->va[n]].box);
        uint32_t base = 6 * (uint32_t)s->slot[n];
        for (int c = 0; c < 6; c++) {
            s->val[base + c] = coord_of(&tb, c); /* targets are roots */
        }
    }
    /* right-hand side */
    memcpy(s->b, s->b0, s->nrows * sizeof *s->b);
    for (size_t k = 0; k < s->nterms_t; k++)
        s->b[s->trow[k]] -= s->tcoef[k] * s->val[s->troot[k]];
    if (s->lsq && (st = ag_lsq_solve(s->lsq, s->b, s->x, err))) {
        free(tv);
        free(set);
        return st;
    }
    /* coordinates → boxes */
    size_t nc = 6 * s->nslots;
    double *xv = tv; /* reuse: value of every AOE coordinate */
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = s->croot[i];
        xv[i] = (s->fix[r] ? s->val[r] : s->x[s->col[r]]) + s->coff[i];
    }
    double maxres = 0;
    for (size_t h = 0; h < s->nhard; h++) {
        const hard_eq *q = &s->hard[h];
        double other = q->other_coord == CONST_EQ    ? q->d
                       : q->other_coord == TARGET_EQ ? s->val[q->coord]
                                                     : xv[q->other_coord] + q->d;
        double r = fabs(xv[q->coord] - other);
        if (r > maxres)
            maxres = r;
    }
    for (size_t q = 0; q < s->nslots; q++) {
        int32_t n = s->slot_node[q];
        ag_box b;
        for (int c = 0; c < 6; c++)
            set_coord(&b, c, xv[6 * q + c]);
        for (int a = 0; a < 3; a++)
            if (b.max[a] < b.min[a]) { /* a flip: collapse rather than invert */
                double mid = 0.5 * (b.min[a] + b.max[a]);
                b.min[a] = b.max[a] = mid;
            }
        if (s->va[n] > 0)
            clamp_into(&b, &t->nodes[s->va[n]].box);
        boxes[n] = b;
        set[n] = 1;
    }
    derive_boxes(t, boxes, set);
    free(tv);
    free(set);
    if (rep) {
        rep->equations = s->nrows;
        rep->unknowns = s->ncols;
        rep->solve_ms = now_ms() - t0;
        rep->max_residual = maxres;
        rep->max_residual_rel = s->diag > 0 ? maxres / s->diag : 0;
    }
    return AG_OK;
}

/* ---- emission ------------------------------------------------------------------------ */

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
    ag_status st;
    ag_error *err;
} emitter;

/* Components placed between two polls of the budget's callback. */
#define EMIT_POLL 1024

static void emit_node(emitter *E, int32_t n, const amap *g, int depth);

static void emit_component(emitter *E, int32_t n, const amap *m)
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
    int32_t lab = x->label >= 0 ? x->label : L->label[x->component];
    int32_t gi = -1;
    if (lab >= 0 && (size_t)lab < L->nlabels) {
        if (E->group_of_label[lab] < 0) {
            char name[32];
            snprintf(name, sizeof name, "L%d", lab + 1);
            size_t ix;
            if ((E->st = ag_mesh_add_group(E->out, name, &ix)))
                return;
            E->group_of_label[lab] = (int32_t)ix;
        }
        gi = E->group_of_label[lab];
    }
    size_t comp;
    if ((E->st = ag_mesh_add_component(E->out, gi, &comp)))
        return;
    E->emission++;
    for (uint32_t k = L->tri_start[x->component]; k < L->tri_start[x->component + 1]; k++) {
        uint32_t tr = L->tris[k], v[3];
        for (int j = 0; j < 3; j++) {
            uint32_t sv = src->tri[3 * tr + j];
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
static ag_box new_box(emitter *E, int32_t c, const amap *g)
{
    return g ? map_box(g, &E->in->tree->nodes[c].box) : E->boxes[c];
}

/* A child slot of a node and the group it joins (join_siblings). */
typedef struct {
    int32_t slot, end; /* the child and the node its split chain ends in */
    int32_t leader;    /* index of the group's first member */
    size_t members;    /* at the leader: how many */
    int stuck;         /* at the leader: squeezed but no neighbour to join */
    double w[3];       /* at the leader: the group's new size per axis */
    ag_box box;        /* at the leader: the group's new box */
} sibling;

static int spans_meet(const ag_box *a, const ag_box *b, int axis, double eps)
{
    return a->min[axis] <= b->max[axis] + eps && b->min[axis] <= a->max[axis] + eps;
}

/* Plain siblings of one rule (children of n not gathered into a grid pattern) squeezed under
 * AG_EDIT_JOIN_RATIO on an axis join with their nearest sibling of the same rule and turn
 * along that axis, recursively, until no group is squeezed or none has a neighbour: the group
 * becomes one copy of its first member's subtree whose size on that axis is the members' sizes
 * summed (at most the span they cover), centred on that span, so two windows squeezed to 0.4×
 * become one of 0.8×. Emits n's children and returns 1 when anything joined, else emits
 * nothing and returns 0. */
static int join_siblings(emitter *E, int32_t n, const amap *g, int depth)
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
            for (int a = 0; a < 3; a++)
                x->w[a] = x->box.max[a] - x->box.min[a];
        } else {
            x->leader = -1; /* takes no part */
        }
    }
    double eps = 1e-9 * (1 + ag_box_diagonal(&t->nodes[0].box));
    size_t joined = 0;
    /* every round joins two groups or gives up on one (until a join frees it again) */
    for (size_t round = 0; round < 4 * m; round++) {
        /* the most squeezed group that may still join */
        size_t best = m;
        int axis = -1;
        double worst = AG_EDIT_JOIN_RATIO;
        for (size_t i = 0; i < m; i++) {
            if (s[i].leader != (int32_t)i || s[i].stuck)
                continue;
            const ag_box *ob = &t->nodes[s[i].end].box;
            for (int a = 0; a < 3; a++) {
                double ow = ob->max[a] - ob->min[a];
                if (ow <= 1e-12)
                    continue;
                double r = s[i].w[a] / ow;
                if (r < worst) {
                    worst = r;
                    best = i;
                    axis = a;
                }
            }
        }
        if (best == m)
            break;
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
            if (!spans_meet(bb, jb, (axis + 1) % 3, eps) ||
                !spans_meet(bb, jb, (axis + 2) % 3, eps))
                continue;
            double d = fmax(0, fmax(jb->min[axis] - bb->max[axis], bb->min[axis] - jb->max[axis]));
            if (d < gap) {
                gap = d;
                other = j;
            }
        }
        if (other == m) {
            s[best].stuck = 1;
            continue;
        }
        /* the earlier sibling leads: its subtree is the one kept */
        size_t lead = best < other ? best : other, gone = best < other ? other : best;
        sibling *L = &s[lead], *G = &s[gone];
        ag_box u = L->box;
        for (int a = 0; a < 3; a++) {
            u.min[a] = fmin(u.min[a], G->box.min[a]);
            u.max[a] = fmax(u.max[a], G->box.max[a]);
        }
        double span = u.max[axis] - u.min[axis];
        double w = fmin(L->w[axis] + G->w[axis], span), mid = 0.5 * (u.min[axis] + u.max[axis]);
        u.min[axis] = mid - 0.5 * w;
        u.max[axis] = mid + 0.5 * w;
        L->box = u;
        for (int a = 0; a < 3; a++)
            L->w[a] = a == axis ? w : u.max[a] - u.min[a];
        L->members += G->members;
        L->stuck = 0;
        for (size_t i = 0; i < m; i++)
            if (s[i].leader == (int32_t)gone)
                s[i].leader = (int32_t)lead;
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
            amap jm = map_between(&t->nodes[s[i].end].box, &s[i].box);
            emit_node(E, s[i].end, &jm, depth + 1);
        } /* else joined into an earlier sibling */
    }
    free(s);
    return 1;
}

static void emit_children(emitter *E, int32_t n, const amap *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    if (t->nodes[n].kind != AG_NODE_SPLIT && join_siblings(E, n, g, depth))
        return;
    for (int32_t c = t->nodes[n].first_child; c >= 0 && !E->st; c = t->nodes[c].next_sibling)
        emit_node(E, c, g, depth + 1);
}

static void emit_pattern(emitter *E, int32_t n, const amap *g, int depth)
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
    /* the old grid: first cell, cell size, counts; the new layout from the cells' new boxes */
    int32_t first = x->first_child;
    size_t ncells = 0;
    ag_box span_old = t->nodes[first].box, span_new = new_box(E, first, g);
    for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling) {
        ncells++;
        ag_box ob = t->nodes[c].box, nb = new_box(E, c, g);
        for (int a = 0; a < 3; a++) {
            span_old.min[a] = fmin(span_old.min[a], ob.min[a]);
            span_old.max[a] = fmax(span_old.max[a], ob.max[a]);
            span_new.min[a] = fmin(span_new.min[a], nb.min[a]);
            span_new.max[a] = fmax(span_new.max[a], nb.max[a]);
        }
    }
    uint32_t cnt[3], ncnt[3];
    double w[3], nw[3], np[3], rho[3];
    size_t total = 1, ntotal = 1;
    int changed = 0;
    ag_box fo = t->nodes[first].box, fnew = new_box(E, first, g);
    for (int a = 0; a < 3; a++) {
        cnt[a] = P->counts[a] ? P->counts[a] : 1;
        total *= cnt[a];
        w[a] = fo.max[a] - fo.min[a];
        double nwa = fnew.max[a] - fnew.min[a];
        double Lnew = span_new.max[a] - span_new.min[a];
        ncnt[a] = cnt[a];
        nw[a] = nwa;
        np[a] = 0;
        if (cnt[a] < 2 || w[a] <= 1e-12 || nwa <= 1e-12 * (1 + fabs(Lnew))) {
            /* no repetition on this axis, or cells collapsed: the count stays */
            ntotal *= ncnt[a];
            continue;
        }
        double pold = (span_old.max[a] - span_old.min[a] - w[a]) / (cnt[a] - 1);
        double pnew = (Lnew - nwa) / (cnt[a] - 1);
        rho[a] = pnew > 1e-12 ? nwa / pnew : (pold > 1e-12 ? w[a] / pold : 1);
        if (!(rho[a] > 1e-9) || !isfinite(rho[a])) {
            ntotal *= ncnt[a];
            continue;
        }
        uint32_t k = cnt[a];
        for (int it = 0; it < 40; it++) {
            double p = Lnew / (k - 1 + rho[a]);
            double cw = rho[a] * p;
            if (cw / w[a] > AG_EDIT_SPLIT_RATIO && k < (1u << 20))
                k *= 2;
            else if (cw / w[a] < AG_EDIT_JOIN_RATIO && k > 1)
                k = k / 2;
            else
                break;
        }
        ncnt[a] = k;
        np[a] = Lnew / (k - 1 + rho[a]);
        nw[a] = rho[a] * np[a];
        if (k != cnt[a])
            changed = 1;
        ntotal *= k;
    }
    if (!changed || ncells != total) {
        emit_children(E, n, g, depth);
        return;
    }
    if (ntotal > total)
        E->splits += ntotal - total;
    else
        E->joins += total - ntotal;
    /* old grid index → cell node */
    int32_t *cell = malloc(total * sizeof *cell);
    if (!cell) {
        E->st = ag_error_set(E->err, AG_ERR_NOMEM, 0, "out of memory");
        return;
    }
    for (size_t i = 0; i < total; i++)
        cell[i] = first;
    for (int32_t c = first; c >= 0; c = t->nodes[c].next_sibling) {
        size_t idx = 0, mul = 1;
        for (int a = 0; a < 3; a++) {
            long ia = 0;
            if (cnt[a] > 1) {
                double pold = (span_old.max[a] - span_old.min[a] - w[a]) / (cnt[a] - 1);
                ia = pold > 1e-12 ? lround((t->nodes[c].box.min[a] - span_old.min[a]) / pold) : 0;
                if (ia < 0)
                    ia = 0;
                if (ia >= (long)cnt[a])
                    ia = cnt[a] - 1;
            }
            idx += (size_t)ia * mul;
            mul *= cnt[a];
        }
        cell[idx] = c;
    }
    for (size_t i = 0; i < ntotal && !E->st; i++) {
        size_t rest = i, src = 0, mul = 1, ia[3];
        for (int a = 0; a < 3; a++) {
            ia[a] = rest % ncnt[a];
            rest /= ncnt[a];
            src += (ia[a] * cnt[a] / ncnt[a]) * mul;
            mul *= cnt[a];
        }
        int32_t c = cell[src];
        ag_box nb = new_box(E, c, g); /* axes whose count stays: the cell as mapped */
        for (int a = 0; a < 3; a++)
            if (ncnt[a] != cnt[a]) {
                nb.min[a] = span_new.min[a] + ia[a] * np[a];
                nb.max[a] = nb.min[a] + nw[a];
            }
        amap m = map_between(&t->nodes[c].box, &nb);
        emit_node(E, c, &m, depth + 1);
    }
    free(cell);
}

static void emit_node(emitter *E, int32_t n, const amap *g, int depth)
{
    const ag_splittree *t = E->in->tree;
    const ag_tnode *x = &t->nodes[n];
    if (x->kind == AG_NODE_DEAD || depth > 4 * AG_SPLITTREE_MAX_NESTING + 64)
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
    amap m = map_between(&x->box, &nb);
    /* stretched past the split ratio on an axis: two copies of the subtree, each half */
    int axis = -1;
    double best = AG_EDIT_SPLIT_RATIO;
    for (int a = 0; a < 3; a++) {
        double w = x->box.max[a] - x->box.min[a];
        if (w <= 1e-12)
            continue;
        double r = (nb.max[a] - nb.min[a]) / w;
        if (r > best) {
            best = r;
            axis = a;
        }
    }
    if (axis >= 0) {
        E->splits++;
        double mid = 0.5 * (nb.min[axis] + nb.max[axis]);
        for (int h = 0; h < 2 && !E->st; h++) {
            ag_box hb = nb;
            if (h == 0)
                hb.max[axis] = mid;
            else
                hb.min[axis] = mid;
            amap hm = map_between(&x->box, &hb);
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
    *out = NULL;
    emitter E = {.in = in, .boxes = boxes, .err = err, .budget = budget};
    const ag_labels *L = in->labels;
    E.out = ag_mesh_create();
    E.group_of_label = malloc((L->nlabels + 1) * sizeof *E.group_of_label);
    E.vmap = malloc((in->mesh->nverts + 1) * sizeof *E.vmap);
    E.stamp = calloc(in->mesh->nverts + 1, sizeof *E.stamp);
    E.max_components = 64 * (in->tree->nnodes + 16) + (1u << 20);
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

ag_status ag_edit_resize(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_edit_resize_solver *s;
    double t0 = now_ms();
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
        rep->solve_ms = now_ms() - t0; /* equations, factorization and solve */
    if (!st)
        st = ag_edit_resize_emit(in, boxes, op->budget, out, rep, err);
    free(boxes);
    ag_edit_resize_solver_free(s);
    return st;
}
