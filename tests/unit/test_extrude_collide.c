/* Parts of a plan growing into each other: squares set corner to corner whose soffits (an
 * overhang moving out at the eaves) meet head-on. The parts merge where their eaves meet, as
 * a building of two wings joined at a corner is built; they must never pass through each other
 * (two soffits over one spot, edges used by four faces) nor be refused as not good.
 *
 * Judged by independent checks of the triangles (extrude_check.h: welded closed 2-manifold,
 * winding once, no folded flats) and by the roof's plan area, which is the area of the union
 * of the squares grown by the overhang, computed here from the squares themselves. Every case
 * is turned, moved to UTM-sized coordinates and given in both loop orders. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "core/extrude/extrude.h"
#include "core/extrude/plan.h"
#include "extrude_check.h"

#define OVERHANG 0.5

typedef struct {
    double x0, y0, x1, y1; /* axis-aligned before the turn */
    int walled_top;        /* its top edge a plain wall (no overhang), the others eaves */
} square;

/* Profile 0: wall to 9 m, the soffit OVERHANG out, a roof rising 3 m over 3 m inwards;
 * profile 1: a wall going on up (a gable or party wall). */
static void add_profiles(ag_plan *p)
{
    const ag_profile_point eaves[] = {{0, 0}, {0, 9}, {-OVERHANG, 9}, {2.5, 12}};
    const ag_profile_point wall[] = {{0, 0}, {0, 9}, {0, 12}};
    ag_error err = {0};
    if (ag_plan_add_profile(p, "eaves", eaves, 4, NULL, NULL, &err) ||
        ag_plan_add_profile(p, "wall", wall, 3, NULL, NULL, &err))
        fail_msg("profile: %s", err.text);
}

/* A square grown by the overhang on its eaves' sides. */
static square grown(const square *q)
{
    return (square){q->x0 - OVERHANG, q->y0 - OVERHANG, q->x1 + OVERHANG,
                    q->y1 + (q->walled_top ? 0 : OVERHANG), 0};
}

/* The area of the union of the squares grown by the overhang (they overlap pairwise in
 * small rectangles only, never three at one spot, in the cases below). */
static double grown_union_area(const square *s, size_t n)
{
    double a = 0;
    for (size_t i = 0; i < n; i++) {
        square g = grown(&s[i]);
        a += (g.x1 - g.x0) * (g.y1 - g.y0);
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            square p = grown(&s[i]), q = grown(&s[j]);
            double w = fmin(p.x1, q.x1) - fmax(p.x0, q.x0);
            double h = fmin(p.y1, q.y1) - fmax(p.y0, q.y0);
            if (w > 0 && h > 0)
                a -= w * h;
        }
    return a;
}

/* The plan area of the triangles facing up (the roof and the soffits' tops are one). */
static double up_area(const ag_mesh *m)
{
    double a = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = m->pos + 3 * (size_t)m->tri[3 * t + k];
        double cz = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) -
                    (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
        if (cz > 0)
            a += cz / 2;
    }
    return a;
}

/* One case: the squares turned by `turn` radians about the origin, then moved by (ox, oy),
 * given in order or reversed. Returns the building's volume. */
static double build(const square *s, size_t n, double turn, double ox, double oy, int reversed,
                    const char *what)
{
    ag_plan *p = ag_plan_create();
    add_profiles(p);
    ag_error err = {0};
    double c = cos(turn), sn = sin(turn);
    for (size_t k = 0; k < n; k++) {
        const square *q = &s[reversed ? n - 1 - k : k];
        const double corners[8] = {q->x0, q->y0, q->x1, q->y0, q->x1, q->y1, q->x0, q->y1};
        double xy[8];
        for (int i = 0; i < 4; i++) {
            xy[2 * i] = ox + c * corners[2 * i] - sn * corners[2 * i + 1];
            xy[2 * i + 1] = oy + sn * corners[2 * i] + c * corners[2 * i + 1];
        }
        const int32_t profiles[4] = {0, 0, q->walled_top ? 1 : 0, 0};
        if (ag_plan_add_loop(p, xy, 4, profiles, &err))
            fail_msg("%s: loop: %s", what, err.text);
    }
    ag_mesh *m = ag_mesh_create();
    ag_extrude_result r;
    if (ag_extrude_plan(p, m, -1, &r, NULL, &err))
        fail_msg("%s: refused: %s", what, err.text);
    if (!ag_extrude_result_ok(&r))
        fail_msg("%s: not a good building (%s)", what, r.defect);
    char why[200] = "";
    if (!xc_closed_manifold(m, -1, 1e-7, why, sizeof why))
        fail_msg("%s: reported good but not a closed 2-manifold: %s", what, why);
    long winding = xc_max_winding(m);
    if (winding != 1)
        fail_msg("%s: the shell winds %ld times about a point inside", what, winding);
    size_t folds = xc_flat_folds(m, 1e-9);
    if (folds)
        fail_msg("%s: %zu upward and downward triangles overlap", what, folds);
    double want = grown_union_area(s, n), got = up_area(m);
    if (fabs(got - want) > 1e-6 * want)
        fail_msg("%s: the roof covers %.9g m2 of plan, the grown squares' union %.9g", what,
                 got, want);
    double v = xc_mesh_volume(m);
    ag_mesh_free(m);
    ag_plan_free(p);
    return v;
}

static void run_case(const char *name, const square *s, size_t n)
{
    const double turns[] = {0, 30, 90, 197};
    const double offsets[][2] = {{0, 0}, {512345.0, 5812345.0}};
    double v0 = 0;
    int first = 1;
    for (size_t t = 0; t < sizeof turns / sizeof turns[0]; t++)
        for (size_t o = 0; o < 2; o++)
            for (int rev = 0; rev < 2; rev++) {
                char what[160];
                snprintf(what, sizeof what, "%s, turned %g deg, at (%g, %g)%s", name, turns[t],
                         offsets[o][0], offsets[o][1], rev ? ", loops reversed" : "");
                double v = build(s, n, turns[t] * M_PI / 180, offsets[o][0], offsets[o][1],
                                 rev, what);
                if (first)
                    v0 = v;
                first = 0;
                /* the same building however it lies */
                if (fabs(v - v0) > 1e-6 * v0)
                    fail_msg("%s: volume %.9g, the untouched case's %.9g", what, v, v0);
            }
    print_message("%s: volume %.4f m3, roof plan %.4f m2\n", name, v0, grown_union_area(s, n));
}

/* Two squares corner to corner, apart diagonally by less than the two overhangs: their
 * eaves' corners meet head-on, at a quarter, a half and most of the way out. */
static void two_squares_meeting_corner_to_corner_merge(void **state)
{
    (void)state;
    const double gaps[] = {0.2, 0.5, 0.8};
    for (size_t g = 0; g < 3; g++) {
        double a = 10 + gaps[g];
        const square s[] = {{0, 0, 10, 10, 0}, {a, a, 20, 20, 0}};
        char name[64];
        snprintf(name, sizeof name, "two squares %g m apart", gaps[g]);
        run_case(name, s, 2);
    }
}

/* Three and four squares around one, each meeting it corner to corner. */
static void squares_around_one_merge(void **state)
{
    (void)state;
    const square three[] = {{0, 0, 10, 10, 0}, {10.5, 10.5, 20, 20, 0}, {-9.5, 10.5, -0.5, 20, 0}};
    run_case("three squares", three, 3);
    const square four[] = {{0, 0, 10, 10, 0},
                           {10.5, 10.5, 20, 20, 0},
                           {-9.5, 10.5, -0.5, 20, 0},
                           {10.5, -9.5, 20, -0.5, 0}};
    run_case("four squares", four, 4);
}

/* A square whose top is a plain wall: its top right corner slides out along that wall while
 * the eaves of a square set off diagonally come at it; they meet head-on at a wall. The old
 * pairing let them pass through each other and still called the building closed (the roof
 * covered the overlap twice). */
static void eaves_meeting_a_wall_corner_merge(void **state)
{
    (void)state;
    const double offs[] = {0.1, 0.2, 0.3};
    for (size_t k = 0; k < 3; k++) {
        double d = offs[k];
        const square s[] = {{0, 0, 10, 10, 1}, {10 + 2 * d, 10 + d, 20, 20, 0}};
        char name[80];
        snprintf(name, sizeof name, "eaves meeting a wall corner, %g m off", d);
        run_case(name, s, 2);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(two_squares_meeting_corner_to_corner_merge),
        cmocka_unit_test(squares_around_one_merge),
        cmocka_unit_test(eaves_meeting_a_wall_corner_merge),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
