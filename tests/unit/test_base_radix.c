/* The radix sort (core/base/radix.h) against qsort by (key, value): keys with many ties, keys
 * using few or all 64 bits, arrays below and above the insertion-sort threshold; and the
 * order key of doubles against the doubles' own order. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/base/radix.h"
#include "random_fixture.h"

static int cmp_item(const void *a, const void *b)
{
    const ag_radix_item *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->val < y->val ? -1 : x->val > y->val;
}

static void test_sort_against_qsort(void **state)
{
    (void)state;
    uint64_t s = 11;
    const size_t sizes[] = {0, 1, 2, 63, 64, 65, 1000, 70000};
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++)
        for (int kind = 0; kind < 4; kind++) {
            size_t n = sizes[si];
            ag_radix_item *a = malloc((n + 1) * sizeof *a), *b = malloc((n + 1) * sizeof *b);
            assert_non_null(a);
            assert_non_null(b);
            for (size_t i = 0; i < n; i++) {
                uint64_t r = next_random(&s);
                /* few distinct keys; small keys; keys in the high bits only; any key */
                a[i].key = kind == 0 ? r % 7 : kind == 1 ? r % 5000 : kind == 2 ? (r % 9) << 55 : r;
                a[i].val = (uint32_t)i; /* filled in value order, as the callers do */
            }
            memcpy(b, a, n * sizeof *a);
            assert_int_equal(ag_radix_sort(a, n), AG_OK);
            if (n)
                qsort(b, n, sizeof *b, cmp_item);
            for (size_t i = 0; i < n; i++) {
                assert_true(a[i].key == b[i].key);
                assert_int_equal(a[i].val, b[i].val);
            }
            free(a);
            free(b);
        }
}

static void test_double_keys_keep_order(void **state)
{
    (void)state;
    const double x[] = {-INFINITY, -1e300, -5.4e6, -1.0, -1e-300, -0.0, 0.0, 1e-300,
                        0.5,       1.0,    5.4e6,  1e300, INFINITY};
    size_t n = sizeof x / sizeof *x;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            uint64_t a = ag_radix_key_double(x[i]), b = ag_radix_key_double(x[j]);
            assert_int_equal(x[i] < x[j], a < b);
            assert_int_equal(x[i] == x[j], a == b); /* -0 and +0 too */
        }
    uint64_t s = 5;
    for (int k = 0; k < 100000; k++) {
        double p = uniform(&s, -1e7, 1e7), q = uniform(&s, -1e7, 1e7);
        if (k % 3 == 0)
            q = p + (k % 2 ? 1e-9 : -1e-9);
        assert_int_equal(p < q, ag_radix_key_double(p) < ag_radix_key_double(q));
    }
}

/* The run index finds the first position of every present key and n for absent ones, as a
 * lower bound on the sorted array would. */
static void test_index_finds_runs(void **state)
{
    (void)state;
    uint64_t s = 29;
    const size_t sizes[] = {0, 1, 5, 300, 20000};
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
        size_t n = sizes[si];
        ag_radix_item *a = malloc((n + 1) * sizeof *a);
        assert_non_null(a);
        for (size_t i = 0; i < n; i++) {
            a[i].key = (next_random(&s) % (n / 3 + 2)) * 0x9E3779B97F4A7C15ULL;
            a[i].val = (uint32_t)i;
        }
        assert_int_equal(ag_radix_sort(a, n), AG_OK);
        ag_radix_index x;
        assert_int_equal(ag_radix_index_build(&x, a, n), AG_OK);
        for (size_t q = 0; q < n / 3 + 40; q++) {
            uint64_t key = q * 0x9E3779B97F4A7C15ULL;
            size_t lo = 0;
            while (lo < n && a[lo].key != key)
                lo++;
            assert_int_equal(ag_radix_index_find(&x, key), lo); /* n when absent */
        }
        ag_radix_index_free(&x);
        free(a);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_index_finds_runs),
        cmocka_unit_test(test_sort_against_qsort),
        cmocka_unit_test(test_double_keys_keep_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
