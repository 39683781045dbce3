/* Parts library selection (core/parts/select.c) on a generated building whose structure is
 * known: selection windows (world box, screen rectangle), a click, walking, common ancestors. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/parts/select.h"
#include "parts_fixture.h"

#define TOL 1e-6

static ag_proceduralize_result *R;
static ag_mesh *M;
static ag_box *S;
static size_t NS;

static int setup(void **state)
{
    (void)state;
    pf_options o = {.cols = 4, .rows = 3, .side_cols = 2, .ww = 1.6, .wh = 2.0, .frame = 0.12,
                    .mullions = 2, .depth = PF_RECESSED};
    M = pf_building(&o, &S, &NS);
    R = pf_proc(M);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ag_proceduralize_result_free(R);
    ag_mesh_free(M);
    free(S);
    return 0;
}

static int is_ancestor(const ag_splittree *t, int32_t a, int32_t n)
{
    for (; n >= 0; n = t->nodes[n].parent)
        if (n == a)
            return 1;
    return 0;
}

static void test_window_box(void **state)
{
    (void)state;
    ag_box w = S[2];
    for (int a = 0; a < 3; a++) {
        w.min[a] -= 0.01;
        w.max[a] += 0.01;
    }
    int32_t *nodes;
    size_t n;
    assert_int_equal(ag_select_box(R->tree, &w, &nodes, &n, NULL), AG_OK);
    assert_int_equal(n, 8); /* casing, 4 bars, glass, 2 mullions */
    int32_t ca;
    assert_int_equal(ag_select_common_tree(R->tree, nodes, n, &ca, NULL), AG_OK);
    assert_int_equal(ca, pf_node_with_box(R, &S[2], TOL));
    free(nodes);
}

static void test_window_rect(void **state)
{
    (void)state;
    /* a camera in front of the facade looking along +y: ndc x = (x - 5) / 6, ndc y = (z - 5) / 6,
     * w = y + 10 (perspective-like: points behind y = -10 are behind the camera) */
    double vp[16] = {0};
    vp[0] = 1.0 / 6;  /* x row: x */
    vp[12] = -5.0 / 6;
    vp[9] = 1.0 / 6;  /* y row: z */
    vp[13] = -5.0 / 6;
    vp[6] = 1;        /* z row (unused) */
    vp[7] = 0;        /* w row: y + 10, scaled out below */
    /* keep w = 1 for an orthographic view */
    vp[15] = 1;
    ag_box s = S[6];
    double rect[4] = {(s.min[0] - 0.01 - 5) / 6, (s.min[2] - 0.01 - 5) / 6,
                      (s.max[0] + 0.01 - 5) / 6, (s.max[2] + 0.01 - 5) / 6};
    int32_t *nodes;
    size_t n;
    assert_int_equal(ag_select_rect(R->tree, vp, rect, &nodes, &n, NULL), AG_OK);
    /* the front window and, seen end-on, nothing of the side walls fits in the rectangle */
    assert_int_equal(n, 8);
    for (size_t i = 0; i < n; i++)
        assert_true(pf_inside(&R->tree->nodes[nodes[i]].box, &s, TOL));
    free(nodes);
    /* the camera moved behind the facade's plane: w = y - 0.2 is <= 0 for the front windows */
    vp[7] = 1;
    vp[15] = -0.2;
    assert_int_equal(ag_select_rect(R->tree, vp, rect, &nodes, &n, NULL), AG_OK);
    for (size_t i = 0; i < n; i++)
        assert_true(R->tree->nodes[nodes[i]].box.min[1] > 0.2);
    free(nodes);
    vp[3] = NAN;
    assert_int_equal(ag_select_rect(R->tree, vp, rect, &nodes, &n, NULL), AG_ERR_INVALID);
}

static void test_click_and_walk(void **state)
{
    (void)state;
    const ag_box *s = &S[1];
    /* the windows are recessed into the solid wall: the ray starts inside the wall, in front
     * of the window */
    double o[3] = {0.5 * (s->min[0] + s->max[0]), 0.05, 0.5 * (s->min[2] + s->max[2])};
    double d[3] = {0, 1, 0};
    int32_t hit;
    assert_int_equal(ag_select_pick(R, o, d, &hit, NULL), AG_OK);
    int32_t casing = pf_node_with_box(R, s, TOL);
    assert_int_equal(hit, casing);
    double away[3] = {0, -1, 0}, far[3] = {o[0], -10, o[2]};
    ag_error err = {0};
    assert_int_equal(ag_select_pick(R, far, away, &hit, &err), AG_ERR_NOT_FOUND);
    /* walking down from the casing reaches its 7 members, each child's parent is the casing
     * (or a pattern below it), siblings walk both ways */
    const ag_splittree *t = R->tree;
    int32_t stack[64], kids[64];
    size_t sp = 0, visible = 0;
    stack[sp++] = casing;
    while (sp) {
        int32_t v = stack[--sp];
        visible += t->nodes[v].kind == AG_NODE_COMPONENT;
        size_t nk = ag_select_children(t, v, kids, 64);
        assert_true(nk <= 64);
        for (size_t i = 0; i < nk; i++) {
            assert_int_equal(ag_select_parent(t, kids[i]), v);
            assert_true(t->nodes[kids[i]].kind != AG_NODE_SPLIT);
            if (i > 0) {
                assert_int_equal(ag_select_sibling(t, kids[i], -1), kids[i - 1]);
                assert_int_equal(ag_select_sibling(t, kids[i - 1], +1), kids[i]);
            }
            stack[sp++] = kids[i];
        }
        if (nk) {
            assert_int_equal(ag_select_sibling(t, kids[0], -1), -1);
            assert_int_equal(ag_select_sibling(t, kids[nk - 1], +1), -1);
        }
    }
    assert_int_equal(visible, 8);
    assert_int_equal(ag_select_parent(t, 0), -1);
    assert_int_equal(ag_select_parent(t, -5), -1);
}

static void test_common_ancestors(void **state)
{
    (void)state;
    const ag_splittree *t = R->tree;
    int32_t a = pf_node_with_box(R, &S[0], TOL), b = pf_node_with_box(R, &S[7], TOL);
    int32_t sel[2] = {a, b};
    int32_t ca;
    assert_int_equal(ag_select_common_tree(t, sel, 2, &ca, NULL), AG_OK);
    /* an ancestor of both, and none of its children is */
    assert_true(is_ancestor(t, ca, a) && is_ancestor(t, ca, b));
    int32_t kids[256];
    size_t nk = ag_select_children(t, ca, kids, 256);
    for (size_t i = 0; i < nk && i < 256; i++)
        assert_false(is_ancestor(t, kids[i], a) && is_ancestor(t, kids[i], b));
    /* at the rule level both windows are offered: they share their rule */
    int32_t *nodes;
    size_t n;
    assert_int_equal(ag_select_common_rule(t, sel, 2, &nodes, &n, NULL), AG_OK);
    assert_int_equal(n, 2);
    assert_true((nodes[0] == a && nodes[1] == b) || (nodes[0] == b && nodes[1] == a));
    assert_int_equal(t->nodes[a].rule, t->nodes[b].rule);
    free(nodes);
    /* a window and one of its bars: the window */
    int32_t kids2[16];
    size_t k2 = ag_select_children(t, a, kids2, 16);
    assert_true(k2 > 0);
    int32_t sel2[2] = {kids2[0], a};
    assert_int_equal(ag_select_common_tree(t, sel2, 2, &ca, NULL), AG_OK);
    assert_int_equal(ca, a);
    /* bad selections */
    ag_error err = {0};
    assert_int_equal(ag_select_common_tree(t, sel, 0, &ca, &err), AG_ERR_INVALID);
    int32_t bad[2] = {a, 1 << 30};
    assert_int_equal(ag_select_common_rule(t, bad, 2, &nodes, &n, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(err.element, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_box),
        cmocka_unit_test(test_window_rect),
        cmocka_unit_test(test_click_and_walk),
        cmocka_unit_test(test_common_ancestors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
