/* kNN PCA normals: the 3x3 eigen solver against random symmetric matrices, normals on
 * planes, spheres and cylinders (noisy, rotated, far from the origin) against the analytic
 * ones, the building orientation convention, degenerate neighbourhoods. */
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
#include "core/points/rng.h"

static void test_eigen_solver(void **state)
{
    (void)state;
    ag_rng r;
    ag_rng_seed(&r, 11);
    for (int t = 0; t < 20000; t++) {
        /* A = Q diag(l) Q^T with a random rotation and spectrum (repeated values included) */
        double l[3] = {ag_rng_unit(&r), ag_rng_unit(&r) * 10, ag_rng_unit(&r) * 100};
        if (t % 5 == 0)
            l[1] = l[2];
        if (t % 7 == 0)
            l[0] = 0;
        double q[4] = {ag_rng_gauss(&r), ag_rng_gauss(&r), ag_rng_gauss(&r), ag_rng_gauss(&r)};
        double qn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int k = 0; k < 4; k++)
            q[k] /= qn;
        double w = q[0], x = q[1], y = q[2], z = q[3];
        double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        double A[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                A[i][j] = 0;
                for (int k = 0; k < 3; k++)
                    A[i][j] += R[i][k] * l[k] * R[j][k];
            }
        double a6[6] = {A[0][0], A[0][1], A[0][2], A[1][1], A[1][2], A[2][2]};
        double n[3], ev[3];
        ag_normals_smallest_eigenvector(a6, n, ev);
        double smallest = fmin(l[0], fmin(l[1], l[2]));
        assert_true(fabs(ev[0] - smallest) < 1e-6 * (1 + l[2]));
        /* A n = l0 n */
        for (int i = 0; i < 3; i++) {
            double an = A[i][0] * n[0] + A[i][1] * n[1] + A[i][2] * n[2];
            assert_true(fabs(an - ev[0] * n[i]) < 1e-6 * (1 + l[2]));
        }
        assert_true(fabs(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1) < 1e-9);
    }
    /* zero and isotropic matrices give a unit vector, not NaN */
    double zero[6] = {0, 0, 0, 0, 0, 0}, iso[6] = {2, 0, 0, 2, 0, 2}, n[3];
    ag_normals_smallest_eigenvector(zero, n, NULL);
    assert_true(n[2] == 1);
    ag_normals_smallest_eigenvector(iso, n, NULL);
    assert_true(fabs(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1) < 1e-12);
}

typedef enum { PLANE, SPHERE, CYLINDER } shape;

/* Points on a shape, with the exact normal of each. */
static ag_cloud *sample(shape s, size_t n, double noise, double far, double *truth, ag_rng *r)
{
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    double tilt = 0.4, ct = cos(tilt), st = sin(tilt);
    for (size_t i = 0; i < n; i++) {
        double p[3], nv[3];
        if (s == PLANE) {
            double u = ag_rng_unit(r) * 10, v = ag_rng_unit(r) * 10;
            /* the plane z = 0 turned about x by `tilt` */
            p[0] = u;
            p[1] = v * ct;
            p[2] = v * st;
            nv[0] = 0;
            nv[1] = -st;
            nv[2] = ct;
        } else if (s == SPHERE) {
            double a = ag_rng_unit(r) * 2 * M_PI, zc = ag_rng_unit(r) * 2 - 1, rr = sqrt(1 - zc * zc);
            nv[0] = rr * cos(a);
            nv[1] = rr * sin(a);
            nv[2] = zc;
            for (int k = 0; k < 3; k++)
                p[k] = 5 * nv[k];
        } else {
            double a = ag_rng_unit(r) * 2 * M_PI, h = ag_rng_unit(r) * 10;
            nv[0] = cos(a);
            nv[1] = sin(a);
            nv[2] = 0;
            p[0] = 3 * nv[0];
            p[1] = 3 * nv[1];
            p[2] = h;
        }
        double e = noise * ag_rng_gauss(r);
        for (int k = 0; k < 3; k++) {
            c->xyz[3 * i + k] = p[k] + e * nv[k] + (k < 2 ? far : 0);
            truth[3 * i + k] = nv[k];
        }
    }
    return c;
}

static void test_shapes(void **state)
{
    (void)state;
    ag_rng r;
    ag_rng_seed(&r, 5);
    const double fars[2] = {0, 5e5}; /* model coordinates, and UTM-sized ones */
    for (int s = 0; s < 3; s++)
        for (int f = 0; f < 2; f++) {
            size_t n = 20000;
            double *truth = malloc(3 * n * sizeof *truth);
            ag_cloud *c = sample((shape)s, n, 0.002, fars[f], truth, &r);
            ag_kdtree *t;
            assert_int_equal(ag_kdtree_build(c->xyz, NULL, n, &t, NULL), AG_OK);
            float *var = malloc(n * sizeof *var);
            uint32_t *nb = malloc(n * 16 * sizeof *nb);
            ag_normals_info info;
            assert_int_equal(ag_normals_compute(c, t, NULL, var, nb, &info, NULL), AG_OK);
            size_t good = 0;
            double var_sum = 0;
            for (size_t i = 0; i < n; i++) {
                const float *nv = c->normals + 3 * i;
                double d = fabs(nv[0] * truth[3 * i] + nv[1] * truth[3 * i + 1] + nv[2] * truth[3 * i + 2]);
                good += d > cos(5 * M_PI / 180);
                var_sum += var[i];
                /* the graph's first entry is the point itself (no duplicates here) */
                assert_int_equal(nb[16 * i], i);
            }
            assert_true(good > 0.97 * n);
            assert_true(var_sum / n < 0.02);
            /* spacing: about the mean distance between neighbours for the sampled area */
            double area = s == PLANE ? 100 : s == SPHERE ? 4 * M_PI * 25 : 2 * M_PI * 3 * 10;
            double expect = sqrt(area / n);
            assert_true(info.spacing > 0.2 * expect && info.spacing < 1.5 * expect);
            ag_kdtree_free(t);
            free(var);
            free(nb);
            free(truth);
            ag_cloud_free(c);
        }
}

static void test_orientation(void **state)
{
    (void)state;
    /* a box's faces: the roof normal points up, wall normals away from the centre */
    ag_cloud *c = ag_cloud_create();
    size_t n = 0;
    assert_int_equal(ag_cloud_resize(c, 2 * 2500, NULL), AG_OK);
    for (int i = 0; i < 50; i++)
        for (int j = 0; j < 50; j++) {
            double u = i * 0.2, v = j * 0.2;
            double *roof = c->xyz + 3 * n++;
            roof[0] = u;
            roof[1] = v;
            roof[2] = 10;
            double *wall = c->xyz + 3 * n++;
            wall[0] = u;
            wall[1] = 0;
            wall[2] = v;
        }
    ag_kdtree *t;
    assert_int_equal(ag_kdtree_build(c->xyz, NULL, n, &t, NULL), AG_OK);
    assert_int_equal(ag_normals_compute(c, t, NULL, NULL, NULL, NULL, NULL), AG_OK);
    size_t up = 0, out = 0;
    for (size_t i = 0; i < n; i++) {
        const double *p = c->xyz + 3 * i;
        const float *nv = c->normals + 3 * i;
        if (p[2] == 10 && p[0] > 1 && p[0] < 9 && p[1] > 1 && p[1] < 9)
            up += nv[2] > 0.99;
        if (p[1] == 0 && p[2] > 1 && p[2] < 9 && p[0] > 1 && p[0] < 9)
            out += nv[1] < -0.99;
    }
    assert_true(up > 1500);
    assert_true(out > 1500);
    ag_kdtree_free(t);
    ag_cloud_free(c);
}

static void test_degenerate(void **state)
{
    (void)state;
    /* collinear points, a pile of duplicates, two points: unit normals, no NaN */
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, 300, NULL), AG_OK);
    for (size_t i = 0; i < 300; i++) {
        double *p = c->xyz + 3 * i;
        if (i < 200) {
            p[0] = i * 0.1;
            p[1] = 2 * i * 0.1;
            p[2] = 3;
        } else {
            p[0] = p[1] = p[2] = 7;
        }
    }
    ag_kdtree *t;
    assert_int_equal(ag_kdtree_build(c->xyz, NULL, 300, &t, NULL), AG_OK);
    float var[300];
    ag_normals_info info;
    assert_int_equal(ag_normals_compute(c, t, NULL, var, NULL, &info, NULL), AG_OK);
    for (size_t i = 0; i < 300; i++) {
        const float *nv = c->normals + 3 * i;
        double l = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        assert_true(fabs(l - 1) < 1e-5);
        assert_true(var[i] >= 0 && var[i] <= 1.0 / 3 + 1e-6);
        if (i < 200 && i > 10 && i < 190) /* across the line */
            assert_true(fabs(nv[0] * 1 + nv[1] * 2) / sqrt(5) < 1e-3);
    }
    assert_true(info.spacing > 0.2 && info.spacing < 0.25); /* the line's step, not 0 */
    ag_kdtree_free(t);
    /* a tree of another cloud is refused */
    ag_kdtree *small;
    assert_int_equal(ag_kdtree_build(c->xyz, NULL, 10, &small, NULL), AG_OK);
    ag_error e;
    assert_int_equal(ag_normals_compute(c, small, NULL, NULL, NULL, NULL, &e), AG_ERR_INVALID);
    ag_kdtree_free(small);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eigen_solver),
        cmocka_unit_test(test_shapes),
        cmocka_unit_test(test_orientation),
        cmocka_unit_test(test_degenerate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
