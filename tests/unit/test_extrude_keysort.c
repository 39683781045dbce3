/* The key sort of the shell and the building check: every length (insertion, quicksort and
 * radix ranges), duplicates, extreme keys, doubles as keys; checked against a plain
 * comparison sort of the same entries. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/extrude/keysort.h"

static uint64_t rng = 0x853c49e6748fea9bULL;
static uint64_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static int cmp_entry(const void *a, const void *b)
{
    const ag_keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->val < y->val ? -1 : x->val > y->val;
}

static void test_sorts_like_qsort(void **state)
{
    (void)state;
    const size_t lengths[] = {0, 1, 2, 3, 23, 24, 25, 100, 1000, 4096, 4097, 20000};
    for (size_t li = 0; li < sizeof lengths / sizeof *lengths; li++) {
        size_t n = lengths[li];
        for (int kind = 0; kind < 4; kind++) {
            ag_keyed *v = malloc((n + 1) * sizeof *v), *w = malloc((n + 1) * sizeof *w);
            for (size_t i = 0; i < n; i++) {
                uint64_t k = next();
                if (kind == 1)
                    k %= 7; /* many duplicates */
                else if (kind == 2)
                    k = (uint64_t)(n - i); /* reversed */
                else if (kind == 3)
                    k = i % 2 ? UINT64_MAX : 0; /* extremes */
                v[i] = (ag_keyed){k, (uint32_t)i};
            }
            memcpy(w, v, n * sizeof *v);
            assert_int_equal(ag_keysort(v, n, NULL), AG_OK);
            /* sorted, and the same entries: sort both fully and compare */
            for (size_t i = 1; i < n; i++)
                assert_true(v[i - 1].key <= v[i].key);
            qsort(v, n, sizeof *v, cmp_entry);
            qsort(w, n, sizeof *w, cmp_entry);
            for (size_t i = 0; i < n; i++) {
                assert_true(v[i].key == w[i].key);
                assert_int_equal(v[i].val, w[i].val);
            }
            free(v);
            free(w);
        }
    }
}

static void test_double_keys_order_numbers(void **state)
{
    (void)state;
    const double d[] = {-INFINITY, -1e300, -5.8e6, -1, -1e-300, -0.0, 0.0, 1e-300, 0.5, 1,
                        85123.456, 5.8e6, 1e300, INFINITY};
    size_t n = sizeof d / sizeof *d;
    for (size_t i = 0; i + 1 < n; i++)
        assert_true(ag_keysort_double(d[i]) <= ag_keysort_double(d[i + 1]));
    assert_true(ag_keysort_double(-1) < ag_keysort_double(1));
    assert_true(ag_keysort_double(1e-300) < ag_keysort_double(1e-299));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sorts_like_qsort),
        cmocka_unit_test(test_double_keys_order_numbers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
