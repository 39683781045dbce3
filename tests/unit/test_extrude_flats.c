/* Terrace and soffit steps at one height: edges whose profiles step inwards (a terrace) and
 * edges whose profiles step outwards (a soffit) at the same height h, then rise as walls to
 * H. Swept, the two kinds of horizontal face fold over each other around every corner
 * between them; built as the difference of the plans below and above they must make a
 * closed 2-manifold. Generated plans: rectangles, regular polygons and L shapes, plain,
 * turned, jittered and at UTM-sized coordinates, started at every corner. Each building is
 * judged independently of the extrusion's verdict: welded triangles with every directed edge
 * once and its reverse once, the winding number 1 just inside every face, nothing further
 * outside the footprint than the widest soffit's mitre, and the signed volume of the
 * triangles equal to the analytic one, area(plan) h + area(plan above) (H - h), the plan
 * above made of the edges' lines moved by their steps (small steps: no edge vanishes).
 * Polyominoes stepping whole metres (events during the step, parts touching) are judged
 * the same way, styled or fallen back; and the building check must report a fold. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/extrude/building.h"
#include "core/extrude/extrude.h"
#include "core/extrude/shell.h"
#include "core/extrude/verify.h"
#include "extrude_check.h"

#define MAXN 16
#define H_STEP 3.0
#define H_TOP 5.0

static uint64_t rng = 0x8F3A6C1D2B4E5F70ULL;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* Twice the signed area of a polygon, about its first corner. */
static double area2(const double *xy, size_t n)
{
    double a = 0;
    for (size_t i = 1; i + 1 < n; i++)
        a += (xy[2 * i] - xy[0]) * (xy[2 * i + 3] - xy[1]) -
             (xy[2 * i + 2] - xy[0]) * (xy[2 * i + 1] - xy[1]);
    return a;
}

/* The plan above: each edge's line moved inwards by step[i] (negative: outwards), corners
 * where consecutive lines meet; coordinates about the first corner of xy. */
static void moved_plan(const double *xy, size_t n, const double *step, double *out)
{
    double ox = xy[0], oy = xy[1];
    for (size_t j = 0; j < n; j++) {
        size_t i = (j + n - 1) % n; /* edge i ends at corner j, edge j starts there */
        double l[2][3];
        for (int k = 0; k < 2; k++) {
            size_t e = k ? j : i, f = (e + 1) % n;
            double ax = xy[2 * e] - ox, ay = xy[2 * e + 1] - oy;
            double dx = xy[2 * f] - xy[2 * e], dy = xy[2 * f + 1] - xy[2 * e + 1];
            double len = hypot(dx, dy), nx = -dy / len, ny = dx / len;
            l[k][0] = nx, l[k][1] = ny, l[k][2] = nx * ax + ny * ay + step[e];
        }
        double det = l[0][0] * l[1][1] - l[0][1] * l[1][0];
        out[2 * j] = (l[0][2] * l[1][1] - l[0][1] * l[1][2]) / det;
        out[2 * j + 1] = (l[0][0] * l[1][2] - l[0][2] * l[1][0]) / det;
    }
}

/* The base shapes, counter-clockwise. */
static size_t shape(int kind, double *xy)
{
    size_t n = 0;
    if (kind == 0) { /* a rectangle */
        double w = 6 + 4 * rnd(), d = 4 + 3 * rnd();
        double c[] = {0, 0, w, 0, w, d, 0, d};
        memcpy(xy, c, sizeof c);
        n = 4;
    } else if (kind == 1 || kind == 2) { /* a regular pentagon or hexagon */
        n = kind == 1 ? 5 : 6;
        double r = 4 + 2 * rnd();
        for (size_t i = 0; i < n; i++) {
            xy[2 * i] = r * cos(2 * M_PI * (double)i / (double)n);
            xy[2 * i + 1] = r * sin(2 * M_PI * (double)i / (double)n);
        }
    } else { /* an L: reflex corners between the two kinds too */
        double c[] = {0, 0, 8, 0, 8, 3, 3, 3, 3, 7, 0, 7};
        memcpy(xy, c, sizeof c);
        n = 6;
    }
    return n;
}

/* variant: bit 0 turned, bit 1 jittered, bit 2 at UTM-sized coordinates */
static void transform(double *xy, size_t n, int variant)
{
    double a = (variant & 1) ? 0.4 + rnd() : 0;
    double ox = (variant & 4) ? 512345.678 : 0, oy = (variant & 4) ? 5801234.321 : 0;
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        if (variant & 2) {
            x += (rnd() - 0.5) * 0.2;
            y += (rnd() - 0.5) * 0.2;
        }
        xy[2 * i] = ox + x * cos(a) - y * sin(a);
        xy[2 * i + 1] = oy + x * sin(a) + y * cos(a);
    }
}

/* Builds the plan (edge i steps in by step[i] at H_STEP, negative: out, then rises as a
 * wall to H_TOP) through the batch's building path into a new mesh. */
static ag_mesh *build_stepped(const double *xy, size_t n, const double *step,
                              ag_building_result *r)
{
    ag_plan *p = ag_plan_create();
    int32_t *prof = malloc(n * sizeof *prof);
    assert_non_null(prof);
    for (size_t i = 0; i < n; i++) {
        char name[32];
        snprintf(name, sizeof name, "e%zu", i);
        ag_profile_point pts[] = {{0, 0}, {0, H_STEP}, {step[i], H_STEP}, {step[i], H_TOP}};
        ag_plan_add_profile(p, name, pts, 4, NULL, NULL, NULL);
        prof[i] = (int32_t)i;
    }
    ag_plan_add_loop(p, xy, n, prof, NULL);
    free(prof);
    ag_mesh *m = ag_mesh_create();
    ag_extrude_options eo = {0};
    ag_error err = {0};
    assert_int_equal(ag_building_extrude_plan(p, &eo, m, -1, r, &err), AG_OK);
    ag_plan_free(p);
    return m;
}

/* The independent checks of whatever was built: closed 2-manifold after welding, no fold,
 * winding once behind every face, within reach (m) of the footprint. */
static void judge(const ag_mesh *m, const ag_building_result *r, const double *xy, size_t n,
                  double reach, const char *what)
{
    if (r->built == AG_BUILT_NONE)
        fail_msg("%s: nothing built", what);
    if (r->built != AG_BUILT_STYLED && !r->reason[0])
        fail_msg("%s: fell back to %s without a reason", what, ag_built_name(r->built));
    char why[160] = "";
    if (!xc_closed_manifold(m, -1, 1e-7, why, sizeof why))
        fail_msg("%s: built %s but %s", what, ag_built_name(r->built), why);
    size_t folds = xc_flat_folds(m, 1e-9);
    if (folds)
        fail_msg("%s: built %s but %zu upward and downward triangles overlap (a fold)", what,
                 ag_built_name(r->built), folds);
    long w = xc_max_winding(m);
    if (w != 1)
        fail_msg("%s: built %s but the shell winds %ld times just inside a face", what,
                 ag_built_name(r->built), w);
    const double *loops[1] = {xy};
    size_t sizes[1] = {n};
    double out = xc_outside(m, -1, loops, sizes, 1, 0);
    if (out > reach + 1e-6)
        fail_msg("%s: built %s reaching %.3g m outside the footprint (%.3g allowed)", what,
                 ag_built_name(r->built), out, reach);
}

/* Builds the plan and checks it: styled, independently good, the analytic volume. */
static void check_plan(const double *xy, size_t n, const double *step, const char *what)
{
    ag_building_result r;
    ag_mesh *m = build_stepped(xy, n, step, &r);
    if (r.built != AG_BUILT_STYLED)
        fail_msg("%s: built %s: %s", what, ag_built_name(r.built), r.reason);
    double widest = 0;
    for (size_t i = 0; i < n; i++)
        widest = fmax(widest, -step[i]);
    /* a soffit's mitre where it meets a terrace may lead further than its width */
    judge(m, &r, xy, n, 2.5 * widest, what);
    double above[2 * MAXN];
    moved_plan(xy, n, step, above);
    double expect = area2(xy, n) / 2 * H_STEP + area2(above, n) / 2 * (H_TOP - H_STEP);
    double got = xc_mesh_volume(m);
    if (fabs(got - expect) > 1e-7 * fabs(expect) + 1e-6)
        fail_msg("%s: volume %.9f, analytic %.9f", what, got, expect);
    ag_mesh_free(m);
}

/* Terraces and soffits alternating (and in runs) around each shape, every variant, every
 * starting corner. */
static void test_terrace_and_soffit_at_one_height(void **state)
{
    (void)state;
    size_t plans = 0;
    for (int kind = 0; kind < 4; kind++)
        for (int variant = 0; variant < 8; variant++)
            for (int pattern = 0; pattern < 3; pattern++) {
                double base[2 * MAXN], xy[2 * MAXN], step[MAXN], rot_step[MAXN];
                size_t n = shape(kind, base);
                transform(base, n, variant);
                for (size_t i = 0; i < n; i++) {
                    int terrace = pattern == 0 ? (int)(i % 2) : pattern == 1 ? (i % 3 != 0)
                                                                             : rnd() < 0.5;
                    step[i] = terrace ? 0.3 + 0.4 * rnd() : -(0.3 + 0.4 * rnd());
                }
                for (size_t s = 0; s < n; s++) {
                    for (size_t i = 0; i < n; i++) {
                        xy[2 * i] = base[2 * ((i + s) % n)];
                        xy[2 * i + 1] = base[2 * ((i + s) % n) + 1];
                        rot_step[i] = step[(i + s) % n];
                    }
                    char what[96];
                    snprintf(what, sizeof what, "shape %d variant %d pattern %d start %zu", kind,
                             variant, pattern, s);
                    check_plan(xy, n, rot_step, what);
                    plans++;
                }
            }
    printf("terrace and soffit at one height: %zu plans closed, volumes as computed\n", plans);
}

/* The building check reports a fold: a closed box passes; the same box with a sheet of
 * two horizontal faces back to back inside it (upward and downward triangles over the same
 * square, triangulated along different diagonals, every edge paired, no volume) fails, and
 * says why. */
static void test_verify_reports_a_fold(void **state)
{
    (void)state;
    ag_plan *p = ag_plan_create();
    ag_profile_point wall[] = {{0, 0}, {0, 2}};
    ag_plan_add_profile(p, "wall", wall, 2, NULL, NULL, NULL);
    const double sq[] = {0, 0, 4, 0, 4, 4, 0, 4};
    const int32_t prof[] = {0, 0, 0, 0};
    ag_plan_add_loop(p, sq, 4, prof, NULL);
    double extent = 0;
    ag_error err = {0};
    assert_int_equal(ag_plan_validate(p, NULL, &extent, &err), AG_OK);
    for (int sheet = 0; sheet < 2; sheet++) {
        ag_mesh *m = ag_mesh_create();
        for (int k = 0; k < 8; k++)
            ag_mesh_add_vertex(m, (k & 1) ? 4 : 0, (k & 2) ? 4 : 0, (k & 4) ? 2 : 0);
        /* the box, outward: bottom, top, four sides */
        static const uint32_t box[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                            {0, 1, 5}, {0, 5, 4}, {1, 3, 7}, {1, 7, 5},
                                            {3, 2, 6}, {3, 6, 7}, {2, 0, 4}, {2, 4, 6}};
        for (int t = 0; t < 12; t++)
            ag_mesh_add_triangle(m, box[t][0], box[t][1], box[t][2], 0);
        if (sheet) {
            /* a, b, c, d: the square (1, 1)-(3, 3) at height 1 */
            for (int k = 0; k < 4; k++)
                ag_mesh_add_vertex(m, (k == 1 || k == 2) ? 3 : 1, k >= 2 ? 3 : 1, 1);
            ag_mesh_add_triangle(m, 8, 9, 10, 0);  /* up: a b c */
            ag_mesh_add_triangle(m, 8, 10, 11, 0); /* up: a c d */
            ag_mesh_add_triangle(m, 9, 8, 11, 0);  /* down: b a d */
            ag_mesh_add_triangle(m, 9, 11, 10, 0); /* down: b d c */
        }
        char why[200] = "";
        int good = ag_verify_building(m, 0, m->ntris, p, why, sizeof why);
        if (!sheet && !good)
            fail_msg("the closed box is not good: %s", why);
        if (sheet) {
            assert_false(good);
            if (!strstr(why, "folded"))
                fail_msg("the sheet is reported as: %s", why);
            /* the independent check of the tests sees it too; welding and faces per edge
             * do not */
            assert_true(xc_flat_folds(m, 1e-9) > 0);
            assert_true(xc_closed_manifold(m, -1, 1e-7, why, sizeof why));
        }
        ag_mesh_free(m);
    }
    ag_plan_free(p);
}

/* Polyominoes of 2 and 3 m cells whose edges step a whole metre in or out at one height:
 * events during the step (corridors closing, parts growing into notches, corners meeting
 * edges) and parts touching exactly. Every building the batch path calls styled must pass
 * the independent checks; the others must have fallen back with a reason, and the fallback
 * passes them too. */
static void test_grid_terrace_and_soffit(void **state)
{
    (void)state;
    size_t plans = 0, styled = 0;
    for (int k = 0; k < 120; k++) {
        double base[2 * 512], xy[2 * 512], step[256];
        size_t n = xc_polyomino(3 + (int)(rnd() * 4), 2 + (int)(rnd() * 2), base, 512, rnd);
        if (n < 4 || n > 200)
            continue;
        memcpy(xy, base, 2 * n * sizeof *xy);
        transform(xy, n, k % 8);
        for (size_t i = 0; i < n; i++)
            step[i] = rnd() < 0.5 ? 1 : -1;
        ag_building_result r;
        ag_mesh *m = build_stepped(xy, n, step, &r);
        char what[64];
        snprintf(what, sizeof what, "grid plan %d (%zu corners, variant %d)", k, n, k % 8);
        judge(m, &r, xy, n, 2.5, what);
        plans++;
        styled += r.built == AG_BUILT_STYLED;
        ag_mesh_free(m);
    }
    printf("grid plans stepping in and out at one height: %zu plans, %zu styled, %zu fell back "
           "(reported)\n", plans, styled, plans - styled);
    assert_true(plans > 50);
    /* built as the plans' difference nearly all are styled (swept, 4 of these 120 were:
     * the rest folded and fell back) */
    assert_true(styled * 10 >= plans * 9);
}

/* Signed area (seen from above) of face f's loops in a finished shell. */
static double face_area(const ag_shell *s, size_t f)
{
    double a = 0;
    uint32_t nl = s->faces[f].nloops & 0x7fffffffu;
    if (!nl)
        return 0;
    /* about the face's first corner: a UTM-sized origin would drown the area */
    const double *o = &s->pos[3 * s->idx[s->loop_start[s->faces[f].first_loop]]];
    for (uint32_t l = s->faces[f].first_loop; l < s->faces[f].first_loop + nl; l++)
        for (uint32_t i = s->loop_start[l]; i < s->loop_start[l + 1]; i++) {
            uint32_t j = i + 1 < s->loop_start[l + 1] ? i + 1 : s->loop_start[l];
            const double *p = &s->pos[3 * s->idx[i]], *q = &s->pos[3 * s->idx[j]];
            a += (p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1]);
        }
    return a / 2;
}

/* A rectangle [x0, x1] x [y0, y1] at height z as a face of s, upward (counter-clockwise
 * seen from above) or downward. */
static uint32_t add_rect(ag_shell *s, double x0, double y0, double x1, double y1, double z,
                         int up)
{
    ag_shell_face f = {AG_SHELL_FACE_SIDE, 0, 0, 0, 0, 0, 0};
    uint32_t id = 0, v[4];
    assert_int_equal(ag_shell_add_face(s, &f, &id), AG_OK);
    const double c[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (int k = 0; k < 4; k++)
        assert_int_equal(ag_shell_add_vertex(s, c[k][0], c[k][1], z, &v[k]), AG_OK);
    for (int k = 0; k < 4; k++) {
        int a = up ? k : 3 - k, b = up ? (k + 1) % 4 : (3 - k + 3) % 4;
        assert_int_equal(ag_shell_add_segment(s, id, v[a], v[b]), AG_OK);
    }
    return id;
}

/* The rebuild on shells made by hand: an upward and a downward rectangle overlapping become
 * the two differences (the overlap, in neither plan, is gone), at UTM-sized coordinates too;
 * a height where two upward faces overlap (winding 2) is left as it was and counted so. */
static void test_rebuild_by_hand(void **state)
{
    (void)state;
    for (int far = 0; far < 2; far++) {
        double ox = far ? 512345.5 : 0, oy = far ? 5801234.25 : 0;
        ag_shell *s = ag_shell_create();
        uint32_t up = add_rect(s, ox, oy, ox + 2, oy + 2, 1, 1);
        uint32_t down = add_rect(s, ox + 1, oy, ox + 3, oy + 2, 1, 0);
        assert_int_equal(ag_shell_finish(s, 1e-9), AG_OK);
        assert_int_equal(s->flat_levels, 1);
        assert_int_equal(s->flat_rebuilt, 1);
        assert_int_equal(s->flat_left, 0);
        double a_up = 0, a_down = 0;
        for (size_t f = 0; f < s->nfaces; f++) {
            double a = face_area(s, f);
            if (f == up)
                a_up = a;
            else if (f == down)
                a_down = a;
            else
                assert_true(fabs(a) < 1e-6);
        }
        assert_true(fabs(a_up - 2) < 1e-9);
        assert_true(fabs(a_down + 2) < 1e-9);
        /* every corner of the upward face lies in [0, 1] x [0, 2], of the downward one in
         * [2, 3] x [0, 2] */
        for (int which = 0; which < 2; which++) {
            uint32_t f = which ? down : up;
            uint32_t nl = s->faces[f].nloops & 0x7fffffffu;
            assert_int_equal(nl, 1);
            for (uint32_t i = s->loop_start[s->faces[f].first_loop];
                 i < s->loop_start[s->faces[f].first_loop + 1]; i++) {
                double x = s->pos[3 * s->idx[i]] - ox;
                assert_true(which ? x > 2 - 1e-9 : x < 1 + 1e-9);
            }
        }
        ag_shell_free(s);
    }
    /* winding 2: left alone */
    ag_shell *s = ag_shell_create();
    add_rect(s, 0, 0, 2, 2, 1, 1);
    add_rect(s, 1, 0, 3, 2, 1, 1);
    add_rect(s, 5, 0, 6, 1, 1, 0);
    assert_int_equal(ag_shell_finish(s, 1e-9), AG_OK);
    assert_int_equal(s->flat_levels, 1);
    assert_int_equal(s->flat_rebuilt, 0);
    assert_int_equal(s->flat_left, 1);
    assert_true(fabs(face_area(s, 0) - 4) < 1e-9);
    assert_true(fabs(face_area(s, 1) - 4) < 1e-9);
    assert_true(fabs(face_area(s, 2) + 1) < 1e-9);
    ag_shell_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_terrace_and_soffit_at_one_height),
        cmocka_unit_test(test_verify_reports_a_fold),
        cmocka_unit_test(test_grid_terrace_and_soffit),
        cmocka_unit_test(test_rebuild_by_hand),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
