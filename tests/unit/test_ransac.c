/* RANSAC planes: the global pass finds known planes with the right equations (turned, far
 * from the origin, noisy), the normal test keeps perpendicular neighbours out, the adaptive
 * threshold separates a clean plane from a parallel one close by, the local pass finds a
 * small ledge, lines are no planes. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/kdtree.h"
#include "core/points/normals.h"
#include "core/points/ransac.h"
#include "core/points/rng.h"

/* Points on rectangles given by corner, two edges; id per rectangle in `truth`. */
typedef struct {
    double o[3], u[3], v[3];
    size_t n;
} rect;

static ag_cloud *make(const rect *rs, size_t nr, double noise, int32_t **truth, uint64_t seed)
{
    size_t n = 0;
    for (size_t k = 0; k < nr; k++)
        n += rs[k].n;
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    *truth = malloc(n * sizeof **truth);
    ag_rng r;
    ag_rng_seed(&r, seed);
    size_t at = 0;
    for (size_t k = 0; k < nr; k++) {
        const rect *q = &rs[k];
        double nv[3] = {q->u[1] * q->v[2] - q->u[2] * q->v[1], q->u[2] * q->v[0] - q->u[0] * q->v[2],
                        q->u[0] * q->v[1] - q->u[1] * q->v[0]};
        double l = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        for (size_t i = 0; i < q->n; i++, at++) {
            double s = ag_rng_unit(&r), t = ag_rng_unit(&r), e = noise * ag_rng_gauss(&r);
            for (int a = 0; a < 3; a++)
                c->xyz[3 * at + a] = q->o[a] + s * q->u[a] + t * q->v[a] + e * nv[a] / l;
            (*truth)[at] = (int32_t)k;
        }
    }
    return c;
}

static void add_normals(ag_cloud *c, uint32_t **graph, float **var)
{
    ag_kdtree *t;
    assert_int_equal(ag_kdtree_build(c->xyz, NULL, c->n, &t, NULL), AG_OK);
    *graph = malloc(c->n * 16 * sizeof **graph);
    *var = malloc(c->n * sizeof **var);
    assert_int_equal(ag_normals_compute(c, t, NULL, *var, *graph, NULL, NULL), AG_OK);
    ag_kdtree_free(t);
}

/* Share of rectangle k's points in the plane that holds most of them, and that plane's
 * share of points from k. */
static void overlap(const int32_t *truth, const int32_t *plane_of, size_t n, int32_t k, size_t nplanes,
                    double *cover, double *purity, int32_t *which)
{
    size_t *cnt = calloc(nplanes + 1, sizeof *cnt), *tot = calloc(nplanes + 1, sizeof *tot), tk = 0;
    for (size_t i = 0; i < n; i++) {
        if (plane_of[i] >= 0)
            tot[plane_of[i]]++;
        if (truth[i] == k) {
            tk++;
            if (plane_of[i] >= 0)
                cnt[plane_of[i]]++;
        }
    }
    size_t best = 0;
    *which = -1;
    for (size_t p = 0; p < nplanes; p++)
        if (cnt[p] > best) {
            best = cnt[p];
            *which = (int32_t)p;
        }
    *cover = tk ? (double)best / tk : 0;
    *purity = best ? (double)best / tot[*which] : 0;
    free(cnt);
    free(tot);
}

static void test_global_known_planes(void **state)
{
    (void)state;
    for (int variant = 0; variant < 4; variant++) {
        double far = variant & 1 ? 4e5 : 0, turn = variant & 2 ? 0.6 : 0, ct = cos(turn), st = sin(turn);
        /* a floor, a wall and a tilted roof */
        rect rs[3] = {{{far, far, 0}, {20 * ct, 20 * st, 0}, {-10 * st, 10 * ct, 0}, 6000},
                      {{far, far, 0}, {20 * ct, 20 * st, 0}, {0, 0, 8}, 4000},
                      {{far - 10 * st, far + 10 * ct, 6}, {20 * ct, 20 * st, 0}, {6 * st, -6 * ct, 4}, 3000}};
        int32_t *truth;
        ag_cloud *c = make(rs, 3, 0.01, &truth, 40 + (uint64_t)variant);
        uint32_t *g;
        float *var;
        add_normals(c, &g, &var);
        int32_t *plane_of = malloc(c->n * sizeof *plane_of);
        uint32_t *idx = malloc(c->n * sizeof *idx);
        for (size_t i = 0; i < c->n; i++) {
            plane_of[i] = -1;
            idx[i] = (uint32_t)i;
        }
        ag_plane_list pl = {0};
        ag_ransac_options o = {.threshold = 0.05, .max_angle = 20, .min_points = 200, .seed = 9, .adaptive = 1};
        assert_int_equal(ag_ransac_global(c, idx, c->n, NULL, 0, &o, plane_of, &pl, NULL), AG_OK);
        assert_true(pl.n >= 3);
        for (int k = 0; k < 3; k++) {
            double cover, purity;
            int32_t which;
            overlap(truth, plane_of, c->n, k, pl.n, &cover, &purity, &which);
            assert_true(cover > 0.9 && purity > 0.97);
            /* the equation: its normal is the rectangle's, the points lie on it */
            const rect *q = &rs[k];
            double nv[3] = {q->u[1] * q->v[2] - q->u[2] * q->v[1], q->u[2] * q->v[0] - q->u[0] * q->v[2],
                            q->u[0] * q->v[1] - q->u[1] * q->v[0]};
            double l = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
            const ag_plane *p = &pl.items[which];
            double d = fabs(p->n[0] * nv[0] + p->n[1] * nv[1] + p->n[2] * nv[2]) / l;
            assert_true(d > cos(0.5 * M_PI / 180));
            double centre[3];
            for (int a = 0; a < 3; a++)
                centre[a] = q->o[a] + 0.5 * q->u[a] + 0.5 * q->v[a];
            assert_true(fabs(p->n[0] * centre[0] + p->n[1] * centre[1] + p->n[2] * centre[2] + p->d) < 0.01);
        }
        ag_plane_list_free(&pl);
        free(plane_of);
        free(idx);
        free(g);
        free(var);
        free(truth);
        ag_cloud_free(c);
    }
}

static void test_adaptive_and_local(void **state)
{
    (void)state;
    /* a clean wall, a parallel panel 8 cm in front of it (inside the 10 cm threshold), a
     * ledge of 40 points standing out perpendicular */
    rect rs[3] = {{{0, 0, 0}, {10, 0, 0}, {0, 0, 6}, 12000},
                  {{3, -0.08, 2}, {2, 0, 0}, {0, 0, 1.5}, 700},
                  {{6, -0.5, 3}, {0.8, 0, 0}, {0, 0.5, 0}, 40}};
    int32_t *truth;
    ag_cloud *c = make(rs, 3, 0.002, &truth, 3);
    /* the panel hides part of the wall: drop the wall points behind it, as a scan would */
    size_t w = 0;
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        if (truth[i] == 0 && p[0] > 3 && p[0] < 5 && p[2] > 2 && p[2] < 3.5)
            continue;
        memmove(c->xyz + 3 * w, p, 3 * sizeof *p);
        truth[w++] = truth[i];
    }
    assert_int_equal(ag_cloud_resize(c, w, NULL), AG_OK);
    uint32_t *g;
    float *var;
    add_normals(c, &g, &var);
    int32_t *plane_of = malloc(c->n * sizeof *plane_of);
    uint32_t *idx = malloc(c->n * sizeof *idx);
    for (size_t i = 0; i < c->n; i++) {
        plane_of[i] = -1;
        idx[i] = (uint32_t)i;
    }
    ag_plane_list pl = {0};
    ag_ransac_options o = {.threshold = 0.1, .max_angle = 20, .min_points = 300, .seed = 4, .adaptive = 1};
    assert_int_equal(ag_ransac_global(c, idx, c->n, NULL, 0, &o, plane_of, &pl, NULL), AG_OK);
    double cover, purity;
    int32_t w0, w1;
    overlap(truth, plane_of, c->n, 0, pl.n, &cover, &purity, &w0);
    assert_true(cover > 0.95 && purity > 0.97);
    overlap(truth, plane_of, c->n, 1, pl.n, &cover, &purity, &w1);
    assert_true(cover > 0.8 && purity > 0.9);
    assert_true(w0 != w1);
    /* without the adaptive threshold the panel goes into the wall */
    for (size_t i = 0; i < c->n; i++)
        plane_of[i] = -1;
    ag_plane_list plain = {0};
    o.adaptive = 0;
    assert_int_equal(ag_ransac_global(c, idx, c->n, NULL, 0, &o, plane_of, &plain, NULL), AG_OK);
    overlap(truth, plane_of, c->n, 1, plain.n, &cover, &purity, &w1);
    overlap(truth, plane_of, c->n, 0, plain.n, &cover, &purity, &w0);
    assert_int_equal(w0, w1);
    ag_plane_list_free(&plain);
    /* the ledge: too small for the global pass, found by the local pass */
    for (size_t i = 0; i < c->n; i++)
        plane_of[i] = -1;
    pl.n = 0;
    o.adaptive = 1;
    assert_int_equal(ag_ransac_global(c, idx, c->n, NULL, 0, &o, plane_of, &pl, NULL), AG_OK);
    size_t before = pl.n;
    size_t m = 0;
    for (size_t i = 0; i < c->n; i++)
        if (plane_of[i] < 0)
            idx[m++] = (uint32_t)i;
    ag_ransac_graph graph = {g, 16};
    ag_ransac_options lo = {.threshold = 0.1, .max_angle = 20, .min_points = 15, .radius = 0.5, .adaptive = 1};
    assert_int_equal(ag_ransac_local(c, &graph, var, idx, m, NULL, 0, &lo, plane_of, &pl, NULL), AG_OK);
    assert_true(pl.n > before);
    overlap(truth, plane_of, c->n, 2, pl.n, &cover, &purity, &w1);
    assert_true(cover > 0.7 && purity > 0.9);
    assert_true(fabs(pl.items[w1].n[2]) > 0.99); /* horizontal */
    ag_plane_list_free(&pl);
    free(plane_of);
    free(idx);
    free(g);
    free(var);
    free(truth);
    ag_cloud_free(c);
}

static void test_lines_are_no_planes(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, 400, NULL), AG_OK);
    for (size_t i = 0; i < 400; i++) {
        c->xyz[3 * i] = i * 0.05;
        c->xyz[3 * i + 1] = -i * 0.02;
        c->xyz[3 * i + 2] = 1;
    }
    uint32_t *g;
    float *var;
    add_normals(c, &g, &var);
    int32_t plane_of[400];
    uint32_t idx[400];
    for (size_t i = 0; i < 400; i++) {
        plane_of[i] = -1;
        idx[i] = (uint32_t)i;
    }
    ag_plane_list pl = {0};
    ag_ransac_options o = {.threshold = 0.05, .max_angle = 20, .min_points = 20, .radius = 1};
    assert_int_equal(ag_ransac_global(c, idx, 400, NULL, 0, &o, plane_of, &pl, NULL), AG_OK);
    ag_ransac_graph graph = {g, 16};
    assert_int_equal(ag_ransac_local(c, &graph, var, idx, 400, NULL, 0, &o, plane_of, &pl, NULL), AG_OK);
    assert_int_equal(pl.n, 0);
    ag_error e;
    o.threshold = 0;
    assert_int_equal(ag_ransac_global(c, idx, 400, NULL, 0, &o, plane_of, &pl, &e), AG_ERR_INVALID);
    ag_plane_list_free(&pl);
    free(g);
    free(var);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_global_known_planes),
        cmocka_unit_test(test_adaptive_and_local),
        cmocka_unit_test(test_lines_are_no_planes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
