/* Triangle-soup matching (ag_label_match_triangles, ag_label_soups_match) against a brute
 * force: every triangle of b, in order, takes the nearest unused triangle of a within tol
 * (vertices compared under the three cyclic shifts), among those whose centroid cell (cells
 * of 2 tol) is next to b's, the first in cell order then triangle order on a tie. On soups
 * reordered, with shifted vertex cycles, duplicates, jitter around tol, reversed triangles
 * that must not match, missing and extra triangles, and UTM-sized offsets; soups small
 * enough to compare every pair and large ones that go through the cell index. */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/proc/label.h"
#include "random_fixture.h"

static double dist(const double *x, const double *y, int shift)
{
    double m = 0;
    for (int v = 0; v < 3; v++) {
        const double *p = x + 3 * v, *q = y + 3 * ((v + shift) % 3);
        double d = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                   (p[2] - q[2]) * (p[2] - q[2]);
        m = fmax(m, d);
    }
    return sqrt(m);
}

static double brute(const double *a, size_t na, const double *b, size_t nb, double tol,
                    size_t *unmatched)
{
    /* the same order first: every triangle against its own index, the first cyclic shift
     * within tol counting */
    if (na == nb) {
        double w = 0;
        size_t i = 0;
        for (; i < na; i++) {
            double d = INFINITY;
            for (int sh = 0; sh < 3 && !(d <= tol); sh++)
                d = fmin(d, dist(b + 9 * i, a + 9 * i, sh));
            if (!(d <= tol))
                break;
            w = fmax(w, d);
        }
        if (i == na) {
            *unmatched = 0;
            return w;
        }
    }
    double cell = 2 * tol, worst = 0;
    uint8_t *used = calloc(na + 1, 1);
    size_t miss = 0;
    for (size_t j = 0; j < nb; j++) {
        double cb[3];
        for (int q = 0; q < 3; q++)
            cb[q] = (b[9 * j + q] + b[9 * j + 3 + q] + b[9 * j + 6 + q]) / 3.0;
        double best = INFINITY;
        size_t bi = SIZE_MAX;
        int brank = 99;
        for (size_t i = 0; i < na; i++) {
            if (used[i])
                continue;
            int rank = 0, near = 1;
            for (int q = 0; q < 3; q++) {
                double ca = (a[9 * i + q] + a[9 * i + 3 + q] + a[9 * i + 6 + q]) / 3.0;
                int64_t off = (int64_t)floor(ca / cell) - (int64_t)floor(cb[q] / cell);
                near = near && off >= -1 && off <= 1;
                rank = 3 * rank + (int)(off + 1);
            }
            if (!near)
                continue;
            double d = INFINITY;
            for (int sh = 0; sh < 3; sh++)
                d = fmin(d, dist(b + 9 * j, a + 9 * i, sh));
            if (!(d <= tol))
                continue;
            if (d < best || (d == best && rank < brank)) {
                best = d;
                bi = i;
                brank = rank;
            }
        }
        if (bi == SIZE_MAX) {
            miss++;
            continue;
        }
        used[bi] = 1;
        worst = fmax(worst, best);
    }
    free(used);
    *unmatched = miss;
    return worst;
}

static void test_against_brute_force(void **state)
{
    (void)state;
    uint64_t s = 23;
    for (int trial = 0; trial < 400; trial++) {
        double tol = trial % 3 == 0 ? 1e-3 : trial % 3 == 1 ? 5e-3 : 1e-6;
        double off[3] = {0, 0, 0};
        if (trial % 4 == 1) {
            off[0] = 512345.25;
            off[1] = 5812345.5;
        }
        /* small soups (every pair compared) and large ones (through the cell index) */
        size_t na = trial % 3 == 2 ? 70 + next_random(&s) % 250 : 1 + next_random(&s) % 60;
        double *a = malloc(9 * na * sizeof *a), *b = malloc(9 * (na + 5) * sizeof *b);
        double span = trial % 5 == 0 ? 4 * tol : 2.0; /* crowded: many candidates per cell */
        for (size_t i = 0; i < na; i++) {
            if (i > 0 && next_random(&s) % 8 == 0) { /* a duplicate */
                memcpy(a + 9 * i, a + 9 * (i - 1), 9 * sizeof *a);
                continue;
            }
            double c[3];
            for (int q = 0; q < 3; q++)
                c[q] = off[q] + uniform(&s, 0, span);
            for (int v = 0; v < 9; v++)
                a[9 * i + v] = c[v % 3] + uniform(&s, -0.3, 0.3) * (span < 1 ? tol : 1);
        }
        /* b: a permutation of a, vertex cycles shifted, jittered around tol; some reversed,
         * some dropped, some extra */
        size_t nb = 0;
        size_t *perm = malloc(na * sizeof *perm);
        for (size_t i = 0; i < na; i++)
            perm[i] = i;
        if (trial % 6) /* else the same order */
            for (size_t i = na; i > 1; i--) {
                size_t k = next_random(&s) % i, t = perm[i - 1];
                perm[i - 1] = perm[k];
                perm[k] = t;
            }
        for (size_t i = 0; i < na; i++) {
            if (trial % 7 == 3 && next_random(&s) % 10 == 0)
                continue; /* dropped */
            const double *t = a + 9 * perm[i];
            int sh = trial % 6 ? (int)(next_random(&s) % 3) : 0;
            int rev = trial % 9 == 4 && next_random(&s) % 10 == 0;
            for (int v = 0; v < 3; v++) {
                int src = rev ? (3 - v) % 3 : (v + sh) % 3;
                for (int q = 0; q < 3; q++) {
                    double j = uniform(&s, -1, 1) * tol * (trial % 2 ? 0.7 : 0.2);
                    b[9 * nb + 3 * v + q] = t[3 * src + q] + j;
                }
            }
            nb++;
        }
        if (trial % 8 == 5)
            for (int e = 0; e < 3; e++, nb++)
                for (int v = 0; v < 9; v++)
                    b[9 * nb + v] = off[v % 3] + uniform(&s, 0, span);
        size_t m1 = 0, m2 = 0;
        double w1 = ag_label_match_triangles(a, na, b, nb, tol, &m1);
        double w2 = brute(a, na, b, nb, tol, &m2);
        if (m1 != m2 || w1 != w2)
            fail_msg("trial %d: %zu unmatched, worst %.17g; brute force %zu, %.17g", trial, m1,
                     w1, m2, w2);
        double w3 = -1;
        int same = ag_label_soups_match(a, na, b, nb, tol, &w3);
        assert_int_equal(same, m2 == 0);
        if (same)
            assert_true(w3 == w2);
        free(a);
        free(b);
        free(perm);
    }
}

static void put_tri(double *t, double x)
{
    const double base[9] = {0, 0, 0, 0.125, 0, 0, 0, 0.125, 0};
    for (int v = 0; v < 9; v++)
        t[v] = base[v] + (v % 3 == 0 ? x : 0);
}

/* Two candidates exactly as near: the one a scan of the cells in order meets first is taken
 * (here the one with the higher index), which leaves the other for the next triangle. */
static void test_ties_follow_the_cell_scan(void **state)
{
    (void)state;
    double a[18], b[18];
    put_tri(a, 1.25);     /* cell 1 (cells of 2 tol = 1) */
    put_tri(a + 9, 0.75); /* cell 0: scanned first */
    put_tri(b, 1.0);      /* 0.25 from both */
    put_tri(b + 9, 1.5);  /* 0.25 from the first only */
    size_t miss = 9, bm = 9;
    double w = ag_label_match_triangles(a, 2, b, 2, 0.5, &miss);
    double bw = brute(a, 2, b, 2, 0.5, &bm);
    assert_int_equal(bm, 0);
    assert_int_equal(miss, 0);
    assert_true(w == bw && w == 0.25);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ties_follow_the_cell_scan),
        cmocka_unit_test(test_against_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
