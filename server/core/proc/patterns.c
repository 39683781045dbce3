#include "patterns.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"
#include "../base/search.h"
#include "../base/tolerance.h"
#include "weld.h"

/* Work limits of the fits: a grid of more steps per axis, a lattice over more instances or
 * with larger indices is not looked for (the instances stay as they are). */
#define GRID_MAX_STEPS 1e6
#define LATTICE_MAX_INSTANCES 4096
#define LATTICE_MAX_INDEX 1000000

typedef struct {
    int32_t rule;
    uint8_t rot;
    int32_t node;
    int32_t slot; /* the child of the parent the node hangs from */
} inst;

static int cmp_inst(const void *a, const void *b)
{
    const inst *x = a, *y = b;
    if (x->rule != y->rule)
        return x->rule < y->rule ? -1 : 1;
    if (x->rot != y->rot)
        return x->rot < y->rot ? -1 : 1;
    return x->node < y->node ? -1 : x->node > y->node;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Per axis grid fit of the instances' min corners: counts, step, and each instance's index.
 * Returns 1 for a complete grid. */
static int grid_fit(const ag_splittree *t, const inst *g, size_t n, double tol, uint32_t counts[3],
                    double step[3], double origin[3], uint32_t *idx, double *tmp, uint8_t *seen)
{
    for (int a = 0; a < 3; a++) {
        for (size_t i = 0; i < n; i++)
            tmp[i] = t->nodes[g[i].node].box.min[a];
        qsort(tmp, n, sizeof *tmp, cmp_double);
        double lo = tmp[0], d = INFINITY;
        for (size_t i = 1; i < n; i++) {
            double gap = tmp[i] - tmp[i - 1];
            if (gap > tol && gap < d)
                d = gap;
        }
        origin[a] = lo;
        if (!isfinite(d)) {
            counts[a] = 1;
            step[a] = 0;
            for (size_t i = 0; i < n; i++)
                idx[3 * i + a] = 0;
            continue;
        }
        /* refine the step over the whole span so errors do not accumulate */
        double span = tmp[n - 1] - lo;
        double m = floor(span / d + 0.5);
        if (m < 1 || m > GRID_MAX_STEPS)
            return 0;
        d = span / m;
        counts[a] = (uint32_t)m + 1;
        step[a] = d;
        for (size_t i = 0; i < n; i++) {
            double x = (t->nodes[g[i].node].box.min[a] - lo) / d;
            double r = floor(x + 0.5);
            if (fabs(x - r) * d > tol)
                return 0;
            idx[3 * i + a] = (uint32_t)r;
        }
    }
    size_t cells = (size_t)counts[0] * counts[1] * counts[2];
    if (cells != n)
        return 0;
    memset(seen, 0, n);
    for (size_t i = 0; i < n; i++) {
        size_t c = (idx[3 * i + 2] * (size_t)counts[1] + idx[3 * i + 1]) * counts[0] + idx[3 * i];
        if (c >= n || seen[c])
            return 0;
        seen[c] = 1;
    }
    return 1;
}

/* A pattern found under one parent, applied after all of the parent's groups are done. */
typedef struct {
    size_t first, n; /* members in `members`, in cell order */
    uint32_t counts[3];
    double step[3];
    int nvec;        /* 0 = axis-aligned grid */
    double vec[3][3];
} found;

typedef struct {
    inst *members;
    size_t nmembers, capm;
    found *list;
    size_t n, cap;
} foundset;

static int add_found(foundset *f, const inst *m, size_t n, const uint32_t counts[3],
                     const double step[3], int nvec, const double vec[][3])
{
    if (AG_ARRAY_RESERVE_MORE(f->members, f->capm, f->nmembers, n) ||
        AG_ARRAY_RESERVE(f->list, f->cap, f->n + 1))
        return -1;
    memcpy(f->members + f->nmembers, m, n * sizeof *m);
    found *x = &f->list[f->n++];
    x->first = f->nmembers;
    x->n = n;
    memcpy(x->counts, counts, sizeof x->counts);
    memcpy(x->step, step, sizeof x->step);
    x->nvec = nvec;
    memset(x->vec, 0, sizeof x->vec);
    for (int k = 0; k < nvec; k++)
        memcpy(x->vec[k], vec[k], sizeof x->vec[k]);
    f->nmembers += n;
    return 0;
}

/* Detaches every member's slot from the parent in one pass, then adds the pattern nodes. */
static ag_status apply_found(ag_splittree *t, int32_t parent, foundset *f, uint8_t *moved)
{
    if (!f->n)
        return AG_OK;
    for (size_t i = 0; i < f->nmembers; i++)
        moved[f->members[i].slot] = 1;
    int32_t prev = -1;
    for (int32_t s = t->nodes[parent].first_child, nx; s >= 0; s = nx) {
        nx = t->nodes[s].next_sibling;
        if (moved[s]) {
            if (prev >= 0)
                t->nodes[prev].next_sibling = nx;
            else
                t->nodes[parent].first_child = nx;
            if (t->nodes[parent].last_child == s)
                t->nodes[parent].last_child = prev;
            for (int32_t k = s; k >= 0 && t->nodes[k].kind == AG_NODE_SPLIT;) {
                int32_t c = t->nodes[k].first_child;
                t->nodes[k].kind = AG_NODE_DEAD;
                k = c;
            }
            moved[s] = 0;
        } else {
            prev = s;
        }
    }
    for (size_t p = 0; p < f->n; p++) {
        const found *x = &f->list[p];
        const inst *g = f->members + x->first;
        ag_box b = t->nodes[g[0].node].box;
        for (size_t i = 1; i < x->n; i++)
            ag_box_extend_box(&b, &t->nodes[g[i].node].box);
        ag_status st = AG_ARRAY_RESERVE(t->patterns, t->cap_patterns, t->npatterns + 1);
        if (st)
            return st;
        int32_t pn = ag_splittree_insert(t, parent, &b, AG_NODE_PATTERN);
        if (pn < 0)
            return AG_ERR_NOMEM;
        ag_pattern *pt = &t->patterns[t->npatterns];
        pt->rule = g[0].rule;
        pt->rot = g[0].rot;
        memcpy(pt->counts, x->counts, sizeof pt->counts);
        memcpy(pt->step, x->step, sizeof pt->step);
        pt->nvec = (uint8_t)x->nvec;
        memcpy(pt->vec, x->vec, sizeof pt->vec);
        pt->node = pn;
        t->nodes[pn].pattern = (int32_t)t->npatterns++;
        t->nodes[pn].first_child = t->nodes[pn].last_child = -1;
        for (size_t i = 0; i < x->n; i++) {
            int32_t v = g[i].node;
            t->nodes[v].octant = 0;
            memset(t->nodes[v].pivot, 0, sizeof t->nodes[v].pivot);
            ag_splittree_attach(t, pn, v);
        }
    }
    f->n = 0;
    f->nmembers = 0;
    return AG_OK;
}

#define OFF_LATTICE INT64_MIN

/* Points a vector so that its largest component is positive (a canonical direction). */
static void flip_positive(double v[3])
{
    int m = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(v[a]) > fabs(v[m]))
            m = a;
    if (v[m] < 0)
        for (int a = 0; a < 3; a++)
            v[a] = -v[a];
}

/* Lattice fit of the instances' min corners: o + i a (+ j b) for vectors a, b in any
 * direction (the shortest offset between two instances, then the shortest one off a's
 * line). On success ij[2k], ij[2k+1] hold instance k's indices (from 0) and counts the
 * extent; *complete tells whether every lattice cell holds an instance. */
/* Instances in the order of their boxes' min x (then index): the closest-pair searches
 * below visit the pairs in that order. */
typedef struct {
    double x;
    size_t k;
} by_x;

static int cmp_by_x(const void *a, const void *b)
{
    const by_x *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return p->k < q->k ? -1 : p->k > q->k;
}

/* One closest-offset search of lattice_fit over points P (3 per position, in sweep order):
 * for every pair of positions ii < kk in order, d = P[kk] - P[ii] becomes the best when it
 * is longer than tol, shorter than the best by more than tol and, with a line (direction
 * line, line . line = ll), farther than off_min from it. Returns the best length (INFINITY
 * for none), its offset in out.
 *
 * Only a pair shorter than the best at the start of ii can replace it, so once a best is
 * known the pairs of ii are taken from a grid of cells of that size (the 27 cells around
 * P[ii]) in kk order: the same pairs, in the same order, as a scan of all pairs, which is
 * n^2 on a facade whose windows share one x. Until then (and for every ii while nothing
 * qualifies), a scan in x order that stops where the x gap alone exceeds the best. */
/* Below this many points the scan is cheaper than the grid. */
#define CLOSEST_GRID_MIN 64

static double closest_offset(const double *P, size_t n, double tol, const double *line,
                             double ll, double off_min, double out[3], int *nomem)
{
    double best = INFINITY, h = 0;
    ag_radix_item *cells = NULL;
    ag_radix_index index = {0};
    uint32_t *cand = NULL;
    size_t ncand = 0, cap_cand = 0;
    for (size_t ii = 0; ii < n && !*nomem; ii++) {
        const double *x = P + 3 * ii;
        if (isfinite(best) && !cells && n > CLOSEST_GRID_MIN) { /* the grid, once */
            h = best > 0 ? best : 1;
            cells = malloc(n * sizeof *cells);
            if (!cells) {
                *nomem = 1;
                break;
            }
            for (size_t k = 0; k < n; k++) {
                cells[k].key = ag__cell_hash((int64_t)floor(P[3 * k] / h),
                                             (int64_t)floor(P[3 * k + 1] / h),
                                             (int64_t)floor(P[3 * k + 2] / h));
                cells[k].val = (uint32_t)k;
            }
            if (ag_radix_sort(cells, n) || ag_radix_index_build(&index, cells, n)) {
                *nomem = 1;
                break;
            }
        }
        ncand = 0;
        if (cells) {
            /* every point within the best of x on each axis (a little more: rounding) */
            double R = best * (1 + 1e-12) + 1e-300;
            int64_t lo[3], hi[3];
            for (int a = 0; a < 3; a++) {
                lo[a] = (int64_t)floor((x[a] - R) / h);
                hi[a] = (int64_t)floor((x[a] + R) / h);
            }
            for (int64_t cx = lo[0]; cx <= hi[0]; cx++)
                for (int64_t cy = lo[1]; cy <= hi[1]; cy++)
                    for (int64_t cz = lo[2]; cz <= hi[2]; cz++) {
                        uint64_t key = ag__cell_hash(cx, cy, cz);
                        for (size_t e = ag_radix_index_find(&index, key);
                             e < n && cells[e].key == key; e++) {
                            if (cells[e].val <= ii)
                                continue;
                            if (AG_ARRAY_RESERVE(cand, cap_cand, ncand + 1)) {
                                *nomem = 1;
                                break;
                            }
                            cand[ncand++] = cells[e].val;
                        }
                    }
            /* in kk order, once each (two cells may share a hash) */
            for (size_t i = 1; i < ncand; i++) {
                uint32_t v = cand[i];
                size_t j = i;
                while (j > 0 && cand[j - 1] > v) {
                    cand[j] = cand[j - 1];
                    j--;
                }
                cand[j] = v;
            }
        }
        size_t m = cells ? ncand : n;
        for (size_t c = 0; c < m; c++) {
            size_t kk;
            if (cells) {
                if (c > 0 && cand[c] == cand[c - 1])
                    continue;
                kk = cand[c];
            } else {
                kk = ii + 1 + c;
                if (kk >= n || P[3 * kk] - x[0] > best)
                    break;
            }
            const double *y = P + 3 * kk;
            double d[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
            double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (line) {
                double s = (d[0] * line[0] + d[1] * line[1] + d[2] * line[2]) / ll;
                double r[3] = {d[0] - s * line[0], d[1] - s * line[1], d[2] - s * line[2]};
                double off = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                if (!(off > off_min && l < best - tol))
                    continue;
            } else if (!(l > tol && l < best - tol)) {
                continue;
            }
            best = l;
            memcpy(out, d, 3 * sizeof *d);
        }
    }
    ag_radix_index_free(&index);
    free(cells);
    free(cand);
    return best;
}

static int lattice_fit(const ag_splittree *t, const inst *g, size_t n, double tol, int *nvec,
                       double vec[2][3], uint32_t counts[2], int64_t *ij, int *complete)
{
    if (n < 2 || n > LATTICE_MAX_INSTANCES)
        return 0;
    by_x *ord = malloc(n * sizeof *ord);
    double *P = malloc(3 * n * sizeof *P);
    if (!ord || !P) {
        free(ord);
        free(P);
        return 0;
    }
    for (size_t k = 0; k < n; k++) {
        ord[k].x = t->nodes[g[k].node].box.min[0];
        ord[k].k = k;
    }
    qsort(ord, n, sizeof *ord, cmp_by_x);
    for (size_t k = 0; k < n; k++)
        memcpy(P + 3 * k, t->nodes[g[ord[k].k].node].box.min, 3 * sizeof *P);
    free(ord);
    const ag_box *B0 = &t->nodes[g[0].node].box;
    double a[3] = {0, 0, 0};
    int nomem = 0;
    double best = closest_offset(P, n, tol, NULL, 0, 0, a, &nomem);
    if (nomem || !isfinite(best)) {
        free(P);
        return 0;
    }
    flip_positive(a);
    double aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    /* b: the shortest offset farther than OFF_LINE tol from a's line; none when every point
     * lies within half that of the line through the first (no pair can then be farther) */
    double off_min = AG_PROC_LATTICE_OFF_LINE * tol, b[3] = {0, 0, 0}, bestb = INFINITY;
    double spread = 0;
    for (size_t k = 1; k < n; k++) {
        double d[3] = {P[3 * k] - P[0], P[3 * k + 1] - P[1], P[3 * k + 2] - P[2]};
        double s = (d[0] * a[0] + d[1] * a[1] + d[2] * a[2]) / aa;
        double r[3] = {d[0] - s * a[0], d[1] - s * a[1], d[2] - s * a[2]};
        spread = fmax(spread, sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
    }
    if (!(spread <= 0.45 * off_min))
        bestb = closest_offset(P, n, tol, a, aa, off_min, b, &nomem);
    free(P);
    if (nomem)
        return 0;
    int nv = isfinite(bestb) ? 2 : 1;
    flip_positive(b);
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2], bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    double det = aa * bb - ab * ab;
    if (nv == 2 && !(fabs(det) > 0))
        return 0;
    int64_t lo[2] = {INT64_MAX, INT64_MAX}, hi[2] = {INT64_MIN, INT64_MIN};
    size_t fitted = 0;
    for (size_t k = 0; k < n; k++) {
        const ag_box *x = &t->nodes[g[k].node].box;
        double d[3] = {x->min[0] - B0->min[0], x->min[1] - B0->min[1], x->min[2] - B0->min[2]};
        double da = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        double c[2];
        if (nv == 1) {
            c[0] = da / aa;
            c[1] = 0;
        } else {
            double db = d[0] * b[0] + d[1] * b[1] + d[2] * b[2];
            c[0] = (bb * da - ab * db) / det;
            c[1] = (aa * db - ab * da) / det;
        }
        int64_t r0 = (int64_t)floor(c[0] + 0.5), r1 = (int64_t)floor(c[1] + 0.5);
        int off = llabs(r0) > LATTICE_MAX_INDEX || llabs(r1) > LATTICE_MAX_INDEX;
        for (int q = 0; q < 3 && !off; q++)
            off = fabs(d[q] - r0 * a[q] - r1 * b[q]) > tol;
        if (off) { /* not on the lattice: left out of its runs */
            ij[2 * k] = ij[2 * k + 1] = OFF_LATTICE;
            continue;
        }
        fitted++;
        ij[2 * k] = r0;
        ij[2 * k + 1] = r1;
        for (int q = 0; q < 2; q++) {
            if (ij[2 * k + q] < lo[q])
                lo[q] = ij[2 * k + q];
            if (ij[2 * k + q] > hi[q])
                hi[q] = ij[2 * k + q];
        }
    }
    if (fitted < 2)
        return 0;
    for (size_t k = 0; k < n; k++)
        if (ij[2 * k] != OFF_LATTICE)
            for (int q = 0; q < 2; q++)
                ij[2 * k + q] -= lo[q];
    counts[0] = (uint32_t)(hi[0] - lo[0] + 1);
    counts[1] = (uint32_t)(hi[1] - lo[1] + 1);
    *nvec = nv;
    memcpy(vec[0], a, sizeof a);
    memcpy(vec[1], b, sizeof b);
    *complete = fitted == n && (size_t)counts[0] * counts[1] == n;
    if (*complete) {
        /* distinct cells */
        uint8_t *seen = calloc(n, 1);
        if (!seen)
            return 0;
        for (size_t k = 0; k < n && *complete; k++) {
            size_t c = (size_t)ij[2 * k + 1] * counts[0] + (size_t)ij[2 * k];
            if (c >= n || seen[c])
                *complete = 0;
            else
                seen[c] = 1;
        }
        free(seen);
    }
    return 1;
}

/* A lattice whose vectors each lie along a distinct axis is an axis-aligned grid. */
static int as_grid(int nvec, const double vec[][3], const uint32_t lc[], double tol,
                   uint32_t counts[3], double step[3], int axis_of[2])
{
    counts[0] = counts[1] = counts[2] = 1;
    step[0] = step[1] = step[2] = 0;
    int used = 0;
    for (int k = 0; k < nvec; k++) {
        int ax = -1;
        for (int a = 0; a < 3; a++) {
            int other = 0;
            for (int b2 = 0; b2 < 3; b2++)
                if (b2 != a && fabs(vec[k][b2]) > tol)
                    other = 1;
            if (!other && vec[k][a] > tol)
                ax = a;
        }
        if (ax < 0 || (used >> ax & 1))
            return 0;
        used |= 1 << ax;
        counts[ax] = lc[k];
        step[ax] = vec[k][ax];
        axis_of[k] = ax;
    }
    return 1;
}

/* Emits the instances (with lattice indices ij) as a pattern, in cell order. */
static int emit_lattice(foundset *f, const inst *g, size_t n, const int64_t *ij, int nvec,
                        double vec[2][3], const uint32_t lc[2], double tol, inst *sorted)
{
    uint32_t counts[3];
    double step[3];
    int axis_of[2] = {0, 0};
    if (as_grid(nvec, vec, lc, tol, counts, step, axis_of)) {
        for (size_t k = 0; k < n; k++) {
            size_t idx[3] = {0, 0, 0};
            for (int q = 0; q < nvec; q++)
                idx[axis_of[q]] = (size_t)ij[2 * k + q];
            sorted[(idx[2] * counts[1] + idx[1]) * counts[0] + idx[0]] = g[k];
        }
        return add_found(f, sorted, n, counts, step, 0, NULL);
    }
    for (size_t k = 0; k < n; k++)
        sorted[(size_t)ij[2 * k + 1] * lc[0] + (size_t)ij[2 * k]] = g[k];
    counts[0] = lc[0];
    counts[1] = nvec > 1 ? lc[1] : 1;
    counts[2] = 1;
    step[0] = step[1] = step[2] = 0;
    return add_found(f, sorted, n, counts, step, nvec, vec);
}

typedef struct {
    int64_t j, i;
    size_t k;
} runkey;

static int cmp_runkey(const void *p, const void *q)
{
    const runkey *x = p, *y = q;
    if (x->j != y->j)
        return x->j < y->j ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

/* Sorting instances by their min corner on two axes (rows along the third). The order goes
 * to the comparison as an argument (qsort_r), not through globals: proceduralizations run on
 * several worker threads at once. */
typedef struct {
    const ag_splittree *t;
    int ax[3]; /* the two other axes, then the row's axis */
} row_order;

static int cmp_row(const void *p, const void *q, void *arg)
{
    const row_order *o = arg;
    const ag_box *x = &o->t->nodes[((const inst *)p)->node].box;
    const ag_box *y = &o->t->nodes[((const inst *)q)->node].box;
    for (int k = 0; k < 3; k++)
        if (x->min[o->ax[k]] != y->min[o->ax[k]])
            return x->min[o->ax[k]] < y->min[o->ax[k]] ? -1 : 1;
    return 0;
}

/* Rows along axis a: runs of instances (sorted) sharing the other two coordinates. Calls
 * back with each run; returns the number of instances in runs of at least minn. */
static size_t rows(const ag_splittree *t, inst *g, size_t n, int a, size_t minn, double tol,
                   int (*cb)(void *, inst *, size_t), void *user, int *fail)
{
    int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
    row_order order = {t, {b1, b2, a}};
    qsort_r(g, n, sizeof *g, cmp_row, &order);
    size_t cover = 0;
    for (size_t i = 0, j; i < n; i = j) {
        const ag_box *x = &t->nodes[g[i].node].box;
        for (j = i + 1; j < n; j++) {
            const ag_box *y = &t->nodes[g[j].node].box;
            if (fabs(x->min[b1] - y->min[b1]) > tol || fabs(x->min[b2] - y->min[b2]) > tol)
                break;
        }
        if (j - i >= minn) {
            cover += j - i;
            if (cb && cb(user, g + i, j - i)) {
                *fail = 1;
                return cover;
            }
        }
    }
    return cover;
}

typedef struct {
    const ag_splittree *t;
    foundset *f;
    int axis;
    uint32_t *idx;
    double *tmp;
    uint8_t *seen;
    inst *sorted;
} rowctx;

static int take_row(void *user, inst *r, size_t n)
{
    rowctx *c = user;
    uint32_t counts[3];
    double step[3], origin[3];
    if (!grid_fit(c->t, r, n, c->t->tol, counts, step, origin, c->idx, c->tmp, c->seen))
        return 0;
    for (size_t q = 0; q < n; q++)
        c->sorted[c->idx[3 * q + c->axis]] = r[q];
    return add_found(c->f, c->sorted, n, counts, step, 0, NULL);
}

/* Complete rows along one axis (instances sharing the other two coordinates); returns
 * non-zero when out of memory. */
static int axis_rows(const ag_splittree *t, inst *g, size_t n, size_t minn, foundset *fs,
                     uint32_t *idx, double *tmp, uint8_t *seen, inst *sorted)
{
    int best = -1, fail = 0;
    size_t best_cover = 0;
    for (int a = 0; a < 3; a++) {
        size_t cover = rows(t, g, n, a, minn, t->tol, NULL, NULL, &fail);
        if (cover > best_cover) {
            best_cover = cover;
            best = a;
        }
    }
    if (best < 0)
        return 0;
    rowctx rc = {t, fs, best, idx, tmp, seen, sorted};
    rows(t, g, n, best, minn, t->tol, take_row, &rc, &fail);
    return fail;
}

/* The scratch of one parent's instances, grown to the most instances a parent has (not the
 * tree's size: most of an edited tree's nodes are dead). */
typedef struct {
    inst *row, *run;
    uint32_t *idx;
    double *tmp;
    uint8_t *seen;
    int64_t *ij, *ij2;
    runkey *rk;
    size_t cap;
} scratch;

static int scratch_reserve(scratch *w, size_t n)
{
    if (n <= w->cap)
        return 0;
    /* doubled from 64, as long as the largest array per unit of capacity (rk) fits */
    size_t cap;
    if (ag_array_capacity(w->cap ? w->cap : 64, n, sizeof *w->rk, &cap))
        return -1;
    if (AG_ARRAY_RESIZE(w->row, cap + 1) || AG_ARRAY_RESIZE(w->run, cap + 1) ||
        AG_ARRAY_RESIZE(w->idx, 3 * cap + 3) || AG_ARRAY_RESIZE(w->tmp, cap + 1) ||
        AG_ARRAY_RESIZE(w->seen, cap + 1) || AG_ARRAY_RESIZE(w->ij, 2 * cap + 2) ||
        AG_ARRAY_RESIZE(w->ij2, 2 * cap + 2) || AG_ARRAY_RESIZE(w->rk, cap + 1))
        return -1;
    w->cap = cap;
    return 0;
}

ag_status ag_patterns_find(ag_splittree *t, const ag_patterns_options *opt, ag_error *err)
{
    size_t minn = opt && opt->min_instances ? opt->min_instances : 2;
    if (minn < 2)
        minn = 2;
    size_t N0 = t->nnodes, cap_buf = 0;
    inst *buf = NULL;
    scratch w = {0};
    uint8_t *moved = calloc(N0 + 1, 1);
    foundset fs = {0};
    ag_status st = AG_ERR_NOMEM;
    if (!moved)
        goto done;
    for (size_t pi = 0; pi < N0; pi++) {
        int kind = t->nodes[pi].kind;
        if (kind != AG_NODE_ROOT && kind != AG_NODE_COMPONENT)
            continue;
        size_t n = 0;
        for (int32_t s = t->nodes[pi].first_child; s >= 0; s = t->nodes[s].next_sibling) {
            int32_t e = ag_splittree_chain_end(t, s);
            if (e < 0 || t->nodes[e].kind != AG_NODE_COMPONENT || t->nodes[e].rule < 0 ||
                t->rule_count[t->nodes[e].rule] < minn)
                continue;
            if (AG_ARRAY_RESERVE(buf, cap_buf, n + 1))
                goto done;
            buf[n].rule = t->nodes[e].rule;
            buf[n].rot = t->nodes[e].rule_rot;
            buf[n].node = e;
            buf[n].slot = s;
            n++;
        }
        if (n < minn)
            continue;
        if (scratch_reserve(&w, n))
            goto done;
        inst *row = w.row, *run = w.run;
        uint32_t *idx = w.idx;
        double *tmp = w.tmp;
        uint8_t *seen = w.seen;
        int64_t *ij = w.ij, *ij2 = w.ij2;
        runkey *rk = w.rk;
        qsort(buf, n, sizeof *buf, cmp_inst);
        for (size_t i = 0, j; i < n; i = j) {
            for (j = i + 1; j < n && buf[j].rule == buf[i].rule && buf[j].rot == buf[i].rot; j++)
                ;
            size_t g = j - i;
            if (g < minn)
                continue;
            uint32_t counts[3];
            double step[3], origin[3];
            if (grid_fit(t, buf + i, g, t->tol, counts, step, origin, idx, tmp, seen)) {
                for (size_t k = 0; k < g; k++) {
                    size_t c = (idx[3 * k + 2] * (size_t)counts[1] + idx[3 * k + 1]) * counts[0] +
                               idx[3 * k];
                    row[c] = buf[i + k];
                }
                if (add_found(&fs, row, g, counts, step, 0, NULL))
                    goto done;
                continue;
            }
            /* any translation lattice (oblique facades); else its complete runs along a */
            int nvec, complete = 0;
            double vec[2][3];
            uint32_t lc[2];
            size_t before = fs.n;
            if (!lattice_fit(t, buf + i, g, t->tol, &nvec, vec, lc, ij, &complete)) {
                if (axis_rows(t, buf + i, g, minn, &fs, idx, tmp, seen, row))
                    goto done;
                continue;
            }
            if (complete) {
                if (emit_lattice(&fs, buf + i, g, ij, nvec, vec, lc, t->tol, row))
                    goto done;
                continue;
            }
            size_t nk = 0;
            for (size_t k = 0; k < g; k++) {
                if (ij[2 * k] == OFF_LATTICE)
                    continue;
                rk[nk].i = ij[2 * k];
                rk[nk].j = ij[2 * k + 1];
                rk[nk++].k = k;
            }
            qsort(rk, nk, sizeof *rk, cmp_runkey);
            for (size_t u = 0, w; u < nk; u = w) {
                for (w = u + 1; w < nk && rk[w].j == rk[u].j && rk[w].i == rk[w - 1].i + 1; w++)
                    ;
                size_t rn = w - u;
                if (rn < minn)
                    continue;
                for (size_t q = 0; q < rn; q++) {
                    run[q] = buf[i + rk[u + q].k];
                    ij2[2 * q] = (int64_t)q;
                    ij2[2 * q + 1] = 0;
                }
                uint32_t rc[2] = {(uint32_t)rn, 1};
                if (emit_lattice(&fs, run, rn, ij2, 1, vec, rc, t->tol, row))
                    goto done;
            }
            /* nothing on a lattice: complete rows along the axis that covers most */
            if (fs.n == before && axis_rows(t, buf + i, g, minn, &fs, idx, tmp, seen, row))
                goto done;
        }
        if ((st = apply_found(t, (int32_t)pi, &fs, moved)))
            goto done;
        st = AG_ERR_NOMEM;
    }
    st = AG_OK;
done:
    free(buf);
    free(w.row);
    free(w.run);
    free(w.idx);
    free(w.tmp);
    free(w.seen);
    free(w.ij);
    free(w.ij2);
    free(w.rk);
    free(moved);
    free(fs.members);
    free(fs.list);
    if (st)
        return ag_error_set(err, st, 0, "out of memory while finding patterns");
    return AG_OK;
}
