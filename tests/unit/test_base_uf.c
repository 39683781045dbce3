/* Union-find (core/base/uf.h) against an independent oracle: random unions on many sizes,
 * checked pair by pair against sets kept as explicit labels relabelled by brute force; the
 * offsets of the potential variant against hidden values; caller-chosen roots; resets. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "core/base/uf.h"
#include "random_fixture.h"

/* Oracle: label[i] is i's set; a union relabels every member of one set (O(n) each). */
static void oracle_union(uint32_t *label, size_t n, uint32_t a, uint32_t b)
{
    uint32_t from = label[b], to = label[a];
    if (from == to)
        return;
    for (size_t i = 0; i < n; i++)
        if (label[i] == from)
            label[i] = to;
}

static void test_random_unions_match_oracle(void **state)
{
    (void)state;
    uint64_t s = 0x1234567;
    const size_t sizes[] = {1, 2, 3, 17, 100, 513};
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
        size_t n = sizes[si];
        for (int trial = 0; trial < 8; trial++) {
            ag_uf uf;
            assert_int_equal(ag_uf_init(&uf, n, 0), AG_OK);
            uint32_t *label = malloc(n * sizeof *label);
            for (size_t i = 0; i < n; i++)
                label[i] = (uint32_t)i;
            /* few unions (many sets) to many (one set) */
            size_t nu = (size_t)(next_random(&s) % (2 * n + 1));
            for (size_t k = 0; k < nu; k++) {
                uint32_t a = (uint32_t)(next_random(&s) % n), b = (uint32_t)(next_random(&s) % n);
                uint32_t r = ag_uf_union(&uf, a, b);
                oracle_union(label, n, a, b);
                assert_int_equal(r, ag_uf_find(&uf, a));
                assert_int_equal(r, ag_uf_find(&uf, b));
            }
            for (size_t i = 0; i < n; i++) {
                uint32_t ri = ag_uf_find(&uf, (uint32_t)i);
                assert_true(ri < n);
                assert_int_equal(ag_uf_find(&uf, ri), ri); /* a root is its own root */
                assert_int_equal(label[ri], label[i]);     /* the root is a member */
                for (size_t j = 0; j < n; j += 1 + n / 40)
                    assert_int_equal(ri == ag_uf_find(&uf, (uint32_t)j), label[i] == label[j]);
                /* path compression: after a find, the element points at its root */
                assert_int_equal(uf.parent[i], ri);
            }
            free(label);
            ag_uf_free(&uf);
        }
    }
}

/* Union by rank keeps trees shallow even for the chain that defeats naive linking. */
static void test_rank_keeps_trees_shallow(void **state)
{
    (void)state;
    size_t n = 1 << 14;
    ag_uf uf;
    assert_int_equal(ag_uf_init(&uf, n, 0), AG_OK);
    for (size_t i = 1; i < n; i++)
        ag_uf_union(&uf, (uint32_t)i, (uint32_t)(i - 1));
    size_t deepest = 0;
    for (size_t i = 0; i < n; i++) {
        size_t d = 0;
        for (uint32_t x = (uint32_t)i; uf.parent[x] != x; x = uf.parent[x])
            d++;
        if (d > deepest)
            deepest = d;
    }
    assert_true(deepest <= 14); /* log2 n */
    ag_uf_free(&uf);
}

/* Potentials: hidden values v; every union states v[a] - v[b]; then any two members of a set
 * differ by their offsets from the root. The root a caller links under stays the root. */
static void test_offsets_follow_values(void **state)
{
    (void)state;
    uint64_t s = 99;
    for (int trial = 0; trial < 20; trial++) {
        size_t n = 2 + next_random(&s) % 300;
        double *v = malloc(n * sizeof *v);
        uint8_t *pinned = calloc(n, 1); /* a class whose root must stay its root */
        for (size_t i = 0; i < n; i++)
            v[i] = (double)(next_random(&s) % 2000001) / 1000 - 1000 + 5.4e6; /* UTM-sized */
        ag_uf uf;
        assert_int_equal(ag_uf_init(&uf, n, 1), AG_OK);
        for (size_t i = 0; i < n; i += 7)
            pinned[i] = 1;
        for (size_t k = 0; k < 2 * n; k++) {
            uint32_t a = (uint32_t)(next_random(&s) % n), b = (uint32_t)(next_random(&s) % n);
            uint32_t ra = ag_uf_find(&uf, a), rb = ag_uf_find(&uf, b);
            if (ra == rb)
                continue;
            double d = v[a] - v[b];
            /* value(ra) - value(rb), from value(x) = value(root) + offset(x) */
            double rel = ag_uf_offset(&uf, b) + d - ag_uf_offset(&uf, a);
            if (pinned[ra] && pinned[rb])
                continue;
            if (pinned[ra])
                ag_uf_link(&uf, rb, ra, -rel);
            else
                ag_uf_link(&uf, ra, rb, rel);
        }
        for (size_t i = 0; i < n; i++) {
            uint32_t r = ag_uf_find(&uf, (uint32_t)i);
            assert_true(fabs(ag_uf_offset(&uf, (uint32_t)i) - (v[i] - v[r])) < 1e-6);
            for (size_t j = 0; j < n; j += 1 + n / 20) {
                if (ag_uf_find(&uf, (uint32_t)j) != r)
                    continue;
                double dij = ag_uf_offset(&uf, (uint32_t)i) - ag_uf_offset(&uf, (uint32_t)j);
                assert_true(fabs(dij - (v[i] - v[j])) < 1e-6);
            }
        }
        /* a pinned element is always its class's root: nothing was linked under another */
        for (size_t i = 0; i < n; i++)
            if (pinned[i])
                assert_int_equal(ag_uf_find(&uf, (uint32_t)i), i);
        free(v);
        free(pinned);
        ag_uf_free(&uf);
    }
}

static void test_reset_and_limits(void **state)
{
    (void)state;
    ag_uf uf;
    assert_int_equal(ag_uf_init(&uf, 6, 0), AG_OK);
    ag_uf_union(&uf, 0, 1);
    ag_uf_union(&uf, 1, 2);
    ag_uf_union(&uf, 4, 5);
    assert_int_equal(ag_uf_find(&uf, 0), ag_uf_find(&uf, 2));
    /* reset the whole set {0, 1, 2}: singletons again, the other set untouched */
    for (uint32_t i = 0; i < 3; i++)
        ag_uf_reset(&uf, i);
    for (uint32_t i = 0; i < 3; i++)
        assert_int_equal(ag_uf_find(&uf, i), i);
    assert_int_equal(ag_uf_find(&uf, 4), ag_uf_find(&uf, 5));
    assert_int_equal(ag_uf_find(&uf, 3), 3);
    assert_true(ag_uf_offset(&uf, 5) == 0); /* no offsets: always 0 */
    ag_uf_free(&uf);
    ag_uf_free(&uf); /* twice is harmless */
    ag_uf_free(NULL);
    /* indices are 32-bit: refused before anything is allocated */
    assert_int_equal(ag_uf_init(&uf, (size_t)UINT32_MAX, 0), AG_ERR_TOO_LARGE);
    assert_null(uf.parent);
    assert_int_equal(ag_uf_init(&uf, 0, 1), AG_OK);
    ag_uf_free(&uf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_unions_match_oracle),
        cmocka_unit_test(test_rank_keeps_trees_shallow),
        cmocka_unit_test(test_offsets_follow_values),
        cmocka_unit_test(test_reset_and_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
