/* Rule labeling and pattern discovery on buildings with known repetition. */
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

static void add_box(ag_mesh *m, double x0, double y0, double z0, double x1, double y1, double z1,
                    const char *group)
{
    size_t g = 0, c;
    if (group)
        assert_int_equal(ag_mesh_add_group(m, group, &g), AG_OK);
    assert_int_equal(ag_mesh_add_component(m, group ? (int32_t)g : -1, &c), AG_OK);
    uint32_t b = (uint32_t)m->nverts;
    for (int i = 0; i < 8; i++)
        ag_mesh_add_vertex(m, i & 1 ? x1 : x0, i & 2 ? y1 : y0, i & 4 ? z1 : z0);
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12; i++)
        ag_mesh_add_triangle(m, b + f[i][0], b + f[i][1], b + f[i][2], (uint32_t)c);
}

/* Statements of a rule body or the axiom that apply `callee`. */
static size_t applications(const ag_grule *r, const char *callee, const ag_gstmt **last)
{
    size_t n = 0;
    for (size_t i = 0; i < r->nstmts; i++)
        if (r->stmts[i].kind == AG_GSTMT_APPLY && !strcmp(r->stmts[i].callee, callee)) {
            n++;
            if (last)
                *last = &r->stmts[i];
        }
    return n;
}

static ag_proceduralize_result *run(const ag_mesh *m)
{
    ag_proceduralize_options o = {.verify = 1};
    ag_proceduralize_result *r = NULL;
    ag_error err = {0};
    ag_status st = ag_proceduralize_run(m, &o, &r, &err);
    if (st)
        fail_msg("proceduralize: %s", err.text);
    assert_int_equal(r->fidelity.unmatched, 0);
    assert_true(r->fidelity.relative < 1e-9);
    return r;
}

static void test_window_grid_is_one_rule_subdivided(void **state)
{
    (void)state;
    ag_mesh *m;
    ag_gen_facade_options o = {.cols = 6, .rows = 4, .side_cols = 3, .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    ag_proceduralize_result *r = run(m);
    const ag_grammar *g = r->grammar;
    /* the window rule is the only rule, applied as two subdivides in the axiom */
    assert_int_equal(g->nrules, 1);
    const char *rule = g->rules[0].name;
    size_t subdivides = 0;
    int seen_front = 0, seen_side = 0, rot_front = -1, rot_side = -1;
    for (size_t i = 0; i < g->axiom.nstmts; i++) {
        const ag_gstmt *s = &g->axiom.stmts[i];
        if (s->kind != AG_GSTMT_APPLY || !s->subdivide)
            continue;
        assert_string_equal(s->callee, rule);
        subdivides++;
        if (s->counts[0] == 6 && s->counts[1] == 1 && s->counts[2] == 4) {
            seen_front = 1;
            rot_front = s->rot;
            assert_true(fabs(s->step[0] - 2.5) < 1e-9 && fabs(s->step[2] - 3.2) < 1e-9);
        }
        if (s->counts[0] == 1 && s->counts[1] == 3 && s->counts[2] == 4) {
            seen_side = 1;
            rot_side = s->rot;
            assert_true(fabs(s->step[1] - 2.5) < 1e-9);
        }
    }
    assert_int_equal(subdivides, 2);
    assert_true(seen_front && seen_side);
    /* the side facade reuses the rule turned by a quarter */
    assert_int_equal((rot_side - rot_front) & 3, 1);
    /* the rule places the window terminal; the annex terminal is placed once, directly */
    assert_int_equal(g->rules[0].nstmts, 1);
    size_t annex_c = SIZE_MAX;
    for (size_t c = 0; c < r->mesh->ncomponents; c++) {
        int32_t gi = r->mesh->component_group[c];
        if (gi >= 0 && !strcmp(r->mesh->group_names[gi], "annex"))
            annex_c = c;
    }
    assert_true(annex_c != SIZE_MAX);
    int32_t at = r->info.terminal_of_variant[r->labels->variant[annex_c]];
    assert_int_equal(applications(&g->axiom, g->terminals[at].name, NULL), 1);
    assert_int_equal(r->tree->npatterns, 2);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

/* Frames with a pane nested inside: the subtree (frame + pane) is the rule. */
static ag_mesh *framed_grid(int odd_one)
{
    ag_mesh *m = ag_mesh_create();
    add_box(m, 0, 0, 0, 12, 0.4, 10, "wall");
    char name[32];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 4; i++) {
            double x = 1 + 2.5 * i, z = 1 + 3 * j;
            snprintf(name, sizeof name, "frame_%d_%d", i, j);
            add_box(m, x, 0.05, z, x + 1.5, 0.3, z + 2, name);
            snprintf(name, sizeof name, "pane_%d_%d", i, j);
            double w = odd_one && i == 2 && j == 1 ? 0.9 : 1.1;
            add_box(m, x + 0.2, 0.1, z + 0.2, x + 0.2 + w, 0.2, z + 1.8, name);
        }
    return m;
}

static void test_nested_subtree_becomes_the_rule(void **state)
{
    (void)state;
    ag_mesh *m = framed_grid(0);
    ag_proceduralize_result *r = run(m);
    const ag_grammar *g = r->grammar;
    assert_int_equal(g->nrules, 1);
    const ag_grule *rule = &g->rules[0];
    /* T_frame(p), a split or two, T_pane(n) */
    size_t splits = 0, terms = 0;
    for (size_t i = 0; i < rule->nstmts; i++)
        rule->stmts[i].kind == AG_GSTMT_SPLIT ? splits++ : terms++;
    assert_int_equal(terms, 2);
    assert_true(splits >= 1 && splits <= 2);
    assert_true(fabs(rule->size[0] - 1.5) < 1e-12 && fabs(rule->size[2] - 2) < 1e-12);
    const ag_gstmt *s = NULL;
    size_t uses = 0;
    /* the pattern hangs under the wall, inside the axiom */
    uses = applications(&g->axiom, rule->name, &s);
    assert_int_equal(uses, 1);
    assert_true(s->subdivide);
    assert_int_equal(s->counts[0], 4);
    assert_int_equal(s->counts[1], 1);
    assert_int_equal(s->counts[2], 3);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

static void test_irregular_rows_and_odd_subtree(void **state)
{
    (void)state;
    /* one pane differs: its frame's subtree gets another rule, the grid breaks into rows */
    ag_mesh *m = framed_grid(1);
    ag_proceduralize_result *r = run(m);
    const ag_grammar *g = r->grammar;
    const char *rule = NULL;
    for (size_t i = 0; i < g->nrules; i++)
        if (applications(&g->axiom, g->rules[i].name, NULL) >= 2)
            rule = g->rules[i].name;
    assert_non_null(rule);
    size_t rows = 0, singles = 0, lens[8] = {0};
    for (size_t i = 0; i < g->axiom.nstmts; i++) {
        const ag_gstmt *s = &g->axiom.stmts[i];
        if (s->kind != AG_GSTMT_APPLY || strcmp(s->callee, rule))
            continue;
        if (s->subdivide) {
            assert_int_equal(s->subdivide, 1); /* axis-aligned rows stay subdivides */
            assert_int_equal(s->counts[1] * s->counts[2], 1);
            assert_true(fabs(s->step[0] - 2.5) < 1e-9);
            if (rows < 8)
                lens[rows] = s->counts[0];
            rows++;
        } else {
            singles++;
        }
    }
    /* rows 0 and 2 are complete; row 1 keeps the run before the odd frame, the frame after
     * it is a single application */
    assert_int_equal(rows, 3);
    assert_int_equal(lens[0] + lens[1] + lens[2], 10);
    assert_true((lens[0] == 2) + (lens[1] == 2) + (lens[2] == 2) == 1);
    assert_int_equal(singles, 1);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

/* A facade turned 30 degrees about z: windows repeat along an oblique direction. */
static void test_oblique_facade_is_a_lattice(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    const double c = cos(M_PI / 6), s = sin(M_PI / 6);
    char name[32];
    size_t comp = 0;
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 5; i++) {
            /* a small wedge (not a box, so the turn matters), placed along the facade */
            size_t g;
            snprintf(name, sizeof name, "window_%d_%d", i, j);
            ag_mesh_add_group(m, name, &g);
            ag_mesh_add_component(m, (int32_t)g, &comp);
            double ox = 3.0 * i * c, oy = 3.0 * i * s, oz = 4.0 * j;
            uint32_t b = (uint32_t)m->nverts;
            const double lp[4][3] = {{0, 0, 0}, {1.2, 0, 0}, {0, 0.3, 0}, {0, 0, 1.8}};
            for (int k = 0; k < 4; k++)
                ag_mesh_add_vertex(m, ox + lp[k][0], oy + lp[k][1], oz + lp[k][2]);
            ag_mesh_add_triangle(m, b, b + 2, b + 1, (uint32_t)comp);
            ag_mesh_add_triangle(m, b, b + 1, b + 3, (uint32_t)comp);
            ag_mesh_add_triangle(m, b, b + 3, b + 2, (uint32_t)comp);
            ag_mesh_add_triangle(m, b + 1, b + 2, b + 3, (uint32_t)comp);
        }
    ag_proceduralize_result *r = run(m);
    const ag_grammar *g = r->grammar;
    assert_int_equal(g->nrules, 1);
    const ag_gstmt *st = NULL;
    assert_int_equal(applications(&g->axiom, g->rules[0].name, &st), 1);
    assert_int_equal(st->subdivide, 2);
    assert_int_equal(st->nvec, 2);
    assert_int_equal(st->counts[0] * st->counts[1], 15);
    /* one vector is the oblique step (3 cos 30, 3 sin 30, 0), the other (0, 0, 4) */
    int oblique = 0, up = 0;
    for (int k = 0; k < 2; k++) {
        const double *v = st->vec[k];
        if (fabs(v[0] - 3 * c) < 1e-9 && fabs(v[1] - 3 * s) < 1e-9 && fabs(v[2]) < 1e-9)
            oblique = st->counts[k] == 5;
        if (fabs(v[0]) < 1e-9 && fabs(v[1]) < 1e-9 && fabs(v[2] - 4) < 1e-9)
            up = st->counts[k] == 3;
    }
    assert_true(oblique && up);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

static void test_no_repetition_gives_no_rule(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    for (int i = 0; i < 5; i++)
        add_box(m, 3.0 * i, 0, 0, 3.0 * i + 1 + 0.1 * i, 1, 2 + 0.3 * i, NULL);
    ag_proceduralize_result *r = run(m);
    assert_int_equal(r->grammar->nrules, 0);
    assert_int_equal(r->tree->npatterns, 0);
    assert_int_equal(r->grammar->nterminals, 5);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_window_grid_is_one_rule_subdivided),
        cmocka_unit_test(test_nested_subtree_becomes_the_rule),
        cmocka_unit_test(test_irregular_rows_and_odd_subtree),
        cmocka_unit_test(test_oblique_facade_is_a_lattice),
        cmocka_unit_test(test_no_repetition_gives_no_rule),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
