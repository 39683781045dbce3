/* The level-of-detail order of a point cloud (core/points/lod.h): a permutation, the same for
 * a seed, whose prefixes are even subsamples — checked against cells counted here, from the
 * documented hierarchy (the bounding cube, 2^L cells per axis), not against the code's own
 * levels: the first m points, m the number of occupied cells of a level, hold one point of
 * each. Clouds: a dense block next to a sparse one, turned, at UTM coordinates (raw and as an
 * offset), duplicates, one point, none. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/points/lod.h"
#include "random_fixture.h"

/* 90 % of the points in a 1 m block, 10 % spread over a 20 m one beside it. */
static ag_cloud *two_densities(size_t n, double turn_deg, const double origin[3], int raw,
                               uint64_t seed)
{
    ag_cloud *c = ag_cloud_create();
    assert_non_null(c);
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    double a = turn_deg * M_PI / 180, ca = cos(a), sa = sin(a);
    for (size_t i = 0; i < n; i++) {
        double p[3];
        if (i % 10) {
            p[0] = uniform(&seed, 0, 1);
            p[1] = uniform(&seed, 0, 1);
            p[2] = uniform(&seed, 0, 1);
        } else {
            p[0] = uniform(&seed, 2, 22);
            p[1] = uniform(&seed, 0, 20);
            p[2] = uniform(&seed, 0, 5);
        }
        double q[3] = {ca * p[0] - sa * p[1], sa * p[0] + ca * p[1], p[2]};
        for (int k = 0; k < 3; k++)
            c->xyz[3 * i + k] = q[k] + (raw ? origin[k] : 0);
    }
    if (!raw)
        memcpy(c->offset, origin, sizeof c->offset);
    return c;
}

static void assert_permutation(const uint32_t *order, size_t n)
{
    unsigned char *seen = calloc(n + 1, 1);
    for (size_t i = 0; i < n; i++) {
        assert_true(order[i] < n);
        assert_false(seen[order[i]]);
        seen[order[i]] = 1;
    }
    free(seen);
}

/* The occupied cells of level L (the bounding cube in 2^L cells per axis), and how many of
 * them the first m points of order touch. */
static void cells_of_prefix(const ag_cloud *c, const uint32_t *order, int L, size_t *occupied,
                            size_t *touched, size_t m)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < c->n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], c->xyz[3 * i + k]);
            hi[k] = fmax(hi[k], c->xyz[3 * i + k]);
        }
    double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    size_t side = (size_t)1 << L, cells = side * side * side;
    unsigned char *occ = calloc(cells, 1), *hit = calloc(cells, 1);
    assert_true(occ && hit);
    size_t *cell = malloc(c->n * sizeof *cell);
    for (size_t i = 0; i < c->n; i++) {
        size_t q[3];
        for (int k = 0; k < 3; k++) {
            double v = floor((c->xyz[3 * i + k] - lo[k]) / size * (double)side);
            q[k] = v < 0 ? 0 : v >= (double)side ? side - 1 : (size_t)v;
        }
        cell[i] = (q[2] * side + q[1]) * side + q[0];
        occ[cell[i]] = 1;
    }
    *occupied = *touched = 0;
    for (size_t x = 0; x < cells; x++)
        *occupied += occ[x];
    for (size_t i = 0; i < m; i++)
        if (!hit[cell[order[i]]]) {
            hit[cell[order[i]]] = 1;
            ++*touched;
        }
    free(cell);
    free(occ);
    free(hit);
}

static void prefixes_cover_every_cell_of_their_level(void **state)
{
    (void)state;
    const double utm[3] = {486512.25, 5719877.75, 47.5}, zero[3] = {0, 0, 0};
    const struct {
        double turn;
        const double *origin;
        int raw;
    } v[] = {{0, zero, 0}, {33, zero, 0}, {33, utm, 0}, {71, utm, 1}};
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        size_t n = 50000;
        ag_cloud *c = two_densities(n, v[k].turn, v[k].origin, v[k].raw, 11 + k);
        uint32_t *order = malloc(n * sizeof *order);
        assert_int_equal(ag_lod_order(c, 0, order, NULL), AG_OK);
        assert_permutation(order, n);
        for (int L = 1; L <= 6; L++) {
            size_t occupied, touched;
            cells_of_prefix(c, order, L, &occupied, &touched, n);
            size_t m = occupied;
            cells_of_prefix(c, order, L, &occupied, &touched, m);
            /* one point of each occupied cell, no cell twice */
            if (touched != occupied)
                fail_msg("variant %zu level %d: the first %zu points touch %zu of %zu cells", k, L,
                         m, touched, occupied);
        }
        /* the sparse block (a tenth of the points) gets far more than a tenth of a small
         * budget: a random subsample would thin it like the dense one */
        size_t m = n / 100, sparse = 0;
        for (size_t i = 0; i < m; i++)
            sparse += order[i] % 10 == 0;
        print_message("variant %zu: %zu of the first %zu points are of the sparse block\n", k,
                      sparse, m);
        assert_true(sparse * 2 > m);
        free(order);
        ag_cloud_free(c);
    }
}

static void the_same_seed_gives_the_same_order(void **state)
{
    (void)state;
    const double zero[3] = {0, 0, 0};
    size_t n = 20000;
    ag_cloud *c = two_densities(n, 10, zero, 0, 5);
    uint32_t *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *d = malloc(n * sizeof *d);
    assert_int_equal(ag_lod_order(c, 0, a, NULL), AG_OK);
    assert_int_equal(ag_lod_order(c, 0, b, NULL), AG_OK);
    assert_memory_equal(a, b, n * sizeof *a);
    assert_int_equal(ag_lod_order(c, 1234, d, NULL), AG_OK);
    assert_permutation(d, n);
    assert_memory_not_equal(a, d, n * sizeof *a);
    free(a);
    free(b);
    free(d);
    ag_cloud_free(c);
}

static void small_and_degenerate_clouds(void **state)
{
    (void)state;
    uint32_t order[64];
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_lod_order(c, 0, order, NULL), AG_OK); /* no points */
    assert_int_equal(ag_cloud_resize(c, 1, NULL), AG_OK);
    c->xyz[0] = 3;
    assert_int_equal(ag_lod_order(c, 0, order, NULL), AG_OK);
    assert_int_equal(order[0], 0);
    /* 40 copies of one point, then 24 of another: every point once, both spots early */
    assert_int_equal(ag_cloud_resize(c, 64, NULL), AG_OK);
    for (size_t i = 0; i < 64; i++)
        for (int k = 0; k < 3; k++)
            c->xyz[3 * i + k] = i < 40 ? 1.5 : -2;
    assert_int_equal(ag_lod_order(c, 0, order, NULL), AG_OK);
    assert_permutation(order, 64);
    assert_true((order[0] < 40) != (order[1] < 40));
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(prefixes_cover_every_cell_of_their_level),
        cmocka_unit_test(the_same_seed_gives_the_same_order),
        cmocka_unit_test(small_and_degenerate_clouds),
    };
    return cmocka_run_group_tests_name("lod", tests, NULL, NULL);
}
