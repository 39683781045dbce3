/* Adjacency of the split tree's visible boxes against a brute-force check of every pair, in
 * the listed order (by the smaller node index, then the larger): boxes of sizes spread over
 * five orders of magnitude, thin plates (no extent on one axis), a facade of touching panels
 * all sharing one x range, rows of buildings, UTM-sized offsets, copies of one box, and gaps
 * just inside and just outside the tolerance. Then the pairs brought up to date
 * (ag_splittree_adjacency_update) after random changes of nested trees (boxes moved, grown,
 * made to coincide, nodes added, killed, made visible or invisible, the tolerance changed):
 * checked against the brute force again and against the pairs found from scratch, and the
 * update must have searched (not started over) where few nodes changed. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/base/box.h"
#include "core/proc/adjacency.h"
#include "core/proc/splittree.h"
#include "adjacency_check.h"
#include "random_fixture.h"

static void check(ag_splittree *t)
{
    assert_int_equal(ag_splittree_adjacency(t), AG_OK);
    adjacency_check_brute_force(t, "adjacency");
}

static ag_splittree *tree(double tol)
{
    ag_splittree *t = calloc(1, sizeof *t);
    assert_non_null(t);
    t->tol = tol;
    assert_true(ag_splittree_add_node(t, AG_NODE_ROOT) == 0);
    return t;
}

static int32_t add_box(ag_splittree *t, const double lo[3], const double hi[3])
{
    int32_t k = ag_splittree_add_node(t, AG_NODE_COMPONENT);
    assert_true(k >= 0);
    for (int a = 0; a < 3; a++) {
        t->nodes[k].box.min[a] = lo[a];
        t->nodes[k].box.max[a] = hi[a];
    }
    return k;
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

/* A random box inside `in` (a share of it, or flat on one axis now and then). */
static ag_box box_inside(uint64_t *s, const ag_box *in)
{
    ag_box b;
    for (int a = 0; a < 3; a++) {
        double len = in->max[a] - in->min[a];
        double lo = in->min[a] + uniform(s, 0, 0.8) * len;
        double e = next_random(s) % 9 == 0 ? 0 : uniform(s, 0.05, 0.5) * len;
        b.min[a] = lo;
        b.max[a] = fmin(lo + e, in->max[a]);
    }
    return b;
}

/* A nested tree as proceduralization makes them: walls under the root, windows (some behind
 * an invisible split node) under walls, panes under windows; windows of a row touch. */
static ag_splittree *nested_tree(uint64_t *s, double tol, size_t nwalls)
{
    ag_splittree *t = tree(tol);
    for (int a = 0; a < 3; a++) {
        t->nodes[0].box.min[a] = 0;
        t->nodes[0].box.max[a] = 100;
    }
    for (size_t w = 0; w < nwalls; w++) {
        double lo[3] = {10.0 * (double)(w % 9), 10.0 * (double)(w / 9 % 9), 0};
        double hi[3] = {lo[0] + 10, lo[1] + 0.3 + (w % 3 ? 0 : tol * 0.5), 30};
        int32_t wall = add_box(t, lo, hi);
        ag_splittree_attach(t, 0, wall);
        for (int i = 0; i < 12; i++) {
            double wl[3] = {lo[0] + 0.8 * i, lo[1], 1 + (i % 4) * 6};
            double wh[3] = {wl[0] + 0.8, lo[1] + 0.3, wl[2] + 1.5};
            int32_t parent = wall;
            if (i % 3 == 0) {
                parent = ag_splittree_add_node(t, AG_NODE_SPLIT);
                assert_true(parent >= 0);
                t->nodes[parent].box = t->nodes[wall].box;
                ag_splittree_attach(t, wall, parent);
            }
            int32_t win = add_box(t, wl, wh);
            ag_splittree_attach(t, parent, win);
            for (int p = 0; p < 2; p++) {
                ag_box pb = box_inside(s, &t->nodes[win].box);
                int32_t pane = add_box(t, pb.min, pb.max);
                ag_splittree_attach(t, win, pane);
            }
        }
    }
    return t;
}

/* One random change of t; returns 1 when it changed a visible node's box or visibility. */
static int mutate(uint64_t *s, ag_splittree *t)
{
    size_t n = 1 + next_random(s) % (t->nnodes - 1);
    ag_tnode *x = &t->nodes[n];
    switch (next_random(s) % 8) {
    case 0: /* moved a little (within the tolerance of its old place, or past it) */
        for (int a = 0; a < 3; a++) {
            double d = (next_random(s) % 2 ? 0.5 : 3) * t->tol * (next_random(s) % 3 - 1.0);
            x->box.min[a] += d;
            x->box.max[a] += d;
        }
        return x->kind == AG_NODE_COMPONENT;
    case 1: /* resized: grown on one side */
        x->box.max[next_random(s) % 3] += uniform(s, 0, 2);
        return x->kind == AG_NODE_COMPONENT;
    case 2: { /* made to coincide with another node */
        size_t o = 1 + next_random(s) % (t->nnodes - 1);
        x->box = t->nodes[o].box;
        return x->kind == AG_NODE_COMPONENT;
    }
    case 3: /* killed, its subtree left where it was (detached from it) */
        if (x->kind == AG_NODE_COMPONENT) {
            x->kind = AG_NODE_DEAD;
            return 1;
        }
        return 0;
    case 4: /* made invisible (an intermediate node now) */
        if (x->kind == AG_NODE_COMPONENT) {
            x->kind = AG_NODE_SPLIT;
            return 1;
        }
        return 0;
    case 5: /* made visible */
        if (x->kind == AG_NODE_SPLIT) {
            x->kind = AG_NODE_COMPONENT;
            return 1;
        }
        return 0;
    case 6: { /* a copy appended under the same parent, shifted by a window */
        ag_box b = x->box;
        int32_t parent = x->parent; /* x moves when the nodes grow */
        b.min[0] += 0.8;
        b.max[0] += 0.8;
        int32_t k = add_box(t, b.min, b.max);
        if (parent >= 0)
            ag_splittree_attach(t, parent, k);
        return 1;
    }
    default: { /* moved far: to another wall's place */
        double dy = 10.0 * (double)(next_random(s) % 3);
        x->box.min[1] += dy;
        x->box.max[1] += dy;
        return x->kind == AG_NODE_COMPONENT && dy != 0;
    }
    }
}

static void test_update_after_random_changes(void **state)
{
    (void)state;
    uint64_t s = 4242;
    size_t searched = 0, rounds = 0;
    for (int trial = 0; trial < 24; trial++) {
        double tol = trial % 3 == 0 ? 0 : 1e-3 * (1 + trial % 3);
        ag_splittree *t = nested_tree(&s, tol, 20 + (size_t)trial % 5 * 10);
        check(t);
        for (int round = 0; round < 6; round++) {
            ag_splittree *c = ag_splittree_copy(t); /* an edit works on a copy */
            assert_non_null(c);
            ag_splittree_free(t);
            t = c;
            int changes = 1 + (int)(next_random(&s) % (round % 3 == 2 ? 40 : 6));
            for (int k = 0; k < changes; k++)
                mutate(&s, t);
            if (round == 4 && trial % 4 == 1)
                t->tol = t->tol > 0 ? 2 * t->tol : 1e-3; /* the model grew: its tolerance too */
            int scratch = -1;
            assert_int_equal(ag_splittree_adjacency_update(t, &scratch), AG_OK);
            adjacency_check_brute_force(t, "adjacency");
            /* the same pairs as from scratch, in the same order */
            ag_splittree *f = ag_splittree_copy(t);
            assert_non_null(f);
            assert_int_equal(ag_splittree_adjacency(f), AG_OK);
            assert_int_equal(f->nadj, t->nadj);
            assert_memory_equal(f->adj, t->adj, 2 * t->nadj * sizeof *t->adj);
            ag_splittree_free(f);
            rounds++;
            searched += scratch == 0;
            if (round == 4 && trial % 4 == 1)
                assert_int_equal(scratch, 1); /* pairs of another tolerance are not kept */
            else if (changes <= 6)
                assert_int_equal(scratch, 0); /* a few changes among hundreds: a search */
        }
        ag_splittree_free(t);
    }
    assert_true(searched * 2 > rounds);
}

/* A tree that knows nothing of its pairs (a tree read back) finds them from scratch. */
static void test_update_without_state(void **state)
{
    (void)state;
    uint64_t s = 99;
    ag_splittree *t = nested_tree(&s, 1e-3, 10);
    int scratch = -1;
    assert_int_equal(ag_splittree_adjacency_update(t, &scratch), AG_OK);
    assert_int_equal(scratch, 1);
    adjacency_check_brute_force(t, "adjacency");
    /* unchanged since: nothing searched, the same pairs */
    size_t n = t->nadj;
    assert_int_equal(ag_splittree_adjacency_update(t, &scratch), AG_OK);
    assert_int_equal(scratch, 0);
    assert_int_equal(t->nadj, n);
    adjacency_check_brute_force(t, "adjacency");
    ag_splittree_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_sizes_and_offsets),
        cmocka_unit_test(test_facade_panels_and_rows),
        cmocka_unit_test(test_update_after_random_changes),
        cmocka_unit_test(test_update_without_state),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
