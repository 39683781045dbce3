/* Plan validation: cleaning with reasons, orientation by nesting, rejected input. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "core/extrude/plan.h"

static const ag_profile_point R45[] = {{0, 0}, {1, 1}};

static ag_plan *one_loop(const double *xy, size_t n)
{
    ag_plan *p = ag_plan_create();
    assert_int_equal(ag_plan_add_profile(p, "r", R45, 2, NULL, NULL, NULL), AG_OK);
    assert_int_equal(ag_plan_add_loop(p, xy, n, NULL, NULL), AG_OK);
    return p;
}

static int has_fix(const ag_plan_fixes *f, ag_plan_fix_kind k, long corner)
{
    for (size_t i = 0; i < f->n; i++)
        if (f->fixes[i].kind == k && (corner < -1 || f->fixes[i].corner == corner))
            return 1;
    return 0;
}

static void test_cleaning(void **state)
{
    (void)state;
    /* corner 1 duplicates corner 0, corner 3 sits on the bottom edge, corner 6 is a spike */
    const double xy[] = {0, 0, 0, 0, 4, 0, 10, 0, 10, 6, 5, 6, 5, 9, 5, 6, 0, 6};
    ag_plan *p = one_loop(xy, 9);
    ag_plan_fixes fx = {0};
    ag_error err = {0};
    double ext = 0;
    assert_int_equal(ag_plan_validate(p, &fx, &ext, &err), AG_OK);
    assert_true(has_fix(&fx, AG_PLAN_FIX_DUPLICATE, 1));
    assert_true(has_fix(&fx, AG_PLAN_FIX_COLLINEAR, 2));
    assert_true(has_fix(&fx, AG_PLAN_FIX_SPIKE, 6));
    for (size_t i = 0; i < fx.n; i++)
        assert_true(strlen(fx.fixes[i].reason) > 10);
    assert_int_equal(p->loops[0].n, 4);
    assert_true(fabs(ag_plan_loop_area(&p->loops[0]) - 60) < 1e-12);
    assert_true(fabs(ext - hypot(10, 9)) < 1e-12);
    ag_plan_fixes_free(&fx);
    ag_plan_free(p);
}

/* A spike no wider than the building check's probe (1e-7 of the plan's size, 3 µm here)
 * is removed, a wider one kept: the plan's corners and area say which. */
static void test_thin_spike_removed(void **state)
{
    (void)state;
    const double widths[] = {2e-7, 2e-6, 2e-5};
    for (int k = 0; k < 3; k++) {
        double h = widths[k] / 2;
        const double xy[] = {0, 0, 20, 0, 20, 10, 10 + h, 10, 10, 25, 10 - h, 10, 0, 10};
        ag_plan *p = one_loop(xy, 7);
        ag_plan_fixes fx = {0};
        assert_int_equal(ag_plan_validate(p, &fx, NULL, NULL), AG_OK);
        double area = ag_plan_loop_area(&p->loops[0]);
        if (k < 2) {
            assert_true(has_fix(&fx, AG_PLAN_FIX_SPIKE, 4));
            assert_int_equal(p->loops[0].n, 4);
            assert_true(fabs(area - 200) < 1e-9);
        } else {
            assert_false(has_fix(&fx, AG_PLAN_FIX_SPIKE, -2));
            assert_int_equal(p->loops[0].n, 7);
            assert_true(fabs(area - (200 + 15 * h)) < 1e-9);
        }
        ag_plan_fixes_free(&fx);
        ag_plan_free(p);
    }
}

static void test_collinear_kept_with_other_profile(void **state)
{
    (void)state;
    const double xy[] = {0, 0, 4, 0, 10, 0, 10, 6, 0, 6};
    const int32_t prof[] = {0, 1, 0, 0, 0};
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "a", R45, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "b", R45, 2, NULL, NULL, NULL);
    ag_plan_add_loop(p, xy, 5, prof, NULL);
    ag_plan_fixes fx = {0};
    assert_int_equal(ag_plan_validate(p, &fx, NULL, NULL), AG_OK);
    assert_int_equal(p->loops[0].n, 5); /* the sweep resolves it by priority */
    assert_int_equal(fx.n, 0);
    ag_plan_fixes_free(&fx);
    ag_plan_free(p);
}

static void test_orientation(void **state)
{
    (void)state;
    /* outer given clockwise, hole given counter-clockwise, island in the hole CW */
    const double outer[] = {0, 0, 0, 20, 20, 20, 20, 0};
    const double hole[] = {5, 5, 15, 5, 15, 15, 5, 15};
    const double island[] = {8, 8, 8, 12, 12, 12, 12, 8};
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "r", R45, 2, NULL, NULL, NULL);
    const int32_t prof[] = {0, 0, 0, 0};
    ag_plan_add_loop(p, outer, 4, prof, NULL);
    ag_plan_add_loop(p, hole, 4, prof, NULL);
    ag_plan_add_loop(p, island, 4, prof, NULL);
    ag_plan_fixes fx = {0};
    assert_int_equal(ag_plan_validate(p, &fx, NULL, NULL), AG_OK);
    assert_true(ag_plan_loop_area(&p->loops[0]) > 0);
    assert_true(ag_plan_loop_area(&p->loops[1]) < 0);
    assert_true(ag_plan_loop_area(&p->loops[2]) > 0);
    assert_int_equal(fx.n, 3);
    assert_true(has_fix(&fx, AG_PLAN_FIX_REVERSED, -1));
    ag_plan_fixes_free(&fx);
    ag_plan_free(p);
}

static void test_reversal_keeps_edge_profiles(void **state)
{
    (void)state;
    /* clockwise square whose edge from (0,0) to (0,4) has profile 1 */
    const double xy[] = {0, 0, 0, 4, 4, 4, 4, 0};
    const int32_t prof[] = {1, 0, 0, 0};
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "a", R45, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "b", R45, 2, NULL, NULL, NULL);
    ag_plan_add_loop(p, xy, 4, prof, NULL);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, NULL), AG_OK);
    const ag_plan_loop *l = &p->loops[0];
    int found = 0;
    for (size_t i = 0; i < 4; i++) {
        size_t j = (i + 1) % 4;
        if (l->profile[i] == 1) {
            /* the same segment, now running from (0,4) to (0,0) */
            assert_true(l->xy[2 * i] == 0 && l->xy[2 * i + 1] == 4);
            assert_true(l->xy[2 * j] == 0 && l->xy[2 * j + 1] == 0);
            found++;
        }
    }
    assert_int_equal(found, 1);
    ag_plan_free(p);
}

static void test_rejects(void **state)
{
    (void)state;
    ag_error err = {0};
    /* bow tie */
    const double bow[] = {0, 0, 10, 10, 10, 0, 0, 6};
    ag_plan *p = one_loop(bow, 4);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "crosses"));
    ag_plan_free(p);
    /* a hole crossing the outer ring where it touches it (its corner on the outer edge,
     * one of its edges outside) */
    const double outer[] = {0, 0, 10, 0, 10, 10, 0, 10};
    const double hole[] = {0, 5, 5, 4, -2, 7};
    p = one_loop(outer, 4);
    ag_plan_add_loop(p, hole, 3, NULL, NULL);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "crosses"));
    ag_plan_free(p);
    /* a hole running along the outer ring (an overlap, not a point) */
    const double along[] = {0, 4, 3, 5, 0, 6};
    p = one_loop(outer, 4);
    ag_plan_add_loop(p, along, 3, NULL, NULL);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "overlaps"));
    ag_plan_free(p);
    /* a ring touching itself (its corner 4 on its edge 1) */
    const double pinch[] = {0, 0, 10, 0, 10, 10, 5, 5, 10, 5, 0, 10};
    p = one_loop(pinch, 6);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "loop 0: edge"));
    ag_plan_free(p);
    /* a symmetric bow tie has no area, but it is refused for crossing, not for that */
    const double sym[] = {0, 0, 10, 0, 0, 10, 10, 10};
    p = one_loop(sym, 4);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "edge 1 crosses edge 3"));
    ag_plan_free(p);
    /* NaN */
    const double bad[] = {0, 0, NAN, 0, 1, 1};
    p = one_loop(bad, 3);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_int_equal(err.element, 1);
    ag_plan_free(p);
    /* degenerate: everything on a line */
    const double line[] = {0, 0, 1, 0, 2, 0};
    p = one_loop(line, 3);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_EMPTY);
    ag_plan_free(p);
    /* profile index out of range */
    const int32_t prof[] = {0, 3, 0, 0};
    p = ag_plan_create();
    ag_plan_add_profile(p, "r", R45, 2, NULL, NULL, NULL);
    ag_plan_add_loop(p, outer, 4, prof, NULL);
    assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "profile"));
    ag_plan_free(p);
}

/* OGC-valid touches are accepted: a hole touching the outer ring at a point, two outer
 * rings meeting at a corner. The touching corner is moved a hair off (a reported fix), so
 * walls on both loops never share an edge, and nothing else changes. */
static void test_touching_loops_accepted(void **state)
{
    (void)state;
    const double outer[] = {0, 0, 10, 0, 10, 10, 0, 10};
    const double hole[] = {0, 5, 5, 4, 5, 6};        /* CCW: validation reverses it too */
    const double other[] = {10, 10, 20, 10, 20, 20, 10, 20};
    const double *second[] = {hole, other};
    const size_t n2[] = {3, 4};
    for (int c = 0; c < 2; c++) {
        ag_plan *p = one_loop(outer, 4);
        assert_int_equal(ag_plan_add_loop(p, second[c], n2[c], NULL, NULL), AG_OK);
        ag_plan_fixes fx = {0};
        ag_error err = {0};
        if (ag_plan_validate(p, &fx, NULL, &err) != AG_OK)
            fail_msg("case %d: %s", c, err.text);
        assert_int_equal(p->nloops, 2);
        assert_true(has_fix(&fx, AG_PLAN_FIX_TOUCH, -2));
        /* the moved corner is off the other loop by a gap well above the weld tolerance
         * and well below a millimetre; every other corner is where it was */
        const ag_plan_loop *l = &p->loops[1];
        double dmin = INFINITY;
        size_t same = 0;
        for (size_t i = 0; i < l->n; i++) {
            for (size_t k = 0; k < n2[c]; k++)
                same += l->xy[2 * i] == second[c][2 * k] && l->xy[2 * i + 1] == second[c][2 * k + 1];
            double x = l->xy[2 * i], y = l->xy[2 * i + 1];
            if (c == 0)
                dmin = fmin(dmin, x); /* distance to the outer edge x = 0 */
            else
                dmin = fmin(dmin, hypot(x - 10, y - 10));
        }
        assert_int_equal(same, n2[c] - 1);
        assert_true(dmin > 1e-5 && dmin < 1e-3);
        ag_plan_fixes_free(&fx);
        ag_plan_free(p);
    }
}

static void test_profiles_checked(void **state)
{
    (void)state;
    ag_plan *p = ag_plan_create();
    ag_error err = {0};
    const ag_profile_point down[] = {{0, 0}, {0, 3}, {1, 2}};
    assert_int_equal(ag_plan_add_profile(p, "down", down, 3, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "monotone"));
    const ag_profile_point off[] = {{1, 0}, {1, 3}};
    assert_int_equal(ag_plan_add_profile(p, "off", off, 2, NULL, NULL, &err), AG_ERR_INVALID);
    const ag_profile_point flat_end[] = {{0, 0}, {0, 3}, {1, 3}};
    assert_int_equal(ag_plan_add_profile(p, "flat", flat_end, 3, NULL, NULL, &err), AG_ERR_INVALID);
    const ag_profile_point two_flat[] = {{0, 0}, {0, 3}, {1, 3}, {2, 3}, {2, 4}};
    assert_int_equal(ag_plan_add_profile(p, "two", two_flat, 5, NULL, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "horizontal"));
    const ag_profile_point one[] = {{0, 0}};
    assert_int_equal(ag_plan_add_profile(p, "one", one, 1, NULL, NULL, &err), AG_ERR_INVALID);
    const ag_profile_point ok[] = {{0, 0}, {0, 3}, {-0.5, 3.2}, {0.5, 4.2}};
    size_t idx = 99;
    assert_int_equal(ag_plan_add_profile(p, "ok", ok, 4, "roof", &idx, &err), AG_OK);
    assert_int_equal(idx, 0);
    assert_int_equal(ag_plan_find_profile(p, "ok"), 0);
    assert_int_equal(ag_plan_find_profile(p, "nope"), -1);
    assert_string_equal(p->profiles[0].tag, "roof");
    ag_plan_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cleaning),
        cmocka_unit_test(test_thin_spike_removed),
        cmocka_unit_test(test_collinear_kept_with_other_profile),
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_reversal_keeps_edge_profiles),
        cmocka_unit_test(test_rejects),
        cmocka_unit_test(test_touching_loops_accepted),
        cmocka_unit_test(test_profiles_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
