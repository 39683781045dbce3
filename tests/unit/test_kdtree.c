/* The kd-tree against brute force: uniform, clustered, duplicated, collinear and planar
 * point sets, k from 1 to beyond the set, radius queries, the hinted kNN. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/kdtree.h"
#include "core/points/rng.h"

typedef enum { UNIFORM, CLUSTERED, DUPLICATES, COLLINEAR, PLANAR, UTM } kind;

static double *make_points(kind k, size_t n, uint64_t seed)
{
    ag_rng r;
    ag_rng_seed(&r, seed);
    double *p = calloc(3 * (n ? n : 1), sizeof *p);
    for (size_t i = 0; i < n; i++) {
        double *q = p + 3 * i;
        switch (k) {
        case UNIFORM:
            for (int a = 0; a < 3; a++)
                q[a] = ag_rng_unit(&r) * 10 - 5;
            break;
        case CLUSTERED: {
            size_t c = ag_rng_below(&r, 5);
            for (int a = 0; a < 3; a++)
                q[a] = (double)c * 3 + ag_rng_gauss(&r) * 0.05;
            break;
        }
        case DUPLICATES:
            for (int a = 0; a < 3; a++)
                q[a] = (double)ag_rng_below(&r, 4); /* 64 distinct spots */
            break;
        case COLLINEAR: {
            double t = ag_rng_unit(&r) * 20;
            q[0] = t;
            q[1] = 2 * t;
            q[2] = -t;
            break;
        }
        case PLANAR:
            q[0] = ag_rng_unit(&r) * 30;
            q[1] = ag_rng_unit(&r) * 10;
            q[2] = 4;
            break;
        case UTM:
            q[0] = 500000 + ag_rng_unit(&r) * 50;
            q[1] = 5700000 + ag_rng_unit(&r) * 50;
            q[2] = ag_rng_unit(&r) * 20;
            break;
        }
    }
    return p;
}

static double dist2(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The kNN distances must be the k smallest brute-force distances (ties make the ids
 * ambiguous, the distances not), ascending, and the ids must be distinct and at those
 * distances. */
static void check_knn(const double *p, size_t n, const ag_kdtree *t, const double *q, size_t k,
                      const uint32_t *ids, const double *d2, size_t m)
{
    size_t want = k < n ? k : n;
    assert_int_equal(m, want);
    double *all = malloc((n ? n : 1) * sizeof *all);
    for (size_t i = 0; i < n; i++)
        all[i] = dist2(p + 3 * i, q);
    qsort(all, n, sizeof *all, cmp_double);
    for (size_t j = 0; j < m; j++) {
        assert_true(fabs(d2[j] - all[j]) <= 1e-9 * (1 + all[j]));
        assert_true(fabs(dist2(p + 3 * (size_t)ids[j], q) - d2[j]) <= 1e-9 * (1 + d2[j]));
        if (j)
            assert_true(d2[j] >= d2[j - 1]);
        for (size_t i = 0; i < j; i++)
            assert_true(ids[i] != ids[j]);
    }
    (void)t;
    free(all);
}

typedef struct {
    uint32_t *ids;
    size_t n;
} collect;

static int gather(void *user, uint32_t id, double d2)
{
    (void)d2;
    collect *c = user;
    c->ids[c->n++] = id;
    return 0;
}

static int stop_at_three(void *user, uint32_t id, double d2)
{
    (void)id;
    (void)d2;
    return ++*(int *)user == 3 ? 7 : 0;
}

typedef struct {
    const double *p;
    size_t n;
    const ag_kdtree *t;
    size_t seen;
} each_check;

static int each_cb(void *user, uint32_t id, const uint32_t *ids, const double *d2,
                   const double *const *pos, size_t m)
{
    each_check *ec = user;
    if (ec->seen++ % 53 == 0)
        check_knn(ec->p, ec->n, ec->t, ec->p + 3 * (size_t)id, 16, ids, d2, m);
    for (size_t j = 0; j < m; j++)
        assert_memory_equal(pos[j], ec->p + 3 * (size_t)ids[j], 3 * sizeof(double));
    return 0;
}

static void run_kind(kind kd, size_t n)
{
    double *p = make_points(kd, n, 1000 + kd);
    ag_kdtree *t;
    ag_error e;
    assert_int_equal(ag_kdtree_build(p, NULL, n, &t, &e), AG_OK);
    assert_int_equal(ag_kdtree_size(t), n);
    /* tree order is a permutation */
    uint8_t *seen = calloc(n + 1, 1);
    for (size_t i = 0; i < n; i++) {
        uint32_t id = ag_kdtree_order(t)[i];
        assert_true(id < n && !seen[id]);
        seen[id] = 1;
    }
    free(seen);
    ag_rng r;
    ag_rng_seed(&r, 77);
    const size_t ks[] = {1, 2, 7, 16, 33, 64, 200};
    uint32_t ids[200], prev[200];
    double d2[200];
    for (int qi = 0; qi < 60; qi++) {
        double q[3];
        if (qi % 2 && n) {
            memcpy(q, p + 3 * ag_rng_below(&r, n), sizeof q); /* a tree point */
        } else {
            for (int a = 0; a < 3; a++)
                q[a] = (n ? p[a] : 0) + ag_rng_gauss(&r) * 3;
        }
        for (size_t ki = 0; ki < sizeof ks / sizeof ks[0]; ki++) {
            size_t m = ag_kdtree_knn(t, q, ks[ki], ids, d2);
            check_knn(p, n, t, q, ks[ki], ids, d2, m);
        }
        /* radius: exactly the points within r */
        double rad = kd == UTM ? 5 : 1.5;
        collect c = {malloc((n ? n : 1) * sizeof(uint32_t)), 0};
        assert_int_equal(ag_kdtree_radius(t, q, rad, gather, &c), 0);
        size_t want = 0;
        for (size_t i = 0; i < n; i++)
            want += dist2(p + 3 * i, q) <= rad * rad;
        assert_int_equal(c.n, want);
        for (size_t j = 0; j < c.n; j++)
            assert_true(dist2(p + 3 * (size_t)c.ids[j], q) <= rad * rad);
        free(c.ids);
    }
    /* the hinted search over all points in tree order equals the plain one */
    int have = 0;
    for (size_t i = 0; i < n; i++) {
        const double *q = p + 3 * (size_t)ag_kdtree_order(t)[i];
        size_t m = have ? ag_kdtree_knn_hint(t, q, 16, prev, p, ids, d2) : ag_kdtree_knn(t, q, 16, ids, d2);
        if (i % 97 == 0)
            check_knn(p, n, t, q, 16, ids, d2, m);
        have = m == 16;
        memcpy(prev, ids, m * sizeof *ids);
    }
    /* every point's neighbours at once: the same distances, positions that match the ids */
    each_check ec = {p, n, t, 0};
    assert_int_equal(ag_kdtree_knn_each(t, 16, each_cb, &ec), 0);
    assert_int_equal(ec.seen, n);
    /* a visitor can stop the query */
    if (n >= 3) {
        int count = 0;
        double far = 1e9;
        assert_int_equal(ag_kdtree_radius(t, p, far, stop_at_three, &count), 7);
        assert_int_equal(count, 3);
    }
    ag_kdtree_free(t);
    free(p);
}

static void test_against_brute_force(void **state)
{
    (void)state;
    const kind kinds[] = {UNIFORM, CLUSTERED, DUPLICATES, COLLINEAR, PLANAR, UTM};
    const size_t sizes[] = {0, 1, 2, 9, 100, 3000};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
        for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
            run_kind(kinds[k], sizes[s]);
}

static void test_subset(void **state)
{
    (void)state;
    double *p = make_points(UNIFORM, 500, 5);
    uint32_t sub[250];
    for (int i = 0; i < 250; i++)
        sub[i] = (uint32_t)(2 * i + 1); /* odd points only */
    ag_kdtree *t;
    assert_int_equal(ag_kdtree_build(p, sub, 250, &t, NULL), AG_OK);
    uint32_t ids[10];
    double d2[10];
    size_t m = ag_kdtree_knn(t, p, 10, ids, d2);
    assert_int_equal(m, 10);
    for (size_t j = 0; j < m; j++)
        assert_true(ids[j] % 2 == 1);
    /* the nearest odd point by brute force */
    double best = INFINITY;
    for (int i = 0; i < 250; i++)
        if (dist2(p + 3 * sub[i], p) < best)
            best = dist2(p + 3 * sub[i], p);
    assert_true(fabs(d2[0] - best) < 1e-12);
    ag_kdtree_free(t);
    free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_against_brute_force),
        cmocka_unit_test(test_subset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
