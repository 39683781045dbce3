/* Lower and upper bounds (core/base/search.h) against a linear scan, on sorted arrays of
 * records with duplicate keys, queries below, between, on and above the keys, empty arrays,
 * and keys at unaligned offsets in packed records. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/base/search.h"
#include "random_fixture.h"

typedef struct {
    uint32_t tag;
    uint64_t key;
    double x;
} rec;

static int cmp_rec(const void *a, const void *b)
{
    uint64_t x = ((const rec *)a)->key, y = ((const rec *)b)->key;
    return x < y ? -1 : x > y;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void test_u64_against_scan(void **state)
{
    (void)state;
    uint64_t s = 3;
    for (int trial = 0; trial < 200; trial++) {
        size_t n = next_random(&s) % 60;
        uint64_t spread = 1 + next_random(&s) % 40; /* small spreads: many duplicates */
        rec *r = malloc((n + 1) * sizeof *r);
        for (size_t i = 0; i < n; i++)
            r[i] = (rec){.tag = (uint32_t)i, .key = next_random(&s) % spread + UINT64_MAX / 2};
        qsort(r, n, sizeof *r, cmp_rec);
        for (uint64_t q = UINT64_MAX / 2 - 2; q <= UINT64_MAX / 2 + spread + 2; q++) {
            size_t lo = 0, up = 0;
            while (lo < n && r[lo].key < q)
                lo++;
            while (up < n && r[up].key <= q)
                up++;
            assert_int_equal(ag_search_lower_u64(&r[0].key, n, sizeof *r, q), lo);
            assert_int_equal(ag_search_upper_u64(&r[0].key, n, sizeof *r, q), up);
        }
        /* the extremes of the key range */
        assert_int_equal(ag_search_lower_u64(&r[0].key, n, sizeof *r, 0), 0);
        assert_int_equal(ag_search_upper_u64(&r[0].key, n, sizeof *r, UINT64_MAX), n);
        free(r);
    }
    /* an empty array: no record is read */
    assert_int_equal(ag_search_lower_u64(NULL, 0, 16, 5), 0);
    assert_int_equal(ag_search_upper_u64(NULL, 0, 16, 5), 0);
}

static void test_double_against_scan(void **state)
{
    (void)state;
    uint64_t s = 11;
    for (int trial = 0; trial < 200; trial++) {
        size_t n = 1 + next_random(&s) % 50;
        double *v = malloc(n * sizeof *v);
        for (size_t i = 0; i < n; i++)
            v[i] = 5.7e6 + 0.25 * (double)(next_random(&s) % 20); /* UTM-sized, repeated */
        if (trial % 5 == 0)
            v[0] = -INFINITY;
        qsort(v, n, sizeof *v, cmp_double);
        for (int k = -3; k < 24; k++) {
            double q = 5.7e6 + 0.125 * k * 2 + (k % 2 ? 0.1 : 0);
            size_t lo = 0, up = 0;
            while (lo < n && v[lo] < q)
                lo++;
            while (up < n && v[up] <= q)
                up++;
            assert_int_equal(ag_search_lower_double(v, n, sizeof *v, q), lo);
            assert_int_equal(ag_search_upper_double(v, n, sizeof *v, q), up);
        }
        free(v);
    }
}

/* Records of 13 bytes with the key at offset 5: never aligned to 8. */
static void test_unaligned_keys(void **state)
{
    (void)state;
    enum { N = 40, STRIDE = 13, OFFSET = 5 };
    unsigned char buf[N * STRIDE + 8];
    memset(buf, 0xAB, sizeof buf);
    for (size_t i = 0; i < N; i++) {
        uint64_t k = 100 + 3 * (i / 2); /* each key twice */
        memcpy(buf + i * STRIDE + OFFSET, &k, sizeof k);
    }
    const void *key = buf + OFFSET;
    for (uint64_t q = 98; q < 100 + 3 * N / 2 + 3; q++) {
        size_t lo = 0, up = 0;
        for (size_t i = 0; i < N; i++) {
            uint64_t k = 100 + 3 * (i / 2);
            lo += k < q;
            up += k <= q;
        }
        assert_int_equal(ag_search_lower_u64(key, N, STRIDE, q), lo);
        assert_int_equal(ag_search_upper_u64(key, N, STRIDE, q), up);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_u64_against_scan),
        cmocka_unit_test(test_double_against_scan),
        cmocka_unit_test(test_unaligned_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
