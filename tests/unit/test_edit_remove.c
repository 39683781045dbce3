/* Remove (edit/remove.c) on a generated facade whose structure is known. */
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

static ag_proceduralize_result *building(size_t *tris)
{
    ag_gen_facade_options o = {.cols = 6, .rows = 4, .side_cols = 3};
    return proc_facade(&o, tris);
}

static ag_mesh *remove_nodes(const ag_proceduralize_result *r, int32_t *nodes, size_t n,
                             ag_status expect, ag_error *err)
{
    ag_edit_op op = {.kind = AG_EDIT_REMOVE, .nnodes = n, .nodes = nodes};
    ag_mesh *out = NULL;
    ag_status st = ag_edit_remove(r, &op, &out, NULL, err);
    if (st != expect)
        fail_msg("remove: status %d, expected %d: %s", st, expect, err ? err->text : "");
    return out;
}

static void test_remove_one_window(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = building(&tris);
    int32_t win = node_at(r, 1.4 + 2.5, 0.15, 1.8 + 3.2);
    int32_t label = r->tree->nodes[win].label;
    size_t wt = r->labels->ntris[r->tree->nodes[win].component];
    size_t windows = label_instances(r->tree, label);
    assert_int_equal(windows, 24 + 12);
    ag_mesh *out = remove_nodes(r, &win, 1, AG_OK, NULL);
    assert_int_equal(out->ntris, tris - wt);
    ag_proceduralize_result *s = proc(out);
    label = s->tree->nodes[node_at(s, 1.4, 0.15, 1.8)].label;
    assert_int_equal(label_instances(s->tree, label), windows - 1);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_remove_takes_the_subtree(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = building(&tris);
    int32_t wall = node_at(r, 6.5, 0.25, 0.5), win = node_at(r, 1.4, 0.15, 1.8);
    size_t wt = r->labels->ntris[r->tree->nodes[win].component];
    /* the front wall goes with its 24 windows; naming a window of it as well changes nothing */
    int32_t sel[2] = {win, wall};
    ag_mesh *out = remove_nodes(r, sel, 2, AG_OK, NULL);
    assert_int_equal(out->ntris, tris - 12 - 24 * wt);
    ag_proceduralize_result *s = proc(out);
    int32_t side = s->tree->nodes[node_at(s, 15.3 - 0.15, 1.4, 1.8)].label;
    assert_int_equal(label_instances(s->tree, side), 12);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);

    /* a pattern node stands for all its instances: removing the front's 6 x 4 grid */
    int32_t pat = -1;
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        if (pt->counts[0] * pt->counts[1] * pt->counts[2] == 24)
            pat = pt->node;
    }
    assert_true(pat > 0);
    out = remove_nodes(r, &pat, 1, AG_OK, NULL);
    assert_int_equal(out->ntris, tris - 24 * wt);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_remove_bad_requests(void **state)
{
    (void)state;
    ag_proceduralize_result *r = building(NULL);
    ag_error err = {0};
    assert_null(remove_nodes(r, NULL, 0, AG_ERR_INVALID, &err));
    assert_non_null(strstr(err.text, "empty"));
    int32_t sel[2] = {node_at(r, 1.4, 0.15, 1.8), AG_EDIT_ROOT};
    assert_null(remove_nodes(r, sel, 2, AG_ERR_INVALID, &err));
    assert_non_null(strstr(err.text, "nodes[1]"));
    assert_non_null(strstr(err.text, "root"));
    sel[1] = 424242;
    assert_null(remove_nodes(r, sel, 2, AG_ERR_NOT_FOUND, &err));
    assert_int_equal(err.element, 424242);
    assert_non_null(strstr(err.text, "node 424242"));
    /* every top-level node: nothing would be left */
    const ag_splittree *t = r->tree;
    size_t n = 0;
    int32_t *all = malloc(t->nnodes * sizeof *all);
    for (int32_t c = t->nodes[0].first_child; c >= 0; c = t->nodes[c].next_sibling)
        all[n++] = c;
    assert_null(remove_nodes(r, all, n, AG_ERR_INVALID, &err));
    assert_non_null(strstr(err.text, "no geometry"));
    free(all);
    ag_proceduralize_result_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_remove_one_window),
        cmocka_unit_test(test_remove_takes_the_subtree),
        cmocka_unit_test(test_remove_bad_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
