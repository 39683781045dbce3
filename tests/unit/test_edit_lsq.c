/* Sparse least squares on the normal equations with a kept factorization. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "core/edit/lsq.h"

/* x + y = 3, x - y = 1, 2x = 4, y = 1: consistent, x = 2, y = 1 exactly. */
static void test_exact_system(void **state)
{
    (void)state;
    uint32_t r[] = {0, 0, 1, 1, 2, 3}, c[] = {0, 1, 0, 1, 0, 1};
    double v[] = {1, 1, 1, -1, 2, 1}, b[] = {3, 1, 4, 1}, x[2];
    ag_lsq *s = NULL;
    ag_error err = {0};
    assert_int_equal(ag_lsq_create(4, 2, 6, r, c, v, &s, &err), AG_OK);
    assert_int_equal(ag_lsq_rows(s), 4);
    assert_int_equal(ag_lsq_cols(s), 2);
    assert_int_equal(ag_lsq_solve(s, b, x, &err), AG_OK);
    assert_true(fabs(x[0] - 2) < 1e-12 && fabs(x[1] - 1) < 1e-12);
    ag_lsq_free(s);
}

/* An inconsistent system: the solution satisfies the normal equations A'A x = A'b, computed
 * densely here; duplicate triplets add up. */
static void test_least_squares_and_resolve(void **state)
{
    (void)state;
    enum { M = 7, N = 3 };
    double A[M][N] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, -1, 0}, {0, 1, -1}, {2, 0, 1},
                      {0.5, 0.5, 0.5}};
    uint32_t r[2 * M * N], c[2 * M * N];
    double v[2 * M * N];
    size_t nnz = 0;
    for (int i = 0; i < M; i++)
        for (int j = 0; j < N; j++)
            if (A[i][j] != 0) {
                /* split each entry into two triplets that sum to it */
                r[nnz] = i, c[nnz] = j, v[nnz++] = A[i][j] * 0.25;
                r[nnz] = i, c[nnz] = j, v[nnz++] = A[i][j] * 0.75;
            }
    ag_lsq *s = NULL;
    ag_error err = {0};
    assert_int_equal(ag_lsq_create(M, N, nnz, r, c, v, &s, &err), AG_OK);
    double b1[M] = {1, 2, 3, 0.5, -0.25, 4, 7}, b2[M] = {-3, 0, 1, 2, 2, -1, 0.1}, x[N];
    for (int round = 0; round < 2; round++) {
        const double *b = round ? b2 : b1;
        assert_int_equal(ag_lsq_solve(s, b, x, &err), AG_OK);
        /* normal equations residual */
        for (int j = 0; j < N; j++) {
            double g = 0;
            for (int i = 0; i < M; i++) {
                double ri = -b[i];
                for (int k = 0; k < N; k++)
                    ri += A[i][k] * x[k];
                g += A[i][j] * ri;
            }
            assert_true(fabs(g) < 1e-10);
        }
        /* the re-solve (round 1, factorization kept) equals a fresh solve */
        if (round) {
            ag_lsq *f = NULL;
            double y[N];
            assert_int_equal(ag_lsq_create(M, N, nnz, r, c, v, &f, &err), AG_OK);
            assert_int_equal(ag_lsq_solve(f, b2, y, &err), AG_OK);
            for (int j = 0; j < N; j++)
                assert_true(fabs(x[j] - y[j]) < 1e-12);
            ag_lsq_free(f);
        }
    }
    ag_lsq_free(s);
}

static void test_bad_systems(void **state)
{
    (void)state;
    ag_lsq *s = NULL;
    ag_error err = {0};
    /* unknown 1 appears nowhere: not determined */
    uint32_t r[] = {0, 1, 2}, c[] = {0, 0, 0};
    double v[] = {1, 2, 3};
    assert_int_equal(ag_lsq_create(3, 2, 3, r, c, v, &s, &err), AG_ERR_INVALID);
    assert_null(s);
    /* fewer equations than unknowns */
    assert_int_equal(ag_lsq_create(1, 2, 1, r, c, v, &s, &err), AG_ERR_INVALID);
    /* an entry out of range */
    uint32_t c2[] = {0, 5, 1};
    assert_int_equal(ag_lsq_create(3, 2, 3, r, c2, v, &s, &err), AG_ERR_INVALID);
    assert_int_equal(err.element, 2);
    assert_null(s);
}

/* A larger banded system (a chain of springs pinned at both ends) solves to the line. */
static void test_chain(void **state)
{
    (void)state;
    enum { N = 2000 };
    size_t M = N + 1 + 2;
    uint32_t *r = malloc(2 * M * sizeof *r), *c = malloc(2 * M * sizeof *c);
    double *v = malloc(2 * M * sizeof *v), *b = calloc(M, sizeof *b), *x = malloc(N * sizeof *x);
    size_t nnz = 0, row = 0;
    for (int i = 0; i + 1 < N; i++, row++) { /* x[i+1] - x[i] = 1 */
        r[nnz] = row, c[nnz] = i, v[nnz++] = -1;
        r[nnz] = row, c[nnz] = i + 1, v[nnz++] = 1;
        b[row] = 1;
    }
    r[nnz] = row, c[nnz] = 0, v[nnz++] = 1, b[row++] = 0;
    r[nnz] = row, c[nnz] = N - 1, v[nnz++] = 1, b[row++] = N - 1;
    ag_lsq *s = NULL;
    ag_error err = {0};
    assert_int_equal(ag_lsq_create(row, N, nnz, r, c, v, &s, &err), AG_OK);
    assert_int_equal(ag_lsq_solve(s, b, x, &err), AG_OK);
    for (int i = 0; i < N; i++)
        assert_true(fabs(x[i] - i) < 1e-6);
    ag_lsq_free(s);
    free(r);
    free(c);
    free(v);
    free(b);
    free(x);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_system),
        cmocka_unit_test(test_least_squares_and_resolve),
        cmocka_unit_test(test_bad_systems),
        cmocka_unit_test(test_chain),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
