/* Split tree construction: nesting, at most two splits per insertion, exact boxes. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/splittree.h"

static int32_t comp_of_group(const ag_mesh *m, const char *name)
{
    for (size_t c = 0; c < m->ncomponents; c++) {
        int32_t g = m->component_group[c];
        if (g >= 0 && !strcmp(m->group_names[g], name))
            return (int32_t)c;
    }
    fail_msg("no group %s", name);
    return -1;
}

/* The visible node (or root) a node hangs from, and the number of splits on the way. */
static int32_t anchor(const ag_splittree *t, int32_t n, int *splits)
{
    *splits = 1;
    int32_t p = t->nodes[n].parent;
    while (t->nodes[p].kind == AG_NODE_SPLIT) {
        (*splits)++;
        p = t->nodes[p].parent;
    }
    return p;
}

static void test_tree_of_generated_building(void **state)
{
    (void)state;
    ag_mesh *m;
    ag_gen_facade_options o = {.cols = 6, .rows = 4, .side_cols = 3, .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    ag_labels *L;
    ag_splittree *t;
    assert_int_equal(ag_label_components(m, NULL, &L, NULL), AG_OK);
    assert_int_equal(ag_splittree_build(m, L, &t, NULL), AG_OK);

    ag_splittree_stats s = ag_splittree_stats_of(t);
    assert_int_equal(s.visible, m->ncomponents);
    assert_int_equal(s.nodes, s.visible + s.invisible);
    assert_int_equal(t->nodes[0].kind, AG_NODE_ROOT);
    double diag = L->diagonal;
    for (size_t c = 0; c < m->ncomponents; c++) {
        int32_t n = t->comp_node[c];
        assert_true(n > 0);
        assert_int_equal(t->nodes[n].component, (int32_t)c);
        assert_int_equal(t->nodes[n].label, L->label[c]);
        for (int a = 0; a < 3; a++) {
            assert_true(fabs(t->nodes[n].box.min[a] - L->box[c].min[a]) < 1e-12 * diag);
            assert_true(fabs(t->nodes[n].box.max[a] - L->box[c].max[a]) < 1e-12 * diag);
        }
        int splits;
        int32_t p = anchor(t, n, &splits);
        assert_true(splits >= 1 && splits <= 2);
        assert_true(t->nodes[p].kind == AG_NODE_ROOT || t->nodes[p].kind == AG_NODE_COMPONENT);
    }
    for (size_t i = 1; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        assert_true(n->octant >= 1 && n->octant <= 8);
        /* the stored box is the split of the parent's box */
        ag_box b = ag_splittree_child_box(&t->nodes[n->parent].box, n->pivot, n->octant);
        assert_memory_equal(&b, &n->box, sizeof b);
        if (n->kind == AG_NODE_SPLIT)
            assert_int_equal(n->first_child, n->last_child); /* exactly one child */
    }
    /* windows nest under their wall, walls and the roof under the root */
    int splits;
    int32_t wall = t->comp_node[comp_of_group(m, "wall_front")];
    int32_t side = t->comp_node[comp_of_group(m, "wall_right")];
    assert_int_equal(anchor(t, t->comp_node[comp_of_group(m, "window_front_3_2")], &splits), wall);
    assert_int_equal(anchor(t, t->comp_node[comp_of_group(m, "window_right_1_0")], &splits), side);
    assert_int_equal(anchor(t, wall, &splits), 0);
    assert_int_equal(anchor(t, t->comp_node[comp_of_group(m, "roof")], &splits), 0);
    size_t depth = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        size_t d = 0;
        for (int32_t p = t->nodes[i].parent; p >= 0; p = t->nodes[p].parent)
            d++;
        if (d > depth)
            depth = d;
    }
    assert_int_equal(s.depth, depth);
    assert_true(depth >= 3 && depth <= 5); /* root, [split], wall, [split], window */

    /* adjacency: ordered unique pairs; a window touches its wall */
    int found = 0;
    int32_t win = t->comp_node[comp_of_group(m, "window_front_0_0")];
    for (size_t i = 0; i < t->nadj; i++) {
        assert_true(t->adj[2 * i] < t->adj[2 * i + 1]);
        if ((int32_t)t->adj[2 * i] == (wall < win ? wall : win) &&
            (int32_t)t->adj[2 * i + 1] == (wall < win ? win : wall))
            found = 1;
    }
    assert_true(found);
    ag_splittree_free(t);
    ag_labels_free(L);
    ag_mesh_free(m);
}

static void test_insert_uses_one_split_on_a_shared_corner(void **state)
{
    (void)state;
    ag_splittree t = {0};
    t.cap = 8;
    t.nodes = calloc(t.cap, sizeof *t.nodes);
    t.nnodes = 1;
    t.nodes[0] = (ag_tnode){.box = {{0, 0, 0}, {10, 10, 10}}, .parent = -1, .first_child = -1,
                            .last_child = -1, .next_sibling = -1, .kind = AG_NODE_ROOT};
    t.eps = 1e-9;
    ag_box corner = {{0, 0, 0}, {2, 3, 4}};
    int32_t a = ag_splittree_insert(&t, 0, &corner, AG_NODE_COMPONENT);
    assert_int_equal(a, 1);
    assert_int_equal(t.nodes[a].parent, 0);
    assert_int_equal(t.nodes[a].octant, 1);
    ag_box top = {{3, 4, 5}, {10, 10, 10}};
    int32_t b = ag_splittree_insert(&t, 0, &top, AG_NODE_COMPONENT);
    assert_int_equal(t.nodes[b].parent, 0);
    assert_int_equal(t.nodes[b].octant, 8);
    ag_box inner = {{1, 2, 3}, {4, 5, 6}};
    int32_t c = ag_splittree_insert(&t, 0, &inner, AG_NODE_COMPONENT);
    int32_t mid = t.nodes[c].parent;
    assert_int_equal(t.nodes[mid].kind, AG_NODE_SPLIT);
    assert_int_equal(t.nodes[mid].parent, 0);
    assert_memory_equal(&t.nodes[c].box, &inner, sizeof inner);
    free(t.nodes);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tree_of_generated_building),
        cmocka_unit_test(test_insert_uses_one_split_on_a_shared_corner),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
