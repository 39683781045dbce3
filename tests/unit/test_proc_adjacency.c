/* Adjacency of the split tree's visible boxes (ag_splittree_adjacency) against a brute-force
 * check of every pair, in the listed order (the sweep order by lower x): boxes of sizes
 * spread over five orders of magnitude, thin plates (no extent on one axis), a facade of
 * touching panels all sharing one x range, rows of buildings, UTM-sized offsets, copies
 * of one box, and gaps just inside and just outside the tolerance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/base/box.h"
#include "core/proc/splittree.h"
#include "random_fixture.h"

typedef struct {
    double x;
    uint32_t n;
} xn;

static int cmp_xn(const void *a, const void *b)
{
    const xn *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return p->n < q->n ? -1 : p->n > q->n;
}

static int meets(const ag_box *a, const ag_box *b, double tol)
{
    for (int k = 0; k < 3; k++)
        if (a->min[k] > b->max[k] + tol || b->min[k] > a->max[k] + tol)
            return 0;
    return 1;
}

/* every meeting pair, ordered by the sweep positions of its two boxes */
static void check(ag_splittree *t)
{
    size_t nv = 0;
    xn *s = malloc((t->nnodes + 1) * sizeof *s);
    assert_non_null(s);
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT) {
            s[nv].x = t->nodes[i].box.min[0];
            s[nv++].n = (uint32_t)i;
        }
    qsort(s, nv, sizeof *s, cmp_xn);
    assert_int_equal(ag_splittree_adjacency(t), AG_OK);
    size_t k = 0;
    for (size_t i = 0; i < nv; i++)
        for (size_t j = i + 1; j < nv; j++) {
            if (!meets(&t->nodes[s[i].n].box, &t->nodes[s[j].n].box, t->tol))
                continue;
            uint32_t x = s[i].n < s[j].n ? s[i].n : s[j].n, y = s[i].n ^ s[j].n ^ x;
            if (k >= t->nadj)
                fail_msg("pair %u %u missing (only %zu listed)", x, y, t->nadj);
            if (t->adj[2 * k] != x || t->adj[2 * k + 1] != y)
                fail_msg("pair %zu: %u %u listed, %u %u expected", k, t->adj[2 * k],
                         t->adj[2 * k + 1], x, y);
            k++;
        }
    assert_int_equal(k, t->nadj);
    free(s);
}

static ag_splittree *tree(double tol)
{
    ag_splittree *t = calloc(1, sizeof *t);
    assert_non_null(t);
    t->tol = tol;
    assert_true(ag_splittree_add_node(t, AG_NODE_ROOT) == 0);
    return t;
}

static void add_box(ag_splittree *t, const double lo[3], const double hi[3])
{
    int32_t k = ag_splittree_add_node(t, AG_NODE_COMPONENT);
    assert_true(k >= 0);
    for (int a = 0; a < 3; a++) {
        t->nodes[k].box.min[a] = lo[a];
        t->nodes[k].box.max[a] = hi[a];
    }
}

static void test_random_sizes_and_offsets(void **state)
{
    (void)state;
    uint64_t s = 17;
    const double offsets[][3] = {{0, 0, 0}, {691234.5, 5401234.25, 312.0}, {-50, 7, -3}};
    for (int trial = 0; trial < 12; trial++) {
        const double *o = offsets[trial % 3];
        double tol = trial % 4 == 0 ? 0 : 1e-3 * (trial % 4);
        ag_splittree *t = tree(tol);
        size_t n = 300 + 150 * (size_t)trial;
        for (size_t i = 0; i < n; i++) {
            double lo[3], hi[3];
            for (int a = 0; a < 3; a++) {
                double e = pow(10, uniform(&s, -3, 2)); /* 1 mm .. 100 m */
                if (next_random(&s) % 7 == 0)
                    e = 0; /* a plate */
                lo[a] = o[a] + uniform(&s, 0, 60);
                hi[a] = lo[a] + e;
            }
            add_box(t, lo, hi);
            if (i % 50 == 0)
                add_box(t, lo, hi); /* a copy */
        }
        check(t);
        ag_splittree_free(t);
    }
}

static void test_facade_panels_and_rows(void **state)
{
    (void)state;
    for (int variant = 0; variant < 4; variant++) {
        double tol = variant < 2 ? 1e-6 : 0.01;
        double ox = variant % 2 ? 691234.5 : 0, oy = variant % 2 ? 5401234.25 : 0;
        ag_splittree *t = tree(tol);
        /* rows of buildings: each a facade facing x of touching panels (one x range), gaps
         * between panels alternately just inside and just outside the tolerance */
        for (int b = 0; b < 6; b++)
            for (int i = 0; i < 20; i++)
                for (int j = 0; j < 10; j++) {
                    double gap = (i + j) % 2 ? 0.9 * tol : 1.1 * tol + 1e-9;
                    double lo[3] = {ox + 30.0 * (b % 3), oy + 40.0 * (b / 3) + i * (1.0 + gap),
                                    j * (1.0 + gap)};
                    double hi[3] = {lo[0] + 0.2, lo[1] + 1.0, lo[2] + 1.0};
                    add_box(t, lo, hi);
                }
        /* a wall behind each facade, and a ground plate under all */
        for (int b = 0; b < 6; b++) {
            double lo[3] = {ox + 30.0 * (b % 3) + 0.2, oy + 40.0 * (b / 3), 0};
            double hi[3] = {lo[0] + 0.3, lo[1] + 25, 12};
            add_box(t, lo, hi);
        }
        double glo[3] = {ox - 5, oy - 5, 0}, ghi[3] = {ox + 100, oy + 100, 0};
        add_box(t, glo, ghi);
        check(t);
        ag_splittree_free(t);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_sizes_and_offsets),
        cmocka_unit_test(test_facade_panels_and_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
