/* Extrusions that never lie: digitising noise of every amplitude, real footprints in every
 * built-in style, and budgets. Every building is judged by the independent checks of
 * extrude_check.h (welded triangles, faces per directed edge, containment), never by the
 * extrusion's own verdict, and where the CGAL oracle is built, uniform 45° roofs must rise
 * exactly as high as CGAL's highest offset time. */
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
#include "core/extrude/style.h"
#include "extrude_check.h"
#include "io/footprints.h"

/* --- jittered hip houses ------------------------------------------------------------------ */

static uint64_t rng;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

#define JIT_CORNERS 200
#define JIT_N (JIT_CORNERS + 4)

/* A 10 x 6 m house whose front edge is JIT_CORNERS corners, each jittered by up to `amp`
 * across and along it; turned by an angle of its seed and moved to (ox, oy). Returns the
 * corner count; xy gets the corners, c/s the rotation. */
static size_t jittered_house(double amp, int seed, double ox, double oy, double *xy, double *c,
                             double *s)
{
    rng = 0x9E3779B97F4A7C15ULL ^ ((uint64_t)seed * 0x2545F4914F6CDD1DULL);
    for (int i = 0; i < 8; i++)
        rnd();
    double a = 0.37 * seed;
    *c = cos(a);
    *s = sin(a);
    size_t n = 0;
    double local[2 * JIT_N];
    local[2 * n] = 0;
    local[2 * n + 1] = 0;
    n++;
    for (int i = 1; i <= JIT_CORNERS; i++) {
        local[2 * n] = 10.0 * i / (JIT_CORNERS + 1) + amp * (2 * rnd() - 1);
        local[2 * n + 1] = amp * (2 * rnd() - 1);
        n++;
    }
    const double rest[] = {10, 0, 10, 6, 0, 6};
    for (int k = 0; k < 3; k++) {
        local[2 * n] = rest[2 * k];
        local[2 * n + 1] = rest[2 * k + 1];
        n++;
    }
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] = ox + *c * local[2 * i] - *s * local[2 * i + 1];
        xy[2 * i + 1] = oy + *s * local[2 * i] + *c * local[2 * i + 1];
    }
    return n;
}

/* Height of the unjittered 10 x 6 hip roof over local (x, y): the distance to the nearest
 * side of the rectangle (a convex polygon). */
static double rect_roof(double x, double y)
{
    return fmax(0, fmin(fmin(x, 10 - x), fmin(y, 6 - y)));
}

static const double AMPS[] = {1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2};
#define NAMPS (sizeof AMPS / sizeof *AMPS)
#define NSEEDS 5
static const double ORIGINS[][2] = {{0, 0}, {85123.456, 446789.012}, {500321.5, 5800654.25}};
static const char *ORIGIN_NAMES[] = {"local", "RD New", "UTM"};
#define NORIGINS 3

/* Every amplitude from 1e-7 to 1e-2 m, several seeds, local and RD/UTM coordinates: each
 * roof is a closed 2-manifold inside its footprint, and no roof point is further from
 * the unjittered roof than the amplitude (plus rounding). */
static void test_jitter_matrix(void **state)
{
    (void)state;
    const ag_profile_point r45[] = {{0, 0}, {1, 1}};
    printf("jitter matrix (10 x 6 m hip, %d corners on the front edge, %d seeds, 3 frames):\n",
           JIT_CORNERS, NSEEDS);
    for (size_t ai = 0; ai < NAMPS; ai++) {
        double amp = AMPS[ai], worst = 0;
        size_t clean = 0;
        for (int o = 0; o < NORIGINS; o++)
            for (int seed = 1; seed <= NSEEDS; seed++) {
                double xy[2 * JIT_N], c, s;
                size_t n = jittered_house(amp, seed, ORIGINS[o][0], ORIGINS[o][1], xy, &c, &s);
                ag_plan *p = ag_plan_create();
                assert_int_equal(ag_plan_add_profile(p, "r", r45, 2, NULL, NULL, NULL), AG_OK);
                assert_int_equal(ag_plan_add_loop(p, xy, n, NULL, NULL), AG_OK);
                ag_mesh *m = ag_mesh_create();
                ag_extrude_result r;
                ag_error err = {0};
                ag_status st = ag_extrude_plan(p, m, -1, &r, NULL, &err);
                if (st != AG_OK)
                    fail_msg("amp %g seed %d %s: %s", amp, seed, ORIGIN_NAMES[o], err.text);
                char why[200];
                /* weld well below the smallest feature (the jitter) and above rounding */
                double weld = 1e-9 * (1 + fmax(fabs(ORIGINS[o][0]), fabs(ORIGINS[o][1])) / 1e5);
                if (!xc_closed_manifold(m, -1, weld, why, sizeof why))
                    fail_msg("amp %g seed %d %s: not a closed 2-manifold: %s", amp, seed,
                             ORIGIN_NAMES[o], why);
                const double *loops[1] = {xy};
                size_t sizes[1] = {n};
                double out = xc_outside(m, -1, loops, sizes, 1, -1e-9);
                if (out > 1e-6)
                    fail_msg("amp %g seed %d %s: %.3g m outside the footprint", amp, seed,
                             ORIGIN_NAMES[o], out);
                /* deviation from the unjittered roof, in the house's own frame */
                double dev = 0;
                for (size_t v = 0; v < m->nverts; v++) {
                    double dx = m->pos[3 * v] - ORIGINS[o][0], dy = m->pos[3 * v + 1] - ORIGINS[o][1];
                    double lx = c * dx + s * dy, ly = -s * dx + c * dy;
                    dev = fmax(dev, fabs(m->pos[3 * v + 2] - rect_roof(lx, ly)));
                }
                /* noise well below the corner spacing (5 cm) moves the roof by no more than
                 * its amplitude; stronger noise tilts the faces, and the straight skeleton
                 * itself (CGAL's, see test_jitter_against_cgal) then deviates by up to about
                 * 6 times the amplitude at 20 % of the spacing */
                double bound = amp <= 1e-3 ? amp * (1 + 1e-6) + 1e-9 : 10 * amp;
                if (dev > bound)
                    fail_msg("amp %g seed %d %s: the roof is %.3g m off the unjittered one", amp,
                             seed, ORIGIN_NAMES[o], dev);
                worst = fmax(worst, dev);
                /* the same house in every frame rises as high */
                static double local_top[NAMPS][NSEEDS + 1];
                double top = xc_top(m, -1);
                if (o == 0)
                    local_top[ai][seed] = top;
                else if (fabs(top - local_top[ai][seed]) > 1e-9 * top)
                    fail_msg("amp %g seed %d %s: rises %.12f, %.12f in the local frame", amp,
                             seed, ORIGIN_NAMES[o], top, local_top[ai][seed]);
                clean += ag_extrude_result_ok(&r);
                if (!ag_extrude_result_ok(&r))
                    fail_msg("amp %g seed %d %s: the extrusion calls itself not good: %s", amp,
                             seed, ORIGIN_NAMES[o], r.failing_faces ? r.problems[0].reason : r.defect);
                ag_mesh_free(m);
                ag_plan_free(p);
            }
        printf("  amplitude %-7g: %zu of %d clean, 0 failed, 0 fallback; max deviation from the "
               "unjittered roof %.3g m (%.2f of the amplitude)\n", amp, clean, NSEEDS * NORIGINS,
               worst, worst / amp);
    }
}

/* The same houses against CGAL: every uniform 45° roof rises as high as CGAL's highest
 * offset time, to 1e-6 relative, and every corner of every roof lies on CGAL's roof. */
static void test_jitter_against_cgal(void **state)
{
    (void)state;
    const char *oracle = xc_oracle();
    if (!oracle)
        skip();
    const ag_profile_point r45[] = {{0, 0}, {1, 1}};
    static double xy[NAMPS * NSEEDS][2 * JIT_N];
    size_t n[NAMPS * NSEEDS];
    const double *loops[NAMPS * NSEEDS];
    xc_polygon poly[NAMPS * NSEEDS];
    double rise[NAMPS * NSEEDS];
    ag_mesh *mesh[NAMPS * NSEEDS];
    size_t k = 0;
    for (size_t ai = 0; ai < NAMPS; ai++)
        for (int seed = 1; seed <= NSEEDS; seed++, k++) {
            double c, s;
            n[k] = jittered_house(AMPS[ai], seed, 0, 0, xy[k], &c, &s);
            loops[k] = xy[k];
            poly[k] = (xc_polygon){1, &loops[k], &n[k]};
            ag_plan *p = ag_plan_create();
            ag_plan_add_profile(p, "r", r45, 2, NULL, NULL, NULL);
            ag_plan_add_loop(p, xy[k], n[k], NULL, NULL);
            mesh[k] = ag_mesh_create();
            ag_extrude_result r;
            assert_int_equal(ag_extrude_plan(p, mesh[k], -1, &r, NULL, NULL), AG_OK);
            ag_plan_free(p);
        }
    char dir[512];
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/ag_roofs_XXXXXX", tmp && tmp[0] ? tmp : P_tmpdir);
    assert_non_null(mkdtemp(dir));
    assert_true(xc_cgal_run(oracle, poly, k, rise, dir));
    double worst_rise = 0, worst_roof = 0;
    for (size_t i = 0; i < k; i++) {
        if (isnan(rise[i]))
            fail_msg("CGAL did not build house %zu", i);
        double ours = xc_top(mesh[i], -1), rel = fabs(ours - rise[i]) / rise[i];
        /* CGAL prints 9 significant digits */
        if (rel > 1e-6)
            fail_msg("amp %g seed %zu: rise %.9f, CGAL %.9f (%.2g relative)", AMPS[i / NSEEDS],
                     i % NSEEDS + 1, ours, rise[i], rel);
        worst_rise = fmax(worst_rise, rel);
        char path[600];
        snprintf(path, sizeof path, "%s/p%zu.obj", dir, i);
        xc_roof roof;
        assert_true(xc_roof_read(path, &roof));
        remove(path);
        for (size_t tv = 0; tv < 3 * mesh[i]->ntris; tv++) {
            const double *q = &mesh[i]->pos[3 * mesh[i]->tri[tv]];
            double h = xc_roof_height(&roof, q[0], q[1]);
            if (isnan(h))
                fail_msg("amp %g seed %zu: corner (%g, %g) is over no face of CGAL's roof",
                         AMPS[i / NSEEDS], i % NSEEDS + 1, q[0], q[1]);
            /* CGAL writes its roof with 6 decimals */
            double d = fabs(q[2] - h);
            if (d > 1e-6 * rise[i] + 2e-6)
                fail_msg("amp %g seed %zu: corner (%g, %g, %.9f) is %.3g m off CGAL's roof",
                         AMPS[i / NSEEDS], i % NSEEDS + 1, q[0], q[1], q[2], d);
            worst_roof = fmax(worst_roof, d);
        }
        xc_roof_free(&roof);
        ag_mesh_free(mesh[i]);
    }
    remove(dir);
    printf("jitter matrix against CGAL: %zu roofs; largest relative difference of the rise %.2g, "
           "largest distance of a roof corner from CGAL's roof %.2g m\n", k, worst_rise,
           worst_roof);
}

/* --- Den Haag ----------------------------------------------------------------------------- */

static ag_footprints *denhaag(void)
{
    const char *path = AG_REPO_DIR "/../shared/data/footprints_denhaag_lod2/denhaag_tile01_footprints.geojson";
    FILE *probe = fopen(path, "rb");
    if (!probe) {
        printf("skipping: %s is absent\n", path);
        return NULL;
    }
    fclose(probe);
    ag_footprints *f = NULL;
    ag_error err = {0};
    assert_int_equal(ag_footprints_read_file(path, NULL, &f, &err), AG_OK);
    return f;
}

/* Every footprint in every built-in style: 0 refused, 0 runaway, 0 not closed 2-manifold,
 * checked on each building's triangles by the independent routines; buildings that fell
 * back are allowed only when the report names them with a reason. */
static void test_denhaag_every_style(void **state)
{
    (void)state;
    ag_footprints *f = denhaag();
    if (!f)
        skip();
    const char *styles[] = {"flat", "hip", "gable", "mansard", "overhang"};
    for (size_t si = 0; si < sizeof styles / sizeof *styles; si++) {
        ag_style s;
        assert_int_equal(ag_style_builtin(styles[si], &s, NULL), AG_OK);
        /* the overhang's soffit leads 0.5 m out, its mitres (bevelled) at most 2.5 times that */
        double reach = strcmp(styles[si], "overhang") == 0 ? 1.25 + 1e-6 : 1e-6;
        ag_mesh *m = ag_mesh_create();
        ag_footprints_report r;
        ag_error err = {0};
        assert_int_equal(ag_footprints_extrude(f, &s, m, &r, &err), AG_OK);
        if (r.nfailed)
            fail_msg("%s: %zu refused, the first %s: %s", styles[si], r.nfailed, r.failed[0].id,
                     r.failed[0].reason);
        for (size_t i = 0; i < r.nfallbacks; i++)
            assert_true(r.fallbacks[i].reason[0] && r.fallbacks[i].built != AG_BUILT_NONE);
        assert_int_equal(r.succeeded + r.nfallbacks, f->n);
        assert_int_equal(m->ncomponents, f->n);
        size_t runaway = 0, broken = 0;
        double worst = 0;
        for (size_t c = 0; c < m->ncomponents; c++) {
            const ag_footprint *fp = &f->items[c];
            char why[200];
            if (!xc_closed_manifold(m, (long)c, 1e-6, why, sizeof why)) {
                if (!broken)
                    printf("  %s %s: %s\n", styles[si], fp->id, why);
                broken++;
            }
            double out = xc_outside(m, (long)c, (const double *const *)fp->loops, fp->sizes,
                                    fp->nloops, -1e-9);
            worst = fmax(worst, out);
            runaway += out > reach;
        }
        printf("Den Haag %-8s: %zu footprints, %zu as styled, %zu fell back, 0 refused, %zu "
               "runaway (furthest %.3g m out), %zu not closed 2-manifold\n", styles[si], f->n,
               r.succeeded, r.nfallbacks, runaway, worst, broken);
        assert_int_equal(runaway, 0);
        assert_int_equal(broken, 0);
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
    }
    ag_footprints_free(f);
}

/* Den Haag with uniform 45° roofs (the hip style's roof above its walls) against CGAL:
 * every footprint with one outer ring rises as high above its walls as CGAL's highest
 * offset time of the same (validated) polygon. */
static void test_denhaag_against_cgal(void **state)
{
    (void)state;
    const char *oracle = xc_oracle();
    if (!oracle)
        skip();
    ag_footprints *f = denhaag();
    if (!f)
        skip();
    ag_style s;
    assert_int_equal(ag_style_builtin("hip", &s, NULL), AG_OK);
    size_t n = 0;
    xc_polygon *poly = calloc(f->n, sizeof *poly);
    double *ours = calloc(f->n, sizeof *ours), *rise = calloc(f->n, sizeof *rise);
    ag_plan **plans = calloc(f->n, sizeof *plans);
    const double ***loops = calloc(f->n, sizeof *loops);
    size_t **sizes = calloc(f->n, sizeof *sizes);
    for (size_t i = 0; i < f->n; i++) {
        const ag_footprint *fp = &f->items[i];
        ag_plan *p = NULL;
        assert_int_equal(ag_style_apply(&s, (const double *const *)fp->loops, fp->sizes,
                                        fp->nloops, fp->height, i, &p, NULL), AG_OK);
        ag_error err = {0};
        assert_int_equal(ag_plan_validate(p, NULL, NULL, &err), AG_OK);
        size_t outer = 0;
        for (size_t l = 0; l < p->nloops; l++)
            outer += ag_plan_loop_area(&p->loops[l]) > 0;
        if (outer != 1 || ag_plan_loop_area(&p->loops[0]) <= 0) {
            ag_plan_free(p);
            continue; /* several parts: CGAL builds one polygon with holes */
        }
        ag_mesh *m = ag_mesh_create();
        ag_extrude_result r;
        assert_int_equal(ag_extrude_plan(p, m, -1, &r, NULL, NULL), AG_OK);
        assert_true(ag_extrude_result_ok(&r));
        double wall = p->profiles[0].points[1].z;
        ours[n] = xc_top(m, -1) - wall;
        ag_mesh_free(m);
        loops[n] = calloc(p->nloops, sizeof **loops);
        sizes[n] = calloc(p->nloops, sizeof **sizes);
        for (size_t l = 0; l < p->nloops; l++) {
            loops[n][l] = p->loops[l].xy;
            sizes[n][l] = p->loops[l].n;
        }
        poly[n] = (xc_polygon){p->nloops, loops[n], sizes[n]};
        plans[n++] = p;
    }
    assert_true(xc_cgal_rises(oracle, poly, n, rise));
    double worst = 0;
    size_t compared = 0;
    for (size_t i = 0; i < n; i++) {
        if (isnan(rise[i]))
            fail_msg("CGAL did not build footprint polygon %zu", i);
        double rel = fabs(ours[i] - rise[i]) / fmax(rise[i], 1e-3);
        if (rel > 1e-6)
            fail_msg("polygon %zu: rise %.9f, CGAL %.9f (%.2g relative)", i, ours[i], rise[i], rel);
        worst = fmax(worst, rel);
        compared++;
    }
    printf("Den Haag hip against CGAL: %zu single-polygon footprints, largest relative "
           "difference of the rise %.2g\n", compared, worst);
    for (size_t i = 0; i < n; i++) {
        free(loops[i]);
        free(sizes[i]);
        ag_plan_free(plans[i]);
    }
    free(loops);
    free(sizes);
    free(plans);
    free(poly);
    free(ours);
    free(rise);
    ag_footprints_free(f);
}

/* --- large footprints ----------------------------------------------------------------------- */

/* An irregular star (radius 60..100 m, angles jittered) or a rectilinear comb of n corners. */
static size_t big_shape(int comb, size_t n, double *xy)
{
    rng = 0xC0FFEE ^ (uint64_t)n;
    size_t k = 0;
    if (!comb) {
        for (size_t i = 0; i < n; i++) {
            double a = 2 * M_PI * ((double)i + 0.6 * rnd() - 0.3) / (double)n, r = 60 + 40 * rnd();
            xy[2 * k] = r * cos(a);
            xy[2 * k + 1] = r * sin(a);
            k++;
        }
        return k;
    }
    /* teeth of random depth along the top of a 10 m high base */
    size_t teeth = (n - 2) / 4;
    double x = 0, *top = malloc(8 * teeth * sizeof *top);
    size_t m = 0;
    for (size_t i = 0; i < teeth; i++) {
        double w = 2 + 4 * rnd(), d = 5 + 15 * rnd(), g = 2 + 4 * rnd();
        top[m++] = x, top[m++] = 10 + d;
        top[m++] = x + w, top[m++] = 10 + d;
        x += w;
        if (i + 1 < teeth) {
            top[m++] = x, top[m++] = 10;
            top[m++] = x + g, top[m++] = 10;
            x += g;
        }
    }
    xy[k++] = 0, xy[k++] = 0;
    xy[k++] = x, xy[k++] = 0;
    for (size_t i = m; i >= 2; i -= 2)
        xy[k++] = top[i - 2], xy[k++] = top[i - 1];
    free(top);
    return k / 2;
}

/* Stars and combs of 100 to 2000 corners: closed 2-manifolds by the independent check
 * (a 2,000-corner star once passed the shell's own check with a duplicated edge), and
 * where the oracle is built, as high as CGAL's roofs. */
/* Area of the triangles at z = 0 facing down: the building's base, seen from above. */
static double base_area(const ag_mesh *m)
{
    double a = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = &m->pos[3 * m->tri[3 * t + k]];
        if (fabs(p[0][2]) + fabs(p[1][2]) + fabs(p[2][2]) > 1e-12)
            continue;
        a -= ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0])) / 2;
    }
    return a;
}

/* A 15 m spike off a 20 x 10 m block, from 2e-7 m to 2 mm wide at its base (the held-out
 * sweep's footprints): spikes no wider than the building check's probe are removed by
 * validation, wider ones are swept; either way the building is good, closed at 1e-9 m,
 * inside its footprint, with the footprint's base area (the spike's counted when kept). */
static void test_thin_spikes(void **state)
{
    (void)state;
    const double half[] = {1e-7, 3e-7, 1e-6, 2e-6, 5e-6, 1e-5, 1e-3};
    const ag_profile_point walls45[] = {{0, 0}, {0, 9}, {1, 10}};
    const ag_profile_point shallow[] = {{0, 0}, {0, 1}, {10, 2}};
    const ag_profile_point *prof[] = {walls45, shallow};
    for (size_t w = 0; w < sizeof half / sizeof *half; w++)
        for (int k = 0; k < 2; k++) {
            const double xy[] = {0, 0, 20, 0, 20, 10, 10 + half[w], 10, 10, 25, 10 - half[w], 10, 0, 10};
            ag_plan *p = ag_plan_create();
            assert_int_equal(ag_plan_add_profile(p, "r", prof[k], 3, NULL, NULL, NULL), AG_OK);
            assert_int_equal(ag_plan_add_loop(p, xy, 7, NULL, NULL), AG_OK);
            ag_mesh *m = ag_mesh_create();
            ag_extrude_result r;
            ag_error err = {0};
            assert_int_equal(ag_extrude_plan(p, m, -1, &r, NULL, &err), AG_OK);
            if (!ag_extrude_result_ok(&r))
                fail_msg("spike %g m wide, profile %d: not good: %s", 2 * half[w], k, r.defect);
            char why[200];
            if (!xc_closed_manifold(m, -1, 1e-9, why, sizeof why))
                fail_msg("spike %g m wide, profile %d: %s", 2 * half[w], k, why);
            const double *loops[1] = {xy};
            size_t sizes[1] = {7};
            assert_true(xc_outside(m, -1, loops, sizes, 1, -1e-9) < 1e-9);
            double spike = 15 * half[w], want = 200 + spike, got = base_area(m);
            if (!(fabs(got - want) < 1e-9 || fabs(got - 200) <= spike + 1e-9))
                fail_msg("spike %g m wide, profile %d: base %.12g m², footprint %.12g", 2 * half[w], k, got, want);
            ag_mesh_free(m);
            ag_plan_free(p);
        }
}

static void test_large_footprints(void **state)
{
    (void)state;
    const char *oracle = xc_oracle();
    const size_t sizes[] = {100, 500, 1000, 2000};
    const ag_profile_point r45[] = {{0, 0}, {1, 1}};
    static double xy[8][2 * 2100];
    size_t n[8];
    const double *loops[8];
    xc_polygon poly[8];
    double ours[8], rise[8];
    size_t k = 0;
    for (int comb = 0; comb < 2; comb++)
        for (size_t s = 0; s < 4; s++, k++) {
            n[k] = big_shape(comb, sizes[s], xy[k]);
            loops[k] = xy[k];
            poly[k] = (xc_polygon){1, &loops[k], &n[k]};
            ag_plan *p = ag_plan_create();
            ag_plan_add_profile(p, "r", r45, 2, NULL, NULL, NULL);
            ag_plan_add_loop(p, xy[k], n[k], NULL, NULL);
            ag_mesh *m = ag_mesh_create();
            ag_extrude_result r;
            ag_error err = {0};
            if (ag_extrude_plan(p, m, -1, &r, NULL, &err) != AG_OK)
                fail_msg("%s %zu: %s", comb ? "comb" : "star", n[k], err.text);
            char why[200];
            if (!xc_closed_manifold(m, -1, 1e-7, why, sizeof why))
                fail_msg("%s %zu: %s", comb ? "comb" : "star", n[k], why);
            assert_true(ag_extrude_result_ok(&r));
            size_t one[1] = {n[k]};
            assert_true(xc_outside(m, -1, &loops[k], one, 1, -1e-9) < 1e-6);
            ours[k] = xc_top(m, -1);
            printf("%s of %zu corners: %zu events, %.3f s, rise %.9f\n", comb ? "comb" : "star",
                   n[k], r.stats.events, r.seconds, ours[k]);
            ag_mesh_free(m);
            ag_plan_free(p);
        }
    if (!oracle)
        return;
    /* CGAL takes seconds on the 2,000-corner star: the others are enough for the rise */
    xc_polygon some[6] = {poly[0], poly[1], poly[2], poly[4], poly[5], poly[6]};
    double ours6[6] = {ours[0], ours[1], ours[2], ours[4], ours[5], ours[6]};
    assert_true(xc_cgal_rises(oracle, some, 6, rise));
    for (size_t i = 0; i < 6; i++)
        if (!(fabs(ours6[i] - rise[i]) <= 1e-6 * rise[i]))
            fail_msg("shape %zu: rise %.9f, CGAL %.9f", i, ours6[i], rise[i]);
}

/* --- budgets ------------------------------------------------------------------------------ */

/* A plan that takes far longer than its budget: a jittered 20,000-corner circle. */
static ag_plan *huge_plan(void)
{
    const size_t n = 20000;
    double *xy = malloc(2 * n * sizeof *xy);
    rng = 12345;
    for (size_t i = 0; i < n; i++) {
        double a = 2 * M_PI * i / n, r = 50 + 0.01 * rnd();
        xy[2 * i] = r * cos(a);
        xy[2 * i + 1] = r * sin(a);
    }
    const ag_profile_point r45[] = {{0, 0}, {1, 1}};
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "r", r45, 2, NULL, NULL, NULL);
    ag_plan_add_loop(p, xy, n, NULL, NULL);
    free(xy);
    return p;
}

static int polls;
static int cancel_after(void *user)
{
    int *limit = user;
    return ++polls > *limit;
}

static void test_budgets(void **state)
{
    (void)state;
    struct {
        const char *what, *msg;
        ag_extrude_budget b;
        ag_status st;
    } cases[] = {
        {"events", "event budget (500 events)", {.max_events = 500}, AG_ERR_TOO_LARGE},
        {"time", "time budget", {.max_seconds = 0.05}, AG_ERR_TOO_LARGE},
        {"memory", "memory budget", {.max_bytes = 1 << 20}, AG_ERR_TOO_LARGE},
        {"cancel", "cancelled", {.cancelled = cancel_after}, AG_ERR_CANCELLED},
    };
    int limit = 3;
    cases[3].b.user = &limit;
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        ag_plan *p = huge_plan();
        ag_mesh *m = ag_mesh_create();
        ag_extrude_options o = {.budget = cases[i].b};
        ag_extrude_result r;
        ag_error err = {0};
        polls = 0;
        ag_status st = ag_extrude_plan_with(p, &o, m, -1, &r, NULL, &err);
        if (st != cases[i].st || !strstr(err.text, cases[i].msg))
            fail_msg("%s: status %d, '%s'", cases[i].what, (int)st, err.text);
        /* nothing half-made is added */
        assert_int_equal(m->ntris, 0);
        assert_int_equal(m->ncomponents, 0);
        assert_non_null(strstr(err.text, "at height"));
        if (cases[i].b.cancelled)
            assert_int_equal(polls, limit + 1); /* stopped at the first poll that said so */
        printf("budget %-6s: %s\n", cases[i].what, err.text);
        ag_mesh_free(m);
        ag_plan_free(p);
    }
}

/* In a batch a building that runs out of its budget is not lost: it falls back, and the
 * report says which building, why, and what was built instead. */
static void test_batch_budget_falls_back(void **state)
{
    (void)state;
    const char *doc =
        "{\"type\": \"FeatureCollection\", \"features\": ["
        " {\"type\": \"Feature\", \"id\": \"small\", \"properties\": {\"height\": 5},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[12,0],[12,7],[0,7],[0,0]]]}},"
        " {\"type\": \"Feature\", \"id\": \"comb\", \"properties\": {\"height\": 5},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[100,0],[140,0],[140,3],"
        "   [137,3],[137,9],[134,9],[134,3],[131,3],[131,9],[128,9],[128,3],[125,3],[125,9],"
        "   [122,9],[122,3],[119,3],[119,9],[116,9],[116,3],[113,3],[113,9],[110,9],[110,3],"
        "   [107,3],[107,9],[104,9],[104,3],[100,3],[100,0]]]}}]}";
    ag_footprints *f = NULL;
    ag_error err = {0};
    assert_int_equal(ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err), AG_OK);
    ag_style s;
    ag_style_builtin("hip", &s, NULL);
    /* enough for a rectangle's hip roof and for flat roofs, not for the comb's hip roof */
    ag_extrude_options o = {.budget = {.max_events = 100}};
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    assert_int_equal(ag_footprints_extrude_with(f, &s, &o, m, &r, &err), AG_OK);
    assert_int_equal(r.footprints, 2);
    assert_int_equal(r.succeeded, 1);
    assert_int_equal(r.nfailed, 0);
    assert_int_equal(r.nfallbacks, 1);
    assert_string_equal(r.fallbacks[0].id, "comb");
    assert_non_null(strstr(r.fallbacks[0].reason, "event budget"));
    assert_true(r.fallbacks[0].built == AG_BUILT_FLAT || r.fallbacks[0].built == AG_BUILT_BLOCK);
    assert_int_equal(m->ncomponents, 2);
    for (long c = 0; c < 2; c++) {
        char why[200];
        if (!xc_closed_manifold(m, c, 1e-6, why, sizeof why))
            fail_msg("building %ld: %s", c, why);
    }
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

/* A building description through ag_building_extrude_plan: a good plan is built as
 * described; one over its budget falls back to a flat roof at its wall height (checked on
 * its triangles: closed 2-manifold, inside the footprint, as high as the eaves); one that
 * validation refuses builds nothing and says why. */
static void test_plan_falls_back(void **state)
{
    (void)state;
    static const double comb[] = {0, 0, 40, 0, 40, 3, 37, 3, 37, 9, 34, 9, 34, 3, 31, 3, 31, 9,
                                  28, 9, 28, 3, 25, 3, 25, 9, 22, 9, 22, 3, 19, 3, 19, 9, 16, 9,
                                  16, 3, 13, 3, 13, 9, 10, 9, 10, 3, 7, 3, 7, 9, 4, 9, 4, 3, 0, 3};
    const size_t n = sizeof comb / sizeof *comb / 2;
    const ag_profile_point hip[] = {{0, 0}, {0, 4.5}, {1, 5.5}};
    for (int budget = 0; budget < 2; budget++) {
        ag_plan *p = ag_plan_create();
        assert_int_equal(ag_plan_add_profile(p, "hip", hip, 3, "roof", NULL, NULL), AG_OK);
        assert_int_equal(ag_plan_add_loop(p, comb, n, NULL, NULL), AG_OK);
        ag_extrude_options o = {.budget = {.max_events = budget ? 100 : 0}};
        ag_mesh *m = ag_mesh_create();
        ag_building_result r;
        ag_error err = {0};
        assert_int_equal(ag_building_extrude_plan(p, &o, m, -1, &r, &err), AG_OK);
        char why[200];
        if (!xc_closed_manifold(m, -1, 1e-6, why, sizeof why))
            fail_msg("budget %d: %s", budget, why);
        const double *loops[] = {comb};
        assert_true(xc_outside(m, -1, loops, &n, 1, 0) < 1e-6);
        if (budget) {
            assert_int_equal(r.built, AG_BUILT_FLAT);
            assert_non_null(strstr(r.reason, "event budget"));
            assert_true(fabs(xc_top(m, -1) - 4.5) < 1e-9); /* the eaves */
        } else {
            assert_int_equal(r.built, AG_BUILT_STYLED);
            assert_string_equal(r.reason, "");
            assert_true(xc_top(m, -1) > 5);
        }
        assert_int_equal(r.triangles, m->ntris);
        ag_mesh_free(m);
        ag_plan_free(p);
    }
    /* a bow tie: refused, nothing built */
    static const double bow[] = {0, 0, 10, 10, 10, 0, 0, 10};
    ag_plan *p = ag_plan_create();
    assert_int_equal(ag_plan_add_profile(p, "hip", hip, 3, NULL, NULL, NULL), AG_OK);
    assert_int_equal(ag_plan_add_loop(p, bow, 4, NULL, NULL), AG_OK);
    ag_mesh *m = ag_mesh_create();
    ag_building_result r;
    assert_int_equal(ag_building_extrude_plan(p, NULL, m, -1, &r, NULL), AG_OK);
    assert_int_equal(r.built, AG_BUILT_NONE);
    assert_non_null(strstr(r.reason, "cross"));
    assert_int_equal(m->ntris, 0);
    ag_mesh_free(m);
    ag_plan_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_jitter_matrix),
        cmocka_unit_test(test_jitter_against_cgal),
        cmocka_unit_test(test_denhaag_every_style),
        cmocka_unit_test(test_denhaag_against_cgal),
        cmocka_unit_test(test_large_footprints),
        cmocka_unit_test(test_thin_spikes),
        cmocka_unit_test(test_budgets),
        cmocka_unit_test(test_batch_budget_falls_back),
        cmocka_unit_test(test_plan_falls_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
