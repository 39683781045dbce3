/* Split by a plane (edit/split.c) on a generated facade whose structure is known. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "edit_fixture.h"

static ag_proceduralize_result *row_building(size_t *tris)
{
    ag_gen_facade_options o = {.cols = 6, .rows = 1};
    return proc_facade(&o, tris);
}

static void test_split_wall_duplicates_its_window_row(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = row_building(&tris);
    /* front wall: 15.3 m along x; below the windows at z = 0.5 only the wall is there */
    int32_t wall = node_at(r, 5.0, 0.25, 0.5);
    const ag_box wb = r->tree->nodes[wall].box;
    assert_true(fabs(wb.max[0] - wb.min[0] - 15.3) < 1e-9);
    int32_t win = node_at(r, 1.4, 0.15, 1.8);
    int32_t wlabel = r->tree->nodes[win].label;
    size_t win_tris = r->labels->ntris[r->tree->nodes[win].component];
    size_t windows = 0;
    for (size_t i = 0; i < r->tree->nnodes; i++)
        if (r->tree->nodes[i].kind == AG_NODE_COMPONENT && r->tree->nodes[i].label == wlabel)
            windows += below(r->tree, (int32_t)i, wall);
    assert_int_equal(windows, 6);

    double mid = 0.5 * (wb.min[0] + wb.max[0]);
    ag_edit_op op = {.kind = AG_EDIT_SPLIT, .node = wall, .axis = 0, .at = mid};
    ag_edit_report rep = {0};
    ag_mesh *out = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_split(r, &op, &out, &rep, &err), AG_OK);
    assert_int_equal(rep.splits, 1);
    /* the wall's subtree (the wall and its 6 windows) now exists twice */
    size_t subtree = 12 + 6 * win_tris;
    assert_int_equal(out->ntris, tris + subtree);

    ag_proceduralize_result *s = proc(out);
    const ag_splittree *t = s->tree;
    /* two walls, each half as long, each holding 6 windows squeezed to half their width */
    int32_t w0 = node_at(s, wb.min[0] + 1.0, 0.25, 0.5), w1 = node_at(s, wb.max[0] - 1.0, 0.25, 0.5);
    assert_true(w0 != w1);
    for (int h = 0; h < 2; h++) {
        const ag_box *b = &t->nodes[h ? w1 : w0].box;
        assert_true(fabs(b->max[0] - b->min[0] - 0.5 * 15.3) < 1e-9);
        assert_true(fabs(b->max[2] - b->min[2] - (wb.max[2] - wb.min[2])) < 1e-9);
    }
    assert_int_equal(t->nodes[w0].label, t->nodes[w1].label);
    assert_int_equal(t->nodes[w0].rule, t->nodes[w1].rule);
    int32_t sw = node_at(s, 0.5 * 1.4, 0.15, 1.8); /* the first squeezed window */
    int32_t slabel = t->nodes[sw].label;
    size_t in0 = 0, in1 = 0, all = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_COMPONENT || n->label != slabel)
            continue;
        all++;
        assert_true(fabs(n->box.max[0] - n->box.min[0] - 0.65) < 1e-9); /* 1.3 m halved */
        assert_true(fabs(n->box.max[2] - n->box.min[2] - 1.86) < 1e-9);  /* height kept */
        in0 += below(t, (int32_t)i, w0);
        in1 += below(t, (int32_t)i, w1);
    }
    assert_int_equal(all, 12);
    assert_int_equal(in0, 6);
    assert_int_equal(in1, 6);
    /* the six squeezed windows of each wall are a pattern of one rule */
    size_t six = 0;
    for (size_t p = 0; p < t->npatterns; p++)
        six += t->patterns[p].counts[0] * t->patterns[p].counts[1] * t->patterns[p].counts[2] == 6;
    assert_true(six >= 1);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_split_root_doubles_the_building(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = row_building(&tris);
    const ag_box rb = r->tree->nodes[0].box;
    ag_edit_op op = {.kind = AG_EDIT_SPLIT, .node = AG_EDIT_ROOT, .axis = 2,
                     .at = 0.5 * (rb.min[2] + rb.max[2])};
    ag_mesh *out = NULL;
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, NULL), AG_OK);
    assert_int_equal(out->ntris, 2 * tris);
    ag_box ob = ag_mesh_bounds(out);
    for (int a = 0; a < 3; a++) {
        assert_true(fabs(ob.min[a] - rb.min[a]) < 1e-9);
        assert_true(fabs(ob.max[a] - rb.max[a]) < 1e-9);
    }
    ag_proceduralize_result *s = proc(out);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_split_bad_requests(void **state)
{
    (void)state;
    ag_proceduralize_result *r = row_building(NULL);
    int32_t wall = node_at(r, 5.0, 0.25, 0.5);
    const ag_box wb = r->tree->nodes[wall].box;
    ag_mesh *out = NULL;
    ag_error err = {0};

    ag_edit_op op = {.kind = AG_EDIT_SPLIT, .node = 100000, .axis = 0, .at = 1};
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(err.element, 100000);
    assert_non_null(strstr(err.text, "node 100000"));
    op.node = -3;
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);

    op.node = wall;
    op.at = wb.max[0] + 1; /* plane outside the box */
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "not inside"));
    op.at = wb.min[0]; /* on a face: one half would be empty */
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    op.at = NAN;
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    op.at = 0.5 * (wb.min[0] + wb.max[0]);
    op.axis = 3;
    assert_int_equal(ag_edit_split(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "axis"));
    assert_null(out);
    ag_proceduralize_result_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_wall_duplicates_its_window_row),
        cmocka_unit_test(test_split_root_doubles_the_building),
        cmocka_unit_test(test_split_bad_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
