/* Grammar export and derivation: exact reproduction, malformed and trivial inputs. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"

static ag_proceduralize_result *run(const ag_mesh *m, ag_status want, ag_error *err)
{
    ag_proceduralize_options o = {.verify = 1};
    ag_proceduralize_result *r = NULL;
    assert_int_equal(ag_proceduralize_run(m, &o, &r, err), want);
    return r;
}

static void test_derivation_reproduces_every_triangle(void **state)
{
    (void)state;
    ag_mesh *m;
    ag_gen_facade_options o = {.cols = 5, .rows = 3, .side_cols = 4, .back = 1, .left = 1,
                               .annex = 1, .bars = 2};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    ag_proceduralize_result *r = run(m, AG_OK, NULL);
    ag_mesh *d;
    assert_int_equal(ag_grammar_derive(r->grammar, NULL, &d, NULL), AG_OK);
    assert_int_equal(d->ntris, m->ntris);
    ag_fidelity f;
    assert_int_equal(ag_grammar_fidelity(m, d, 0, &f, NULL), AG_OK);
    assert_int_equal(f.unmatched, 0);
    assert_true(f.relative <= 1e-12);
    /* one material group per terminal; every placement is one component */
    assert_int_equal(d->ngroups, r->grammar->nterminals);
    assert_int_equal(d->ncomponents, m->ncomponents);
    /* compact: every window stored once */
    size_t stored = 0;
    for (size_t i = 0; i < r->grammar->nterminals; i++)
        stored += r->grammar->terminals[i].ntris;
    assert_true(stored < m->ntris / 10);

    /* a moved vertex is detected */
    d->pos[0] += 0.01;
    assert_int_equal(ag_grammar_fidelity(m, d, 0, &f, NULL), AG_OK);
    assert_true(f.unmatched >= 1);
    ag_mesh_free(d);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

static void test_malformed_input_is_refused(void **state)
{
    (void)state;
    ag_error err = {0};
    ag_mesh *m = ag_mesh_create();
    assert_null(run(m, AG_ERR_EMPTY, &err));
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_vertex(m, 0, 0, 0);
    ag_mesh_add_vertex(m, NAN, 0, 0);
    ag_mesh_add_vertex(m, 0, 1, 0);
    ag_mesh_add_triangle(m, 0, 1, 2, 0);
    assert_null(run(m, AG_ERR_INVALID, &err));
    assert_non_null(strstr(err.text, "non-finite"));
    m->pos[3] = 1;
    m->tri[1] = 9;
    assert_null(run(m, AG_ERR_INVALID, &err));
    ag_mesh_free(m);
}

static void test_one_triangle_and_degenerate_triangles(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_vertex(m, 0, 0, 0);
    ag_mesh_add_vertex(m, 1, 0, 0);
    ag_mesh_add_vertex(m, 0, 1, 0);
    ag_mesh_add_triangle(m, 0, 1, 2, 0);
    ag_proceduralize_result *r = run(m, AG_OK, NULL);
    assert_int_equal(r->grammar->nterminals, 1);
    assert_int_equal(r->grammar->nrules, 0);
    assert_int_equal(r->fidelity.unmatched, 0);
    ag_proceduralize_result_free(r);

    /* zero-area triangles (repeated index, collinear) and an empty group */
    size_t g;
    ag_mesh_add_group(m, "empty", &g);
    ag_mesh_add_component(m, (int32_t)g, &c);
    ag_mesh_add_vertex(m, 2, 0, 0);
    ag_mesh_add_triangle(m, 0, 0, 1, 0);
    ag_mesh_add_triangle(m, 0, 1, 3, 0);
    r = run(m, AG_OK, NULL);
    assert_int_equal(r->fidelity.unmatched, 0);
    assert_int_equal(r->fidelity.derived_triangles, 3);
    ag_proceduralize_result_free(r);

    /* every vertex at one point */
    ag_mesh *p = ag_mesh_create();
    ag_mesh_add_component(p, -1, &c);
    for (int i = 0; i < 3; i++)
        ag_mesh_add_vertex(p, 5, 5, 5);
    ag_mesh_add_triangle(p, 0, 1, 2, 0);
    r = run(p, AG_OK, NULL);
    assert_int_equal(r->fidelity.unmatched, 0);
    ag_proceduralize_result_free(r);
    ag_mesh_free(p);
    ag_mesh_free(m);
}

static void test_derivation_limits_and_turns(void **state)
{
    (void)state;
    /* hand-built grammar: a unit tetra turned by 90 degrees, then subdivided */
    ag_grammar *g = ag_grammar_create();
    double one[3] = {1, 2, 1};
    size_t ti, ri;
    assert_int_equal(ag_grammar_add_terminal(g, "T", one, &ti), AG_OK);
    double pos[12] = {0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 1};
    uint32_t tri[3] = {0, 1, 2};
    assert_int_equal(ag_grammar_set_terminal_geometry(&g->terminals[ti], pos, 4, tri, 1), AG_OK);
    assert_int_equal(ag_grammar_add_rule(g, "R", one, &ri), AG_OK);
    assert_int_equal(ag_grammar_add_apply(&g->rules[ri], "T", "p", 0, NULL, NULL, 0, 0), AG_OK);
    g->has_axiom = 1;
    g->axiom.box = (ag_box){{0, 0, 0}, {2, 1, 1}};
    assert_int_equal(ag_grammar_add_apply(&g->axiom, "R", "p", 1, NULL, NULL, 0, 0), AG_OK);
    long col;
    assert_int_equal(ag_grammar_resolve(g, NULL, &col), AG_OK);
    ag_mesh *d;
    assert_int_equal(ag_grammar_derive(g, NULL, &d, NULL), AG_OK);
    /* (x, y) turned a quarter about the box centre: (0,0)->(2,0), (1,0)->(2,1), (0,2)->(0,0) */
    const double want[9] = {2, 0, 0, 2, 1, 0, 0, 0, 0};
    for (int i = 0; i < 9; i++)
        assert_true(fabs(d->pos[i] - want[i]) < 1e-12);
    ag_mesh_free(d);

    /* too many cells for the limit */
    ag_grammar_free(g);
    g = ag_grammar_create();
    ag_grammar_add_terminal(g, "T", one, &ti);
    ag_grammar_set_terminal_geometry(&g->terminals[ti], pos, 4, tri, 1);
    ag_grammar_add_rule(g, "R", one, &ri);
    ag_grammar_add_apply(&g->rules[ri], "T", "p", 0, NULL, NULL, 0, 0);
    g->has_axiom = 1;
    g->axiom.box = (ag_box){{0, 0, 0}, {1000, 1000, 1}};
    uint32_t counts[3] = {1000, 1000, 1};
    double step[3] = {1, 1, 0};
    ag_grammar_add_apply(&g->axiom, "R", "p", 0, counts, step, 0, 0);
    assert_int_equal(ag_grammar_resolve(g, NULL, &col), AG_OK);
    ag_grammar_derive_options lim = {.max_triangles = 1000};
    ag_error err = {0};
    assert_int_equal(ag_grammar_derive(g, &lim, &d, &err), AG_ERR_TOO_LARGE);
    assert_null(d);
    /* an undefined node is refused by resolve, a rule cannot call a later rule */
    ag_grammar_add_apply(&g->axiom, "T", "nowhere", 0, NULL, NULL, 7, 3);
    assert_int_equal(ag_grammar_resolve(g, &err, &col), AG_ERR_PARSE);
    assert_int_equal(err.element, 7);
    assert_int_equal(col, 3);
    ag_grammar_free(g);
}

static void test_deep_nesting_and_rule_chains(void **state)
{
    (void)state;
    /* 3000 nested shells: nesting is bounded, nothing recurses that deep */
    ag_mesh *m = ag_mesh_create();
    for (int i = 0; i < 3000; i++) {
        size_t c;
        ag_mesh_add_component(m, -1, &c);
        double r = 3000 - i;
        uint32_t b = (uint32_t)m->nverts;
        ag_mesh_add_vertex(m, -r, -r, -r);
        ag_mesh_add_vertex(m, r, -r, -r);
        ag_mesh_add_vertex(m, 0, r, r);
        ag_mesh_add_triangle(m, b, b + 1, b + 2, (uint32_t)c);
    }
    ag_proceduralize_result *r = run(m, AG_OK, NULL);
    assert_int_equal(r->fidelity.unmatched, 0);
    ag_splittree_stats s = ag_splittree_stats_of(r->tree);
    assert_true(s.depth <= 2 * AG_SPLITTREE_MAX_NESTING + 2);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);

    /* a chain of 2000 rules each applying the previous one is refused, not overflowed */
    ag_grammar *g = ag_grammar_create();
    double one[3] = {1, 1, 1};
    size_t ti, ri;
    ag_grammar_add_terminal(g, "T", one, &ti);
    double pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 1};
    uint32_t tri[3] = {0, 1, 2};
    ag_grammar_set_terminal_geometry(&g->terminals[ti], pos, 3, tri, 1);
    char name[32], prev[32] = "T";
    for (int i = 0; i < 2000; i++) {
        snprintf(name, sizeof name, "R%d", i);
        ag_grammar_add_rule(g, name, one, &ri);
        ag_grammar_add_apply(&g->rules[ri], prev, "p", 0, NULL, NULL, 0, 0);
        snprintf(prev, sizeof prev, "%s", name);
    }
    g->has_axiom = 1;
    g->axiom.box = (ag_box){{0, 0, 0}, {1, 1, 1}};
    ag_grammar_add_apply(&g->axiom, prev, "p", 0, NULL, NULL, 0, 0);
    long col;
    assert_int_equal(ag_grammar_resolve(g, NULL, &col), AG_OK);
    ag_mesh *d = NULL;
    ag_error err = {0};
    assert_int_equal(ag_grammar_derive(g, NULL, &d, &err), AG_ERR_TOO_LARGE);
    assert_null(d);
    ag_grammar_free(g);
}

/* A flat component on its parent's upper face, where min + (c.min - min) rounds past max
 * (these coordinates come from a building read with the other up axis): the child box must
 * not come out inverted, and the grammar must export and resolve. */
static void test_flat_child_on_the_upper_face(void **state)
{
    (void)state;
    const double lo = -21.133, hi = -0.929;
    ag_box parent = {{0, lo, 0}, {1, hi, 1}};
    double pivot[3] = {0, hi - lo, 0};
    ag_box child = ag_splittree_child_box(&parent, pivot, 1 + 2); /* upper part along y */
    assert_true(child.min[1] <= child.max[1]);
    assert_true(child.min[1] == hi);

    ag_mesh *m = ag_mesh_create();
    size_t c;
    const double box[8][3] = {{0, lo, 0}, {1, lo, 0}, {0, hi, 0}, {1, hi, 0},
                              {0, lo, 1}, {1, lo, 1}, {0, hi, 1}, {1, hi, 1}};
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    ag_mesh_add_component(m, -1, &c);
    for (int i = 0; i < 8; i++)
        ag_mesh_add_vertex(m, box[i][0], box[i][1], box[i][2]);
    for (int i = 0; i < 12; i++)
        ag_mesh_add_triangle(m, f[i][0], f[i][1], f[i][2], (uint32_t)c);
    /* a quad lying on the box's y = hi face, 10 cm inside its edges */
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_vertex(m, 0.1, hi, 0.1);
    ag_mesh_add_vertex(m, 0.9, hi, 0.1);
    ag_mesh_add_vertex(m, 0.9, hi, 0.9);
    ag_mesh_add_vertex(m, 0.1, hi, 0.9);
    ag_mesh_add_triangle(m, 8, 10, 9, (uint32_t)c);
    ag_mesh_add_triangle(m, 8, 11, 10, (uint32_t)c);
    ag_error err;
    ag_proceduralize_result *r = run(m, AG_OK, &err);
    for (size_t i = 0; i < r->tree->nnodes; i++)
        for (int a = 0; a < 3; a++)
            assert_true(r->tree->nodes[i].box.min[a] <= r->tree->nodes[i].box.max[a]);
    assert_int_equal(r->fidelity.unmatched, 0);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_derivation_reproduces_every_triangle),
        cmocka_unit_test(test_malformed_input_is_refused),
        cmocka_unit_test(test_one_triangle_and_degenerate_triangles),
        cmocka_unit_test(test_derivation_limits_and_turns),
        cmocka_unit_test(test_deep_nesting_and_rule_chains),
        cmocka_unit_test(test_flat_child_on_the_upper_face),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
