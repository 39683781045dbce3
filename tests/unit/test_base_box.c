/* Boxes (core/base/box.h) on generated boxes with UTM-sized offsets, jitter and every axis
 * order, each operation checked against an independent computation: bounds against a plain
 * min/max scan, meets/contains/intersect against a point found by projection, volumes and
 * diagonals against their formulas. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "core/base/box.h"
#include "random_fixture.h"

/* Site origins the boxes are placed around: local, and UTM easting/northing sized. */
static const double origins[][3] = {{0, 0, 0}, {4.6e5, 5.7e6, 12}, {-3.1e5, 6.2e6, -40}};

static ag_box random_box(uint64_t *s, const double o[3], double size)
{
    ag_box b;
    for (int a = 0; a < 3; a++) {
        double c = o[a] + uniform(s, -size, size), e = uniform(s, 0, size);
        if (next_random(s) % 8 == 0)
            e = 0; /* flat on this axis: a wall, a floor */
        b.min[a] = c - e;
        b.max[a] = c + e;
    }
    return b;
}

/* Independent of the box code: the point of b nearest to a's centre, then of a nearest to
 * that; for axis-aligned boxes it lies in both exactly when they intersect. */
static int intersect_by_projection(const ag_box *a, const ag_box *b)
{
    for (int k = 0; k < 3; k++) {
        double p = 0.5 * (a->min[k] + a->max[k]);
        p = p < b->min[k] ? b->min[k] : p > b->max[k] ? b->max[k] : p;
        p = p < a->min[k] ? a->min[k] : p > a->max[k] ? a->max[k] : p;
        if (p < b->min[k] || p > b->max[k])
            return 0;
    }
    return 1;
}

static ag_box grown(const ag_box *b, double eps)
{
    ag_box g = *b;
    for (int a = 0; a < 3; a++) {
        g.min[a] -= eps;
        g.max[a] += eps;
    }
    return g;
}

static void test_empty_and_extend(void **state)
{
    (void)state;
    ag_box e = ag_box_empty();
    assert_true(ag_box_is_empty(&e));
    assert_true(ag_box_diagonal(&e) == 0 && ag_box_volume(&e) == 0);
    ag_box nan = {{0, NAN, 0}, {1, 1, 1}};
    assert_true(ag_box_is_empty(&nan));
    uint64_t s = 5;
    for (size_t oi = 0; oi < 3; oi++)
        for (int trial = 0; trial < 50; trial++) {
            ag_box b = ag_box_empty();
            double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            int n = 1 + (int)(next_random(&s) % 40);
            for (int i = 0; i < n; i++) {
                double p[3];
                for (int a = 0; a < 3; a++) {
                    p[a] = origins[oi][a] + uniform(&s, -30, 30);
                    if (p[a] < lo[a])
                        lo[a] = p[a];
                    if (p[a] > hi[a])
                        hi[a] = p[a];
                }
                ag_box_extend_point(&b, p);
            }
            for (int a = 0; a < 3; a++)
                assert_true(b.min[a] == lo[a] && b.max[a] == hi[a]);
            assert_false(ag_box_is_empty(&b));
            /* extending by a box: the union, and the empty box changes nothing */
            ag_box c = random_box(&s, origins[oi], 20), u = b;
            ag_box_extend_box(&u, &c);
            ag_box_extend_box(&u, &e);
            for (int a = 0; a < 3; a++) {
                assert_true(u.min[a] == (b.min[a] < c.min[a] ? b.min[a] : c.min[a]));
                assert_true(u.max[a] == (b.max[a] > c.max[a] ? b.max[a] : c.max[a]));
            }
            assert_true(ag_box_contains(&u, &b, 0) && ag_box_contains(&u, &c, 0));
        }
}

static void test_measures(void **state)
{
    (void)state;
    ag_box b = {{1, -2, 10}, {4, 2, 22}};
    double e[3], c[3];
    ag_box_extents(&b, e);
    ag_box_centre(&b, c);
    assert_true(e[0] == 3 && e[1] == 4 && e[2] == 12);
    assert_true(c[0] == 2.5 && c[1] == 0 && c[2] == 16);
    for (int a = 0; a < 3; a++) {
        assert_true(ag_box_extent(&b, a) == e[a]);
        assert_true(ag_box_centre_axis(&b, a) == c[a]);
    }
    assert_true(ag_box_diagonal(&b) == 13); /* 3, 4, 12 */
    assert_true(ag_box_volume(&b) == 144);
    /* floored: a flat box orders by its area */
    ag_box flat = {{0, 0, 0}, {2, 3, 0}};
    assert_true(ag_box_volume(&flat) == 0);
    assert_true(ag_box_volume_floor(&flat, 0.5) == 3);
    assert_true(ag_box_volume_floor(&b, 0.5) == 144);
    /* coordinates 0..5: min x, y, z, max x, y, z */
    const double want[6] = {1, -2, 10, 4, 2, 22};
    ag_box w = ag_box_empty();
    for (int k = 0; k < 6; k++) {
        assert_true(ag_box_coord(&b, k) == want[k]);
        ag_box_set_coord(&w, k, want[k]);
    }
    for (int a = 0; a < 3; a++)
        assert_true(w.min[a] == b.min[a] && w.max[a] == b.max[a]);
}

/* meets / intersect / contains against the projection oracle on random boxes. */
static void test_relations_match_oracle(void **state)
{
    (void)state;
    uint64_t s = 77;
    for (size_t oi = 0; oi < 3; oi++)
        for (int trial = 0; trial < 3000; trial++) {
            ag_box a = random_box(&s, origins[oi], 10), b = random_box(&s, origins[oi], 10);
            double eps = (trial % 3) * 0.25;
            ag_box ga = grown(&a, eps);
            int meets = intersect_by_projection(&ga, &b);
            assert_int_equal(ag_box_meets(&a, &b, eps), meets);
            assert_int_equal(ag_box_meets(&b, &a, eps), meets);
            int axes = 1;
            for (int k = 0; k < 3; k++) {
                int mk = ag_box_meets_axis(&a, &b, k, eps);
                axes &= mk;
                /* the overlap is the common length (negative: the gap); the spans meet
                 * within eps exactly where it is at least -eps (up to rounding) */
                double ov = ag_box_overlap_axis(&a, &b, k);
                double slack = 1e-9 * (1 + fabs(a.max[k]) + fabs(b.max[k]));
                if (ov > -eps + slack)
                    assert_true(mk);
                if (ov < -eps - slack)
                    assert_false(mk);
                assert_true(ov == ag_box_overlap_axis(&b, &a, k));
            }
            assert_int_equal(axes, meets);
            ag_box x = ag_box_intersect(&a, &b);
            assert_int_equal(!ag_box_is_empty(&x), intersect_by_projection(&a, &b));
            if (!ag_box_is_empty(&x)) {
                assert_true(ag_box_contains(&a, &x, 0) && ag_box_contains(&b, &x, 0));
                double c[3];
                ag_box_centre(&x, c);
                assert_true(ag_box_contains_point(&a, c, 0) && ag_box_contains_point(&b, c, 0));
            }
            /* contains: every corner of the inner box lies in the grown outer one */
            int inside = 1;
            for (int i = 0; i < 8; i++) {
                double p[3] = {i & 1 ? b.max[0] : b.min[0], i & 2 ? b.max[1] : b.min[1],
                               i & 4 ? b.max[2] : b.min[2]};
                for (int k = 0; k < 3; k++)
                    inside &= p[k] >= ga.min[k] && p[k] <= ga.max[k];
            }
            assert_int_equal(ag_box_contains(&a, &b, eps), inside);
        }
}

/* Touching within a tolerance: faces a hair apart, at every axis and both sides. */
static void test_touch_with_tolerance(void **state)
{
    (void)state;
    for (size_t oi = 0; oi < 3; oi++)
        for (int axis = 0; axis < 3; axis++)
            for (int side = 0; side < 2; side++) {
                const double *o = origins[oi];
                ag_box a = {{o[0], o[1], o[2]}, {o[0] + 3, o[1] + 3, o[2] + 3}};
                ag_box b = a;
                double eps = 1e-3, gap = 0.5e-3;
                if (side) {
                    b.min[axis] = a.max[axis] + gap;
                    b.max[axis] = b.min[axis] + 2;
                } else {
                    b.max[axis] = a.min[axis] - gap;
                    b.min[axis] = b.max[axis] - 2;
                }
                assert_true(ag_box_meets(&a, &b, eps));
                assert_false(ag_box_meets(&a, &b, 0));
                assert_true(ag_box_meets_axis(&a, &b, axis, eps));
                assert_false(ag_box_meets_axis(&a, &b, axis, gap / 4));
                assert_true(ag_box_overlap_axis(&a, &b, axis) < 0);
                ag_box x = ag_box_intersect(&a, &b);
                assert_true(ag_box_is_empty(&x));
                /* flush faces (gap 0) touch with no tolerance at all */
                if (side)
                    b.min[axis] = a.max[axis];
                else
                    b.max[axis] = a.min[axis];
                assert_true(ag_box_meets(&a, &b, 0));
                assert_true(ag_box_overlap_axis(&a, &b, axis) == 0);
            }
}

static void test_clamp(void **state)
{
    (void)state;
    ag_box wall = {{0, 0, 0}, {10, 0.3, 3}};
    ag_box win = {{-1, 0.1, 1}, {2, 0.2, 4}};
    ag_box_clamp(&win, &wall);
    assert_true(win.min[0] == 0 && win.max[0] == 2);
    assert_true(win.min[1] == 0.1 && win.max[1] == 0.2);
    assert_true(win.min[2] == 1 && win.max[2] == 3);
    assert_true(ag_box_contains(&wall, &win, 0));
    /* nothing left on an axis: zero length at the cut-down min */
    ag_box out = {{12, 0.1, 1}, {15, 0.2, 2}};
    ag_box_clamp(&out, &wall);
    assert_true(out.min[0] == 12 && out.max[0] == 12);
    assert_false(ag_box_is_empty(&out));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_and_extend),
        cmocka_unit_test(test_measures),
        cmocka_unit_test(test_relations_match_oracle),
        cmocka_unit_test(test_touch_with_tolerance),
        cmocka_unit_test(test_clamp),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
