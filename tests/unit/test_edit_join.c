/* Join (edit/join.c) on generated facades whose structure is known. */
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

static ag_proceduralize_result *building(unsigned cols, unsigned rows)
{
    ag_gen_facade_options o = {.cols = cols, .rows = rows};
    return proc_facade(&o, NULL);
}

/* Applies a join of nodes a and b and proceduralizes the result. */
static ag_proceduralize_result *join2(ag_proceduralize_result *r, int32_t a, int32_t b,
                                      ag_edit_report *rep)
{
    int32_t sel[2] = {a, b};
    ag_edit_op op = {.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = sel};
    ag_mesh *out = NULL;
    ag_error err = {0};
    if (ag_edit_join(r, &op, &out, rep, &err))
        fail_msg("join: %s", err.text);
    ag_proceduralize_result *s = proc(out);
    ag_mesh_free(out);
    return s;
}

/* Windows of the front row: x = 0.75 + 2.5 i .. + 1.3, z = 0.84 .. 2.7. */
static double wx(int i) { return 1.4 + 2.5 * i; }

/* How many times deriving `rule` places terminal `name`. */
static size_t placements(const ag_grammar *g, const ag_grule *rule, const char *name, int depth)
{
    assert_true(depth < 64);
    size_t n = 0;
    for (size_t i = 0; i < rule->nstmts; i++) {
        const ag_gstmt *st = &rule->stmts[i];
        if (st->kind != AG_GSTMT_APPLY)
            continue;
        size_t cells = 1;
        if (st->subdivide == 1)
            cells = (size_t)st->counts[0] * st->counts[1] * st->counts[2];
        else if (st->subdivide == 2)
            for (int v = 0; v < st->nvec; v++)
                cells *= st->counts[v];
        if (st->callee_is_rule)
            n += cells * placements(g, &g->rules[st->callee_ix], name, depth + 1);
        else if (!strcmp(st->callee, name))
            n += cells;
    }
    return n;
}

static void test_join_repeated_pairs_become_one_rule(void **state)
{
    (void)state;
    /* two rows: the upper one (z = 4.04 .. 5.9) stays as it is */
    ag_proceduralize_result *r = building(4, 2);
    int32_t w[4];
    for (int i = 0; i < 4; i++)
        w[i] = node_at(r, wx(i), 0.15, 1.8);
    int32_t wlabel = r->tree->nodes[w[0]].label;
    size_t win_tris = r->labels->ntris[r->tree->nodes[w[0]].component];
    size_t windows = label_instances(r->tree, wlabel);
    ag_edit_report rep = {0};
    ag_proceduralize_result *s = join2(r, w[0], w[1], &rep);
    assert_int_equal(rep.joins, 1);
    /* labels are numbered afresh by every proceduralization */
    assert_int_equal(label_instances(s->tree, s->tree->nodes[node_at(s, wx(0), 0.15, 5.0)].label),
                     windows - 2);
    int32_t j0 = node_at(s, wx(0), 0.15, 1.8);
    /* one node spanning both windows, holding both of their geometry */
    const ag_box *jb = &s->tree->nodes[j0].box;
    assert_true(fabs(jb->min[0] - 0.75) < 1e-9 && fabs(jb->max[0] - (2.5 + 2.05)) < 1e-9);
    assert_int_equal(s->labels->ntris[s->tree->nodes[j0].component], 2 * win_tris);
    int32_t a = node_at(s, wx(2), 0.15, 1.8), b = node_at(s, wx(3), 0.15, 1.8);
    ag_proceduralize_result *u = join2(s, a, b, &rep);
    assert_int_equal(rep.joins, 2);
    const ag_splittree *t = u->tree;
    int32_t p = node_at(u, wx(0), 0.15, 1.8), q = node_at(u, wx(2), 0.15, 1.8);
    assert_true(p != q);
    /* the two joined pairs are copies: one label, one rule applied to both, and nothing else */
    assert_int_equal(t->nodes[p].label, t->nodes[q].label);
    assert_int_equal(t->nodes[p].rule, t->nodes[q].rule);
    assert_int_equal(t->rule_count[t->nodes[p].rule], 2);
    assert_int_equal(label_instances(t, t->nodes[p].label), 2);
    assert_int_equal(label_instances(t, t->nodes[node_at(u, wx(0), 0.15, 5.0)].label), windows - 4);
    assert_int_equal(windows, 8);
    /* in the grammar the joined terminal is placed twice (as a pattern of a new rule, or by two
     * applications) */
    int32_t term = u->info.terminal_of_variant[t->nodes[p].variant];
    const char *tn = u->grammar->terminals[term].name;
    assert_int_equal(placements(u->grammar, &u->grammar->axiom, tn, 0), 2);
    ag_proceduralize_result_free(u);
    ag_proceduralize_result_free(s);
    ag_proceduralize_result_free(r);
}

static void test_join_different_nodes_is_one_node(void **state)
{
    (void)state;
    ag_proceduralize_result *r = building(4, 1);
    int32_t wall = node_at(r, 5.0, 0.25, 0.5), win = node_at(r, wx(1), 0.15, 1.8);
    int32_t wlabel = r->tree->nodes[win].label;
    size_t windows = label_instances(r->tree, wlabel);
    size_t tris = r->mesh->ntris;
    ag_edit_report rep = {0};
    ag_proceduralize_result *s = join2(r, wall, win, &rep);
    assert_int_equal(s->mesh->ntris, tris);
    int32_t j = node_at(s, 5.0, 0.25, 0.5);
    /* the wall and one window are one component now; the other three windows nest under it */
    assert_int_equal(s->labels->ntris[s->tree->nodes[j].component],
                     12 + r->labels->ntris[r->tree->nodes[win].component]);
    wlabel = s->tree->nodes[node_at(s, wx(2), 0.15, 1.8)].label;
    assert_int_equal(label_instances(s->tree, wlabel), windows - 1);
    size_t under = 0;
    for (size_t i = 0; i < s->tree->nnodes; i++)
        if (s->tree->nodes[i].kind == AG_NODE_COMPONENT && s->tree->nodes[i].label == wlabel)
            under += below(s->tree, (int32_t)i, j);
    assert_int_equal(under, 3);
    ag_proceduralize_result_free(s);
    ag_proceduralize_result_free(r);
}

static void test_join_bad_requests(void **state)
{
    (void)state;
    ag_proceduralize_result *r = building(4, 1);
    int32_t w0 = node_at(r, wx(0), 0.15, 1.8);
    ag_mesh *out = NULL;
    ag_error err = {0};
    ag_edit_op op = {.kind = AG_EDIT_JOIN};
    /* empty selection */
    assert_int_equal(ag_edit_join(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "empty"));
    /* one node, or the same node twice: nothing to join */
    int32_t sel[3] = {w0, w0, 0};
    op.nodes = sel;
    op.nnodes = 1;
    assert_int_equal(ag_edit_join(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    op.nnodes = 2;
    assert_int_equal(ag_edit_join(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "two distinct"));
    /* the root */
    op.nnodes = 3;
    assert_int_equal(ag_edit_join(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "nodes[2]"));
    assert_non_null(strstr(err.text, "root"));
    /* unknown node */
    sel[1] = (int32_t)r->tree->nnodes;
    op.nnodes = 2;
    assert_int_equal(ag_edit_join(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "nodes[1]"));
    assert_int_equal(err.element, (long)r->tree->nnodes);
    assert_null(out);
    ag_proceduralize_result_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_join_repeated_pairs_become_one_rule),
        cmocka_unit_test(test_join_different_nodes_is_one_node),
        cmocka_unit_test(test_join_bad_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
