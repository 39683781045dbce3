/* Array growth (core/base/array.h): contents survive growth, capacities at least double,
 * every size computation that does not fit a size_t is refused with the array untouched,
 * and an allocation that fails leaves it untouched too. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/base/array.h"
#include "random_fixture.h"

/* Address sanitizer builds: a refused huge allocation must return NULL, not abort, since
 * that is what the out-of-memory cases below exercise. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

typedef struct {
    uint64_t key;
    double value;
    char tag[5];
} record;

static void test_push_keeps_contents(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 20; seed++) {
        uint64_t s = seed * 0x9E3779B97F4A7C15ULL;
        size_t n = 1 + next_random(&s) % 5000;
        record *items = NULL;
        size_t len = 0, cap = 0, grows = 0;
        for (size_t i = 0; i < n; i++) {
            size_t before = cap;
            assert_int_equal(AG_ARRAY_RESERVE(items, cap, len + 1), AG_OK);
            assert_true(cap >= len + 1);
            if (cap != before) {
                grows++;
                /* from the minimum on, every growth at least doubles */
                assert_true(cap >= AG_ARRAY_MIN_CAP);
                assert_true(before == 0 || cap >= 2 * before);
            }
            items[len] = (record){.key = i * 31 + seed, .value = (double)i / 7, .tag = "abcd"};
            len++;
        }
        for (size_t i = 0; i < n; i++) {
            assert_true(items[i].key == i * 31 + seed);
            assert_true(items[i].value == (double)i / 7);
            assert_string_equal(items[i].tag, "abcd");
        }
        /* doubling: logarithmically many reallocations */
        size_t bound = 1;
        for (size_t c = AG_ARRAY_MIN_CAP; c < n; c *= 2)
            bound++;
        assert_true(grows <= bound);
        free(items);
    }
}

static void test_reserve_more_and_exact(void **state)
{
    (void)state;
    int *a = NULL;
    size_t cap = 0;
    assert_int_equal(AG_ARRAY_RESERVE_EXACT(a, cap, 5), AG_OK);
    assert_int_equal(cap, 5);
    for (int i = 0; i < 5; i++)
        a[i] = i;
    /* enough room: nothing changes */
    int *before = a;
    assert_int_equal(AG_ARRAY_RESERVE_EXACT(a, cap, 3), AG_OK);
    assert_int_equal(AG_ARRAY_RESERVE(a, cap, 5), AG_OK);
    assert_ptr_equal(a, before);
    assert_int_equal(cap, 5);
    /* growth from a capacity below the minimum goes to the minimum */
    assert_int_equal(AG_ARRAY_RESERVE_MORE(a, cap, 5, 1), AG_OK);
    assert_int_equal(cap, AG_ARRAY_MIN_CAP);
    for (int i = 0; i < 5; i++)
        assert_int_equal(a[i], i);
    /* a jump past double goes to the next doubling that holds it */
    assert_int_equal(AG_ARRAY_RESERVE_MORE(a, cap, 16, 100), AG_OK);
    assert_int_equal(cap, 128);
    free(a);
}

static void test_capacity(void **state)
{
    (void)state;
    size_t c;
    assert_int_equal(ag_array_capacity(0, 1, 8, &c), AG_OK);
    assert_int_equal(c, AG_ARRAY_MIN_CAP);
    assert_int_equal(ag_array_capacity(100, 50, 8, &c), AG_OK);
    assert_int_equal(c, 100);
    assert_int_equal(ag_array_capacity(100, 101, 8, &c), AG_OK);
    assert_int_equal(c, 200);
    assert_int_equal(ag_array_capacity(1000, 5000, 1, &c), AG_OK);
    assert_int_equal(c, 8000);
    /* doubling past what fits in bytes settles for exactly what is needed */
    size_t limit = SIZE_MAX / 8;
    assert_int_equal(ag_array_capacity(limit / 2 + 1, limit / 2 + 2, 8, &c), AG_OK);
    assert_int_equal(c, limit / 2 + 2);
    assert_int_equal(ag_array_capacity(0, limit, 8, &c), AG_OK);
    assert_true(c == limit);
    /* more elements than bytes can count */
    c = 7;
    assert_int_equal(ag_array_capacity(0, limit + 1, 8, &c), AG_ERR_TOO_LARGE);
    assert_int_equal(c, 7);
    assert_int_equal(ag_array_capacity(0, SIZE_MAX, 2, &c), AG_ERR_TOO_LARGE);
    /* elements of one byte: every count fits */
    assert_int_equal(ag_array_capacity(SIZE_MAX / 2 + 1, SIZE_MAX, 1, &c), AG_OK);
    assert_true(c == SIZE_MAX);
}

static void test_checked_arithmetic(void **state)
{
    (void)state;
    size_t r = 123;
    assert_int_equal(ag_array_bytes(SIZE_MAX / 16, 16, &r), AG_OK);
    assert_true(r == SIZE_MAX / 16 * 16);
    r = 123;
    assert_int_equal(ag_array_bytes(SIZE_MAX / 16 + 1, 16, &r), AG_ERR_TOO_LARGE);
    assert_int_equal(r, 123);
    assert_int_equal(ag_array_bytes(SIZE_MAX, 0, &r), AG_OK);
    assert_int_equal(r, 0);
    assert_int_equal(ag_array_sum(SIZE_MAX - 5, 5, &r), AG_OK);
    assert_true(r == SIZE_MAX);
    r = 9;
    assert_int_equal(ag_array_sum(SIZE_MAX - 5, 6, &r), AG_ERR_TOO_LARGE);
    assert_int_equal(ag_array_sum(SIZE_MAX, SIZE_MAX, &r), AG_ERR_TOO_LARGE);
    assert_int_equal(r, 9);
}

/* Growth that overflows or cannot be allocated leaves pointer, capacity and contents. */
static void test_overflow_and_nomem_keep_array(void **state)
{
    (void)state;
    double *a = NULL;
    size_t cap = 0;
    assert_int_equal(AG_ARRAY_RESERVE(a, cap, 10), AG_OK);
    for (int i = 0; i < 10; i++)
        a[i] = i + 0.5;
    double *keep = a;
    size_t keep_cap = cap;
    /* count * 8 bytes overflows a size_t */
    assert_int_equal(AG_ARRAY_RESERVE(a, cap, SIZE_MAX / sizeof *a + 1), AG_ERR_TOO_LARGE);
    assert_int_equal(AG_ARRAY_RESERVE_EXACT(a, cap, SIZE_MAX / 2), AG_ERR_TOO_LARGE);
    /* len + more overflows */
    assert_int_equal(AG_ARRAY_RESERVE_MORE(a, cap, SIZE_MAX - 1, 2), AG_ERR_TOO_LARGE);
    assert_ptr_equal(a, keep);
    assert_int_equal(cap, keep_cap);
    /* representable but far beyond any memory: the allocation fails */
    assert_int_equal(AG_ARRAY_RESERVE(a, cap, SIZE_MAX / sizeof *a / 2), AG_ERR_NOMEM);
    assert_int_equal(AG_ARRAY_RESERVE_EXACT(a, cap, SIZE_MAX / sizeof *a), AG_ERR_NOMEM);
    assert_ptr_equal(a, keep);
    assert_int_equal(cap, keep_cap);
    /* a resize of one array of a struct of arrays: refused alike, the array kept */
    assert_int_equal(AG_ARRAY_RESIZE(a, SIZE_MAX / sizeof *a + 1), AG_ERR_TOO_LARGE);
    assert_int_equal(AG_ARRAY_RESIZE(a, SIZE_MAX / sizeof *a), AG_ERR_NOMEM);
    assert_ptr_equal(a, keep);
    for (int i = 0; i < 10; i++)
        assert_true(a[i] == i + 0.5);
    /* and grown, its contents kept */
    assert_int_equal(AG_ARRAY_RESIZE(a, 1000), AG_OK);
    for (int i = 0; i < 10; i++)
        assert_true(a[i] == i + 0.5);
    a[999] = 1;
    free(a);
}

static void test_hash_size(void **state)
{
    (void)state;
    size_t s;
    for (size_t n = 0; n < 5000; n += 1 + n / 3) {
        assert_int_equal(ag_array_hash_size(n, &s), AG_OK);
        assert_true(s >= 2 * n + 16);
        assert_true((s & (s - 1)) == 0); /* a power of two: masks index it */
        assert_true(s / 2 < 2 * n + 16); /* the smallest such */
    }
    assert_int_equal(ag_array_hash_size(SIZE_MAX / 4, &s), AG_ERR_TOO_LARGE);
    assert_int_equal(ag_array_hash_size(SIZE_MAX, &s), AG_ERR_TOO_LARGE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_push_keeps_contents),
        cmocka_unit_test(test_reserve_more_and_exact),
        cmocka_unit_test(test_capacity),
        cmocka_unit_test(test_checked_arithmetic),
        cmocka_unit_test(test_overflow_and_nomem_keep_array),
        cmocka_unit_test(test_hash_size),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
