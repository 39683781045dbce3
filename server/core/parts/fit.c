#include "fit.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../edit/attach.h"
#include "../edit/lsq.h"
#include "../proc/gframe.h"
#include "../proc/splittree.h"
#include "fitcount.h"
#include "gcopy.h"

#define RIGID_RELAXED_WEIGHT 100.0

typedef struct {
    uint32_t *up;   /* per coordinate: union-find parent */
    double *off;    /* x = x_up + off */
    int8_t *fixed;  /* per root */
    double *val;
    size_t n;
} classes;

static uint32_t find(classes *c, uint32_t x, double *off)
{
    double o = 0;
    uint32_t r = x;
    while (c->up[r] != r) {
        o += c->off[r];
        r = c->up[r];
    }
    /* path compression keeping offsets */
    double acc = o;
    while (c->up[x] != x) {
        uint32_t nx = c->up[x];
        double ox = c->off[x];
        c->up[x] = r;
        c->off[x] = acc;
        acc -= ox;
        x = nx;
    }
    *off = o;
    return r;
}

/* x - y = d as a hard equation; returns 0, or -1 when it contradicts the classes (tol). */
static int merge(classes *c, uint32_t x, uint32_t y, double d, double tol)
{
    double ox, oy;
    uint32_t rx = find(c, x, &ox), ry = find(c, y, &oy);
    /* rx + ox - (ry + oy) = d  ->  rx = ry + (d - ox + oy) */
    double k = d - ox + oy;
    if (rx == ry)
        return fabs(k) <= tol ? 0 : -1;
    if (c->fixed[rx] && c->fixed[ry])
        return fabs(c->val[rx] - (c->val[ry] + k)) <= tol ? 0 : -1;
    if (c->fixed[rx]) { /* hang ry under rx: ry = rx - k */
        c->up[ry] = rx;
        c->off[ry] = -k;
        return 0;
    }
    c->up[rx] = ry;
    c->off[rx] = k;
    return 0;
}

/* x = v */
static int fix(classes *c, uint32_t x, double v, double tol)
{
    double o;
    uint32_t r = find(c, x, &o);
    if (c->fixed[r])
        return fabs(c->val[r] + o - v) <= tol ? 0 : -1;
    c->fixed[r] = 1;
    c->val[r] = v - o;
    return 0;
}

typedef struct {
    uint32_t coord[4];
    double coef[4];
    int nterms;
    double rhs, w;
} soft;

typedef struct {
    soft *s;
    size_t n, cap;
} softs;

static int push(softs *q, soft s)
{
    if (q->n == q->cap) {
        size_t nc = q->cap ? 2 * q->cap : 256;
        soft *p = realloc(q->s, nc * sizeof *p);
        if (!p)
            return -1;
        q->s = p;
        q->cap = nc;
    }
    q->s[q->n++] = s;
    return 0;
}

static double coord_of(const ag_box *b, int c) { return c < 3 ? b->min[c] : b->max[c - 3]; }

typedef struct {
    int32_t item;   /* the item it is (a cell of), -1 for the body's box */
    ag_box box;
} element;

static int grow_el(element **el, size_t *cap)
{
    element *e = realloc(*el, 2 * *cap * sizeof *e);
    if (!e)
        return -1;
    *el = e;
    *cap *= 2;
    return 0;
}

static int by_min_x(const void *a, const void *b, void *ctx)
{
    const element *e = ctx;
    double x = e[*(const uint32_t *)a].box.min[0], y = e[*(const uint32_t *)b].box.min[0];
    return x < y ? -1 : x > y;
}


static ag_box new_box(const double *nv, size_t e)
{
    ag_box b;
    for (int a = 0; a < 3; a++) {
        b.min[a] = nv[6 * e + a];
        b.max[a] = nv[6 * e + 3 + a];
        if (b.max[a] < b.min[a])
            b.max[a] = b.min[a] = 0.5 * (b.min[a] + b.max[a]);
    }
    return b;
}

static int whole_box(const ag_box *b, const double size[3], double tol)
{
    int whole = 1;
    for (int a = 0; a < 3; a++)
        whole &= fabs(b->min[a]) <= tol && fabs(b->max[a] - size[a]) <= tol;
    return whole;
}

/* Two splits from p to box b: `a` the intermediate node, `node` the box. */
static ag_status split_to(ag_grule *out, const char *a, const char *node, const ag_box *b)
{
    double v1[3] = {b->min[0], b->min[1], b->min[2]};
    double v2[3] = {b->max[0] - b->min[0], b->max[1] - b->min[1], b->max[2] - b->min[2]};
    ag_status st = ag_grammar_add_split(out, a, "p", v1, 8, 0, 0);
    return st ? st : ag_grammar_add_split(out, node, a, v2, 1, 0, 0);
}

/* A pattern whose fitted cells still form its lattice is emitted as the pattern over their
 * union with the new vectors; otherwise every cell is applied on its own. */
static ag_status emit_pattern(ag_grule *out, const ag_gstmt *s, const element *el, size_t c0,
                              const double *nv, const double size[3], double tol,
                              unsigned *fresh)
{
    const uint32_t *n = s->counts;
    size_t cells = (size_t)n[0] * n[1] * n[2];
    ag_box first = new_box(nv, c0);
    double vec[3][3] = {{0}};
    /* the lattice vectors from the cells next to the first one along each count */
    size_t stride[3] = {1, n[0], (size_t)n[0] * n[1]};
    for (int k = 0; k < 3; k++)
        if (n[k] > 1) {
            ag_box b = new_box(nv, c0 + stride[k]);
            for (int a = 0; a < 3; a++)
                vec[k][a] = b.min[a] - first.min[a];
        }
    int regular = 1;
    ag_box uni = first;
    for (uint32_t z = 0; z < n[2] && regular; z++)
        for (uint32_t y = 0; y < n[1] && regular; y++)
            for (uint32_t x = 0; x < n[0] && regular; x++) {
                ag_box b = new_box(nv, c0 + x + stride[1] * y + stride[2] * z);
                for (int a = 0; a < 3; a++) {
                    double want = first.min[a] + x * vec[0][a] + y * vec[1][a] + z * vec[2][a];
                    regular &= fabs(b.min[a] - want) <= tol &&
                               fabs((b.max[a] - b.min[a]) - (first.max[a] - first.min[a])) <= tol;
                    uni.min[a] = fmin(uni.min[a], b.min[a]);
                    uni.max[a] = fmax(uni.max[a], b.max[a]);
                }
            }
    (void)el;
    char a1[24], node[24];
    ag_status st = AG_OK;
    if (regular) {
        snprintf(node, sizeof node, "p");
        if (!whole_box(&uni, size, tol)) {
            snprintf(a1, sizeof a1, "g%ua", ++*fresh);
            snprintf(node, sizeof node, "g%ub", *fresh);
            if ((st = split_to(out, a1, node, &uni)))
                return st;
        }
        if ((st = ag_gcopy_stmt(out, s, node, NULL, NULL)))
            return st;
        ag_gstmt *d = &out->stmts[out->nstmts - 1];
        for (int k = 0; k < 3; k++) {
            if (s->subdivide == 1)
                d->step[k] = vec[k][k];
            for (int a = 0; a < 3; a++)
                d->vec[k][a] = vec[k][a];
        }
        return AG_OK;
    }
    for (size_t c = 0; c < cells && !st; c++) {
        ag_box b = new_box(nv, c0 + c);
        snprintf(a1, sizeof a1, "g%ua", ++*fresh);
        snprintf(node, sizeof node, "g%ub", *fresh);
        if (!(st = split_to(out, a1, node, &b)))
            st = ag_grammar_add_apply(out, s->callee, node, s->rot, NULL, NULL, 0, 0);
    }
    return st;
}

/* Every item on its box, by two splits from p (none for the whole box). */
static ag_status emit_items(ag_grule *out, const ag_fit_items *it, const double size[3],
                            double tol)
{
    ag_status st = AG_OK;
    for (size_t i = 0; i < it->n && !st; i++) {
        char a1[24], node[24] = "p";
        if (!whole_box(&it->v[i].box, size, tol)) {
            snprintf(a1, sizeof a1, "f%zua", i);
            snprintf(node, sizeof node, "f%zub", i);
            st = split_to(out, a1, node, &it->v[i].box);
        }
        if (!st)
            st = ag_gcopy_stmt(out, &it->v[i].s, node, NULL, NULL);
    }
    return st;
}

ag_status ag_fit_body(const ag_grammar *g, const ag_grule *r, const double size[3], ag_grule *out,
                      ag_fit_report *rep, ag_error *err)
{
    (void)g;
    ag_fit_report local = {0};
    if (!rep)
        rep = &local;
    memset(rep, 0, sizeof *rep);
    memcpy(out->size, size, 3 * sizeof *size);
    const double *S0 = r->size;
    for (int a = 0; a < 3; a++)
        if (!isfinite(size[a]) || size[a] < 0)
            return ag_error_set(err, AG_ERR_INVALID, 0, "the fitted size is not finite");
    /* the same size: the body as it is (no solve) */
    {
        double d = 0, sc = 0;
        for (int a = 0; a < 3; a++) {
            d = fmax(d, fabs(size[a] - S0[a]));
            sc = fmax(sc, fabs(S0[a]));
        }
        if (d <= 1e-12 * (sc + 1)) {
            for (size_t i = 0; i < r->nstmts; i++)
                if (ag_gcopy_stmt(out, &r->stmts[i], NULL, NULL, NULL))
                    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            rep->elements = r->nstmts;
            return AG_OK;
        }
    }
    size_t nn = r->nnodes ? r->nnodes : 1;
    ag_box *nb = malloc(nn * sizeof *nb);
    ag_fit_items items = {0};
    element *el = NULL;
    classes c = {0};
    softs q = {0};
    uint32_t *order = NULL, *rows = NULL, *cols = NULL, *col_of = NULL;
    double *vals = NULL, *b = NULL, *x = NULL, *nv = NULL;
    size_t *cell0 = NULL;
    ag_lsq *lsq = NULL;
    ag_status st = AG_ERR_NOMEM;
    if (!nb)
        goto done;
    /* the applications on their nodes' boxes */
    nb[0] = (ag_box){{0, 0, 0}, {S0[0], S0[1], S0[2]}};
    for (size_t i = 0; i < r->nstmts; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            nb[s->node_ix] = ag_splittree_child_box(&nb[s->parent_ix], s->v, s->octant);
            continue;
        }
        ag_fit_item it = {*s, nb[s->node_ix]};
        if (ag_fit_items_push(&items, &it))
            goto done;
    }
    double diag = sqrt(S0[0] * S0[0] + S0[1] * S0[1] + S0[2] * S0[2]);
    double diag2 = sqrt(size[0] * size[0] + size[1] * size[1] + size[2] * size[2]);
    double eps = 1e-7 * (diag > 0 ? diag : 1), tol = 1e-7 * (diag + diag2 + 1e-9);
    /* counts: repeated columns re-laid at their own period (fitcount.h) */
    double S[3] = {S0[0], S0[1], S0[2]};
    for (int a = 0; a < 3; a++)
        if ((st = ag_fit_count_axis(&items, S, a, size[a], tol, rep->columns[a], err)))
            goto done;
    int solve = 0;
    for (int a = 0; a < 3; a++)
        solve |= fabs(size[a] - S[a]) > tol;
    if (!solve) { /* every axis that changed was re-laid: the items are in place */
        size_t cells = 0;
        for (size_t i = 0; i < items.n; i++)
            cells += items.v[i].s.subdivide ? (size_t)items.v[i].s.counts[0] *
                                                  items.v[i].s.counts[1] * items.v[i].s.counts[2]
                                            : 1;
        if (cells > AG_FIT_MAX_ELEMENTS) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                              "the part's root would apply %zu nodes (at most %d can be fitted)",
                              cells, AG_FIT_MAX_ELEMENTS);
            goto done;
        }
        rep->elements = cells;
        if ((st = emit_items(out, &items, size, tol)))
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    st = AG_ERR_NOMEM;
    /* the elements: the body's box, every single application, every pattern's cells */
    size_t ne = 1, cap_el = items.n + 1;
    el = malloc(cap_el * sizeof *el);
    cell0 = malloc((items.n + 1) * sizeof *cell0);
    if (!el || !cell0)
        goto done;
    el[0] = (element){-1, {{0, 0, 0}, {S[0], S[1], S[2]}}};
    for (size_t i = 0; i < items.n; i++) {
        const ag_fit_item *it = &items.v[i];
        const ag_gstmt *s = &it->s;
        cell0[i] = ne;
        if (!s->subdivide) {
            if (ne == cap_el && grow_el(&el, &cap_el))
                goto done;
            el[ne++] = (element){(int32_t)i, it->box};
            continue;
        }
        /* a pattern: its cells are the members */
        size_t cells = (size_t)s->counts[0] * s->counts[1] * s->counts[2];
        if (ne + cells > AG_FIT_MAX_ELEMENTS + 1) {
            ne += cells;
            break;
        }
        ag_gframe_cells gc;
        ag_gframe_cells_of(s, &it->box, &gc);
        for (uint32_t z = 0; z < s->counts[2]; z++)
            for (uint32_t y = 0; y < s->counts[1]; y++)
                for (uint32_t xx = 0; xx < s->counts[0]; xx++) {
                    if (ne == cap_el && grow_el(&el, &cap_el))
                        goto done;
                    el[ne++] = (element){(int32_t)i, ag_gframe_cell(&gc, xx, y, z)};
                }
    }
    if (ne > AG_FIT_MAX_ELEMENTS) {
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                          "the part's root applies %zu nodes (at most %d can be fitted)", ne - 1,
                          AG_FIT_MAX_ELEMENTS);
        goto done;
    }
    rep->elements = ne - 1;
    size_t nc = 6 * ne;
    c.n = nc;
    c.up = malloc(nc * sizeof *c.up);
    c.off = calloc(nc, sizeof *c.off);
    c.fixed = calloc(nc, 1);
    c.val = calloc(nc, sizeof *c.val);
    order = malloc(ne * sizeof *order);
    if (!c.up || !c.off || !c.fixed || !c.val || !order)
        goto done;
    for (size_t i = 0; i < nc; i++)
        c.up[i] = (uint32_t)i;
    for (int a = 0; a < 3; a++) {
        fix(&c, (uint32_t)a, 0, tol);
        fix(&c, (uint32_t)(3 + a), size[a], tol);
    }
    double ratio[3];
    for (int a = 0; a < 3; a++)
        ratio[a] = S[a] > 0 ? size[a] / S[a] : 1;
    /* an axis that keeps its size keeps every coordinate on it: no unknowns there */
    for (int a = 0; a < 3; a++)
        if (fabs(size[a] - S[a]) <= tol)
            for (size_t e = 1; e < ne; e++) {
                fix(&c, (uint32_t)(6 * e + a), el[e].box.min[a], tol);
                fix(&c, (uint32_t)(6 * e + 3 + a), el[e].box.max[a], tol);
            }
    /* pairs by a sweep along x: only boxes that meet on x can share or overlap anything */
    for (size_t i = 0; i < ne; i++)
        order[i] = (uint32_t)i;
    qsort_r(order, ne, sizeof *order, by_min_x, el);
    for (size_t oi = 0; oi < ne; oi++) {
        uint32_t i = order[oi];
        for (size_t oj = oi + 1; oj < ne; oj++) {
            uint32_t j = order[oj];
            if (el[j].box.min[0] > el[i].box.max[0] + eps)
                break;
            ag_attach at[12];
            size_t na = ag_attach_detect(&el[i].box, &el[j].box, eps, at);
            for (size_t k = 0; k < na; k++) {
                if (at[k].type == AG_ATTACH_CORNER) {
                    /* the contact holds in the fitted box too (an affine stretch keeps it) */
                    if (merge(&c, 6 * i + at[k].ci, 6 * j + at[k].cj, 0, tol) &&
                        push(&q, (soft){{6 * i + at[k].ci, 6 * j + at[k].cj}, {1, -1}, 2, 0,
                                        RIGID_RELAXED_WEIGHT}))
                        goto done;
                    continue;
                }
                /* a ratio: L the longer box on that axis */
                int a = at[k].ci;
                uint32_t L = at[k].swap ? j : i, Sm = at[k].swap ? i : j;
                double kk = at[k].k, w = ag_attach_weight(at[k].type);
                soft s = {.w = w, .nterms = 4};
                uint32_t aS = 6 * Sm + a, bS = 6 * Sm + 3 + a, aL = 6 * L + a, bL = 6 * L + 3 + a;
                if (at[k].form == 0) { /* (aS + bS)/2 - aL = k (bL - aL) */
                    s = (soft){{aS, bS, aL, bL}, {0.5, 0.5, kk - 1, -kk}, 4, 0, w};
                } else if (at[k].form == 1) { /* bS - aL = k (bS - aS) */
                    s = (soft){{bS, aL, aS}, {1 - kk, -1, kk}, 3, 0, w};
                } else { /* bL - aS = k (bS - aS) */
                    s = (soft){{bL, aS, bS}, {1, kk - 1, -kk}, 3, 0, w};
                }
                if (push(&q, s))
                    goto done;
            }
        }
    }
    /* rigid sizes of thin members, then every element's size and scaled place */
    for (size_t e = 1; e < ne; e++)
        for (int a = 0; a < 3; a++) {
            double len = el[e].box.max[a] - el[e].box.min[a];
            uint32_t lo = (uint32_t)(6 * e + a), hi = lo + 3;
            if (len <= AG_FIT_RIGID * S[a] && S[a] > 0 && fabs(size[a] - S[a]) > tol) {
                if (merge(&c, hi, lo, len, tol)) {
                    rep->rigid_relaxed++;
                    if (push(&q, (soft){{hi, lo}, {1, -1}, 2, len, RIGID_RELAXED_WEIGHT}))
                        goto done;
                } else {
                    rep->rigid++;
                }
            }
            if (push(&q, (soft){{hi, lo}, {1, -1}, 2, len * ratio[a],
                                ag_attach_weight(AG_ATTACH_SIZE)}))
                goto done;
            for (int k = 0; k < 2; k++) {
                uint32_t cc = k ? hi : lo;
                double v = coord_of(&el[e].box, k ? a + 3 : a) * ratio[a];
                if (push(&q, (soft){{cc}, {1}, 1, v, ag_attach_weight(AG_ATTACH_POSITION)}))
                    goto done;
            }
        }
    /* columns: the free class roots */
    col_of = malloc(nc * sizeof *col_of);
    if (!col_of)
        goto done;
    size_t ncols = 0;
    for (size_t i = 0; i < nc; i++)
        col_of[i] = c.up[i] == i && !c.fixed[i] ? (uint32_t)ncols++ : UINT32_MAX;
    rep->classes = ncols;
    size_t nnz = 0;
    rows = malloc((4 * q.n + 1) * sizeof *rows);
    cols = malloc((4 * q.n + 1) * sizeof *cols);
    vals = malloc((4 * q.n + 1) * sizeof *vals);
    b = calloc(q.n + 1, sizeof *b);
    x = calloc(ncols + 1, sizeof *x);
    nv = malloc(nc * sizeof *nv);
    if (!rows || !cols || !vals || !b || !x || !nv)
        goto done;
    size_t nrows = 0;
    for (size_t k = 0; k < q.n; k++) {
        const soft *s = &q.s[k];
        double sw = sqrt(s->w), rhs = s->rhs;
        size_t start = nnz;
        for (int t = 0; t < s->nterms; t++) {
            double o;
            uint32_t rt = find(&c, s->coord[t], &o);
            rhs -= s->coef[t] * o;
            if (c.fixed[rt]) {
                rhs -= s->coef[t] * c.val[rt];
                continue;
            }
            rows[nnz] = (uint32_t)nrows;
            cols[nnz] = col_of[rt];
            vals[nnz] = sw * s->coef[t];
            nnz++;
        }
        if (nnz == start)
            continue; /* only fixed coordinates */
        b[nrows++] = sw * rhs;
    }
    rep->equations = nrows;
    if (ncols) {
        if ((st = ag_lsq_create(nrows, ncols, nnz, rows, cols, vals, &lsq, err)) ||
            (st = ag_lsq_solve(lsq, b, x, err)))
            goto done;
    }
    for (size_t i = 0; i < nc; i++) {
        double o;
        uint32_t rt = find(&c, (uint32_t)i, &o);
        nv[i] = (c.fixed[rt] ? c.val[rt] : x[col_of[rt]]) + o;
    }
    /* emission: every application on its new box, by two splits from p */
    unsigned fresh = 0;
    st = AG_OK;
    for (size_t i = 0; i < items.n && !st; i++) {
        const ag_gstmt *s = &items.v[i].s;
        if (s->subdivide) {
            st = emit_pattern(out, s, el, cell0[i], nv, size, tol, &fresh);
            continue;
        }
        size_t e = cell0[i];
        ag_box nbx = new_box(nv, e);
        char node[24] = "p";
        if (!whole_box(&nbx, size, tol)) {
            char a1[24];
            snprintf(a1, sizeof a1, "f%zua", e);
            snprintf(node, sizeof node, "f%zub", e);
            if ((st = split_to(out, a1, node, &nbx)))
                break;
        }
        st = ag_gcopy_stmt(out, s, node, NULL, NULL);
    }
    if (st)
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
done:
    if (st == AG_ERR_NOMEM && err && !err->text[0])
        ag_error_set(err, st, 0, "out of memory");
    ag_lsq_free(lsq);
    free(nb);
    free(items.v);
    free(el);
    free(c.up);
    free(c.off);
    free(c.fixed);
    free(c.val);
    free(q.s);
    free(order);
    free(rows);
    free(cols);
    free(col_of);
    free(vals);
    free(b);
    free(x);
    free(nv);
    free(cell0);
    return st;
}
