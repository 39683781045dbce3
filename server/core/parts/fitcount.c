#include "fitcount.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/hash.h"
#include "../base/tolerance.h"
#include "../proc/gframe.h"
#include "../proc/weld.h"
#include "fit.h"

/* Work limits: columns of an axis, and the new count. */
#define MAX_COLUMNS 1000000L

ag_status ag_fit_items_push(ag_fit_items *it, const ag_fit_item *x)
{
    if (it->n == it->cap) {
        size_t nc = it->cap ? 2 * it->cap : 256;
        ag_fit_item *v = realloc(it->v, nc * sizeof *v);
        if (!v)
            return AG_ERR_NOMEM;
        it->v = v;
        it->cap = nc;
    }
    it->v[it->n++] = *x;
    return AG_OK;
}

/* Pattern s's lattice vector along axis a (its index; *step its length), -1 when it has none
 * or one that is not along a alone (oblique, backwards, two vectors with a part along a). */
static int lattice_vector(const ag_gstmt *s, int a, double tol, double *step)
{
    if (!s->subdivide)
        return -1;
    int found = -1;
    for (int k = 0; k < 3; k++) {
        if (s->counts[k] < 2)
            continue;
        double v[3];
        for (int b = 0; b < 3; b++)
            v[b] = s->subdivide == 2 ? s->vec[k][b] : k == b ? s->step[b] : 0;
        if (fabs(v[a]) <= tol)
            continue;
        if (found >= 0 || v[a] < 0)
            return -1;
        for (int b = 0; b < 3; b++)
            if (b != a && fabs(v[b]) > tol)
                return -1;
        found = k;
        *step = v[a];
    }
    return found;
}

static double cells_of(const ag_gstmt *s)
{
    return s->subdivide ? (double)s->counts[0] * s->counts[1] * s->counts[2] : 1;
}

typedef struct {
    double step, weight;
} step_weight;

static int by_step(const void *x, const void *y)
{
    double a = ((const step_weight *)x)->step, b = ((const step_weight *)y)->step;
    return a < b ? -1 : a > b;
}

/* The period along a: the step of the patterns along a with the most cells; 0 when none. */
static double period(const ag_fit_items *it, int a, double tol, ag_status *st)
{
    step_weight *sw = malloc((it->n + 1) * sizeof *sw);
    if (!sw) {
        *st = AG_ERR_NOMEM;
        return 0;
    }
    size_t m = 0;
    for (size_t i = 0; i < it->n; i++) {
        double step;
        if (lattice_vector(&it->v[i].s, a, tol, &step) >= 0)
            sw[m++] = (step_weight){step, cells_of(&it->v[i].s)};
    }
    qsort(sw, m, sizeof *sw, by_step);
    double best = 0, p = 0;
    for (size_t i = 0; i < m;) {
        size_t j = i;
        double w = 0;
        while (j < m && sw[j].step - sw[i].step <= tol)
            w += sw[j++].weight;
        if (w > best) {
            best = w;
            p = sw[i].step;
        }
        i = j;
    }
    free(sw);
    return p;
}

static int by_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return a < b ? -1 : a > b;
}

static int by_u64(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : a > b;
}

static uint64_t mix(uint64_t h, uint64_t x)
{
    h ^= x + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    return h;
}

static uint64_t quant(double x, double q) { return (uint64_t)(int64_t)llround(x / q); }

/* What one application puts in its column: callee, turn, kind, counts across the axis (kk:
 * the lattice vector that makes the columns, -1 for none), its cell's place in the column and
 * its box across the axis. Summed per column, so the order does not matter. */
static uint64_t content_hash(const ag_fit_item *x, int a, int kk, double rel, const ag_box *cell,
                             double q)
{
    uint64_t h = mix(ag_hash_text(x->s.callee), (uint64_t)x->s.rot);
    h = mix(h, (uint64_t)x->s.subdivide);
    for (int k = 0; k < 3; k++)
        h = mix(h, k == kk ? 0 : x->s.subdivide ? x->s.counts[k] : 1);
    h = mix(h, quant(rel, q));
    h = mix(h, quant(cell->max[a] - cell->min[a], q));
    for (int b = 0; b < 3; b++)
        if (b != a) {
            h = mix(h, quant(x->box.min[b], q));
            h = mix(h, quant(x->box.max[b], q));
        }
    return ag__mix64(h);
}

/* Not thin along a (resize's thin test, AG_EDIT_THIN_RATIO): a window's glass, not a mullion. */
static int thick(const ag_box *b, int a)
{
    double e[3], emax = 0;
    for (int k = 0; k < 3; k++)
        emax = fmax(emax, e[k] = b->max[k] - b->min[k]);
    return e[a] >= AG_EDIT_THIN_RATIO * emax && e[a] > 0;
}

enum { SPANS = 0, IN_COLUMN = 1, COLUMNS = 2 };

ag_status ag_fit_count_axis(ag_fit_items *items, double S[3], int a, double len, double tol,
                            unsigned cols[2], ag_error *err)
{
    cols[0] = cols[1] = 0;
    if (!(S[a] > tol) || fabs(len - S[a]) <= tol || !items->n)
        return AG_OK;
    ag_status st = AG_OK;
    double p = period(items, a, tol, &st);
    if (st)
        return ag_error_set(err, st, 0, "out of memory");
    if (!(p > 10 * tol))
        return AG_OK;
    size_t n = items->n;
    int8_t *kind = malloc(n), *kk = malloc(n);
    double *lo = malloc(n * sizeof *lo), *ph = malloc(n * sizeof *ph);
    uint64_t *colh = NULL, *sorted = NULL;
    uint8_t *thick_col = NULL;
    long *first = NULL, *last = NULL;
    ag_fit_items out = {0};
    if (!kind || !kk || !lo || !ph)
        goto nomem;
    /* what lies in columns, and their phases in the period */
    size_t nph = 0;
    double m = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        const ag_fit_item *x = &items->v[i];
        double step = 0;
        int k = lattice_vector(&x->s, a, tol, &step);
        double ext = x->box.max[a] - x->box.min[a];
        kk[i] = -1;
        if (k >= 0 && fabs(step - p) <= tol) {
            kind[i] = COLUMNS;
            kk[i] = (int8_t)k;
        } else {
            kind[i] = ext < p - tol ? IN_COLUMN : SPANS;
        }
        lo[i] = x->box.min[a];
        if (kind[i] == SPANS)
            continue;
        m = fmin(m, lo[i]);
        hi = fmax(hi, x->box.max[a]);
        double f = fmod(lo[i], p);
        ph[nph++] = f < 0 ? f + p : f;
    }
    if (!nph)
        goto keep;
    /* the columns begin after the widest gap between the phases */
    qsort(ph, nph, sizeof *ph, by_double);
    double gap = ph[0] + p - ph[nph - 1], b = ph[0];
    for (size_t i = 0; i + 1 < nph; i++)
        if (ph[i + 1] - ph[i] > gap) {
            gap = ph[i + 1] - ph[i];
            b = ph[i + 1];
        }
    double o = b + p * floor((m + tol - b) / p);
    long ncols = 0;
    for (size_t i = 0; i < n; i++) {
        if (kind[i] == SPANS)
            continue;
        long j = (long)floor((lo[i] - o + tol) / p);
        long e = j + (kind[i] == COLUMNS ? (long)items->v[i].s.counts[kk[i]] : 1);
        if (j < 0 || e > MAX_COLUMNS)
            goto keep;
        if (e > ncols)
            ncols = e;
    }
    if (ncols < 3)
        goto keep;
    /* the columns' content */
    double q = 10 * tol;
    colh = calloc((size_t)ncols, sizeof *colh);
    sorted = malloc((size_t)ncols * sizeof *sorted);
    thick_col = calloc((size_t)ncols, 1);
    if (!colh || !sorted || !thick_col)
        goto nomem;
    for (size_t i = 0; i < n; i++) {
        const ag_fit_item *x = &items->v[i];
        if (kind[i] == SPANS)
            continue;
        long j = (long)floor((lo[i] - o + tol) / p);
        double rel = lo[i] - (o + j * p);
        ag_box cell = x->box;
        if (x->s.subdivide) {
            ag_gframe_cells gc;
            ag_gframe_cells_of(&x->s, &x->box, &gc);
            cell = ag_gframe_cell(&gc, 0, 0, 0);
        }
        uint64_t h = content_hash(x, a, kk[i], rel, kind[i] == COLUMNS ? &cell : &x->box, q);
        int th = thick(&cell, a);
        long c = kind[i] == COLUMNS ? (long)x->s.counts[kk[i]] : 1;
        for (long t = 0; t < c; t++) {
            colh[j + t] += h;
            thick_col[j + t] |= (uint8_t)th;
        }
    }
    memcpy(sorted, colh, (size_t)ncols * sizeof *sorted);
    qsort(sorted, (size_t)ncols, sizeof *sorted, by_u64);
    uint64_t mode = 0;
    long best = 0;
    for (long i = 0; i < ncols;) {
        long j = i;
        while (j < ncols && sorted[j] == sorted[i])
            j++;
        if (j - i > best && sorted[i]) {
            best = j - i;
            mode = sorted[i];
        }
        i = j;
    }
    int thick_mode = 0;
    for (long j = 0; j < ncols && !thick_mode; j++)
        thick_mode = colh[j] == mode && thick_col[j];
    if (best < 3 || 2 * best < ncols || !thick_mode)
        goto keep;
    /* the new count: the same density, fewer while they would not fit */
    double span = hi - m;
    long k = lround((double)ncols * len / S[a]);
    if (k < 1)
        k = 1;
    if (k > MAX_COLUMNS)
        k = MAX_COLUMNS;
    while (k > 1 && span + (double)(k - ncols) * p > len + tol)
        k--;
    double nspan = span + (double)(k - ncols) * p;
    if (nspan > len + tol)
        goto keep; /* not even one column fits: the solve squeezes it */
    double ml = fmax(m, 0), mr = fmax(S[a] - hi, 0), room = fmax(len - nspan, 0);
    double lo2 = ml + mr > 0 ? room * ml / (ml + mr) : 0.5 * room;
    /* new column j copies old column src(j): per old column, the new ones copying it */
    first = malloc((size_t)ncols * sizeof *first);
    last = malloc((size_t)ncols * sizeof *last);
    if (!first || !last)
        goto nomem;
    for (long j = 0; j < ncols; j++)
        first[j] = last[j] = -1;
    for (long j = 0; j < k; j++) {
        long s = k == 1 ? (ncols - 1) / 2 : lround((double)j * (ncols - 1) / (double)(k - 1));
        if (first[s] < 0)
            first[s] = j;
        last[s] = j;
    }
    /* what the new columns hold, refused before it is made past what a fit takes */
    double total = 0;
    for (size_t i = 0; i < n; i++) {
        const ag_fit_item *x = &items->v[i];
        if (kind[i] == SPANS) {
            total += cells_of(&x->s);
            continue;
        }
        long j = (long)floor((lo[i] - o + tol) / p);
        if (kind[i] == IN_COLUMN) {
            total += first[j] < 0 ? 0 : cells_of(&x->s) * (double)(last[j] - first[j] + 1);
            continue;
        }
        long c = (long)x->s.counts[kk[i]], t0 = -1, t1 = -1;
        for (long t = j; t < j + c; t++)
            if (first[t] >= 0) {
                t0 = t0 < 0 ? first[t] : t0;
                t1 = last[t];
            }
        if (t0 >= 0)
            total += cells_of(&x->s) / (double)c * (double)(t1 - t0 + 1);
    }
    if (total > AG_FIT_MAX_ELEMENTS) {
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                          "the part's %ld columns would become %ld, %.0f nodes (at most "
                          "%d can be fitted)",
                          ncols, k, total, AG_FIT_MAX_ELEMENTS);
        goto keep;
    }
    double ratio = len / S[a], shift = lo2 - m;
    for (size_t i = 0; i < n && !st; i++) {
        ag_fit_item x = items->v[i];
        if (kind[i] == SPANS) { /* stretched with the body */
            x.box.min[a] *= ratio;
            x.box.max[a] *= ratio;
            if (x.s.subdivide == 1)
                x.s.step[a] *= ratio;
            else if (x.s.subdivide == 2)
                for (int v = 0; v < 3; v++)
                    x.s.vec[v][a] *= ratio;
            st = ag_fit_items_push(&out, &x);
            continue;
        }
        long j = (long)floor((lo[i] - o + tol) / p);
        if (kind[i] == IN_COLUMN) {
            for (long t = first[j]; t >= 0 && t <= last[j] && !st; t++) {
                ag_fit_item y = x;
                double d = shift + (double)(t - j) * p;
                y.box.min[a] += d;
                y.box.max[a] += d;
                st = ag_fit_items_push(&out, &y);
            }
            continue;
        }
        long c = (long)x.s.counts[kk[i]], t0 = -1, t1 = -1;
        for (long t = j; t < j + c; t++)
            if (first[t] >= 0) {
                if (t0 < 0)
                    t0 = first[t];
                t1 = last[t];
            }
        if (t0 < 0)
            continue; /* none of its columns is copied */
        long c2 = t1 - t0 + 1;
        double ext = x.box.max[a] - x.box.min[a];
        x.box.min[a] += shift + (double)(t0 - j) * p;
        x.box.max[a] = x.box.min[a] + ext + (double)(c2 - c) * p;
        x.s.counts[kk[i]] = (uint32_t)c2;
        st = ag_fit_items_push(&out, &x);
    }
    if (st)
        goto nomem;
    free(items->v);
    *items = out;
    out.v = NULL;
    S[a] = len;
    cols[0] = (unsigned)ncols;
    cols[1] = (unsigned)k;
    goto keep;
nomem:
    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
keep:
    free(kind);
    free(kk);
    free(lo);
    free(ph);
    free(colh);
    free(sorted);
    free(thick_col);
    free(first);
    free(last);
    free(out.v);
    return st;
}
