#include "simplify.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "predicates.h"

static double tri_area(const double *a, const double *b, const double *c)
{
    return fabs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / 2;
}

/* One loop: a linked ring; each round removes the corner of least area (loops of
 * footprints are small, a linear scan per removal is enough). */
static ag_status simplify_loop(double *xy, size_t *n, double area, double *moved,
                               size_t *removed)
{
    size_t m = *n;
    if (m <= 3)
        return AG_OK;
    size_t *prev = malloc(m * sizeof *prev), *next = malloc(m * sizeof *next);
    double *orig = malloc(2 * m * sizeof *orig);
    unsigned char *gone = calloc(m, 1);
    if (!prev || !next || !orig || !gone) {
        free(prev);
        free(next);
        free(orig);
        free(gone);
        return AG_ERR_NOMEM;
    }
    memcpy(orig, xy, 2 * m * sizeof *orig);
    for (size_t i = 0; i < m; i++) {
        prev[i] = (i + m - 1) % m;
        next[i] = (i + 1) % m;
    }
    size_t left = m;
    while (left > 3) {
        size_t best = m;
        double ba = area;
        for (size_t i = 0; i < m; i++) {
            if (gone[i])
                continue;
            double a = tri_area(&xy[2 * prev[i]], &xy[2 * i], &xy[2 * next[i]]);
            if (a < ba) {
                ba = a;
                best = i;
            }
        }
        if (best == m)
            break;
        gone[best] = 1;
        next[prev[best]] = next[best];
        prev[next[best]] = prev[best];
        left--;
        (*removed)++;
    }
    /* compact, then measure: every original corner against the simplified ring */
    size_t k = 0;
    for (size_t i = 0; i < m; i++)
        if (!gone[i]) {
            xy[2 * k] = xy[2 * i];
            xy[2 * k + 1] = xy[2 * i + 1];
            k++;
        }
    for (size_t i = 0; i < m && k < m; i++) {
        double d = INFINITY;
        for (size_t j = 0; j < k; j++)
            d = fmin(d, ag_pred_segment_dist(&orig[2 * i], &xy[2 * j], &xy[2 * ((j + 1) % k)]));
        *moved = fmax(*moved, d);
    }
    *n = k;
    free(prev);
    free(next);
    free(orig);
    free(gone);
    return AG_OK;
}

ag_status ag_simplify_loops(double *const *loops, size_t *sizes, size_t nloops, double area,
                            double *moved, size_t *removed)
{
    *moved = 0;
    *removed = 0;
    for (size_t L = 0; L < nloops; L++) {
        ag_status st = simplify_loop(loops[L], &sizes[L], area, moved, removed);
        if (st != AG_OK)
            return st;
    }
    return AG_OK;
}
