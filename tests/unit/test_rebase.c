/* Rebasing live ops (app/rebase.h): a node is found again in a later tree by its kind and box
 * alone — renumbered, moved within the tolerance, among twins only when it kept its id — and
 * is lost when its box changed, when it is gone or dead; the tolerance follows the model's size,
 * so a model far from the origin (UTM coordinates) maps the same. The op's use of it is in
 * tests/integration/rebase.test.js. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>

#include "app/rebase.h"

/* A served tree of the given nodes: kind and box each, ids in order. */
static json_t *tree(size_t n, const char *const *kinds, const double (*boxes)[6], double dx)
{
    json_t *nodes = json_array();
    for (size_t i = 0; i < n; i++) {
        json_t *box = json_array();
        for (int k = 0; k < 6; k++)
            json_array_append_new(box, json_real(boxes[i][k] + (k % 3 == 0 ? dx : 0)));
        json_array_append_new(nodes, json_pack("{s:I, s:s, s:o}", "id", (json_int_t)i, "kind",
                                               kinds[i], "box", box));
    }
    return json_pack("{s:i, s:o}", "root", 0, "nodes", nodes);
}

static void nodes_are_found_by_kind_and_box(void **state)
{
    (void)state;
    for (int far = 0; far < 2; far++) {
        double dx = far ? 512345.0 : 0; /* UTM-sized coordinates */
        const char *ka[] = {"root", "component", "component", "component", "dead"};
        const double ba[][6] = {{0, 0, 0, 10, 1, 10},
                                {0, 0, 0, 10, 1, 10},
                                {1, 0, 1, 2, 1, 2},
                                {4, 0, 1, 5, 1, 2},
                                {4, 0, 1, 5, 1, 2}};
        json_t *a = tree(5, ka, ba, dx);
        /* b: renumbered, node 2 moved within the tolerance, node 3 changed, a new twin of 2 */
        const char *kb[] = {"root", "split", "component", "component", "component", "component"};
        const double bb[][6] = {{0, 0, 0, 10, 1, 10},
                                {0, 0, 0, 10, 1, 10},
                                {4, 0, 1, 5.2, 1, 2},
                                {0, 0, 0, 10, 1, 10},
                                {1, 0, 1, 2 + 1e-9, 1, 2},
                                {7, 0, 1, 8, 1, 2}};
        json_t *b = tree(6, kb, bb, dx);
        assert_int_equal(ag_rebase_map_node(a, b, 0), 0);  /* the root kept its box */
        assert_int_equal(ag_rebase_map_node(a, b, 1), 3);  /* a component, found by kind */
        assert_int_equal(ag_rebase_map_node(a, b, 2), 4);  /* renumbered, within tolerance */
        assert_int_equal(ag_rebase_map_node(a, b, 3), -1); /* its box changed */
        assert_int_equal(ag_rebase_map_node(a, b, 4), -1); /* dead nodes are never named */
        assert_int_equal(ag_rebase_map_node(a, b, 9), -1); /* no such node */
        assert_int_equal(ag_rebase_map_node(a, b, -1), -1);
        json_decref(a);
        json_decref(b);
    }
}

static void twins_map_only_when_the_id_is_kept(void **state)
{
    (void)state;
    const char *k[] = {"root", "component", "component"};
    const double same[][6] = {{0, 0, 0, 4, 1, 4}, {1, 0, 1, 2, 1, 2}, {1, 0, 1, 2, 1, 2}};
    json_t *a = tree(3, k, same, 0);
    json_t *b = tree(3, k, same, 0);
    assert_int_equal(ag_rebase_map_node(a, b, 1), 1);
    assert_int_equal(ag_rebase_map_node(a, b, 2), 2);
    /* in a tree where the twins are elsewhere, which is which cannot be told */
    const char *k3[] = {"root", "split", "component", "component"};
    const double moved[][6] = {{0, 0, 0, 4, 1, 4}, {0, 0, 0, 4, 1, 4}, {1, 0, 1, 2, 1, 2},
                               {1, 0, 1, 2, 1, 2}};
    json_t *c = tree(4, k3, moved, 0);
    assert_int_equal(ag_rebase_map_node(a, c, 1), -1);
    json_decref(a);
    json_decref(b);
    json_decref(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(nodes_are_found_by_kind_and_box),
        cmocka_unit_test(twins_map_only_when_the_id_is_kept),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
