/* Proportions and counts (core/parts/fit.h, fitcount.h) on small bodies written as grammar
 * text: a row of windows fitted into a shorter or longer box holds more or fewer windows at
 * their own width and period; a row of thin posts is spaced out, never added to; two windows
 * are no lattice; a count past what a fit takes is refused before anything is made. The
 * derived results of whole compositions are measured in test_parts_compose.c. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/parts/fit.h"
#include "io/grammar_text.h"

/* A wall 0.9 + n windows 1.2 wide every 2.5 m + 0.9 long; a rail of five posts 0.05 wide every
 * 0.7 m. */
static ag_grammar *parse_body(unsigned n)
{
    double L = 1.8 + (n - 1) * 2.5 + 1.2;
    char text[2048];
    snprintf(text, sizeof text,
             "archgram-grammar 1\n\n"
             "terminal W \"\" size %.17g 0.3 7\n"
             "terminal C \"\" size 1.2 0.16 1.8\n"
             "terminal P \"\" size 0.05 0.05 1\n\n"
             "rule facade size %.17g 0.3 7 {\n"
             "  W(p)\n"
             "  a = split(p, 0.9, 0.1, 1, 8)\n"
             "  b = split(a, %.17g, 0.16, 1.8, 1)\n"
             "  C(subdivide(b, %u, 1, 1, 2.5, 0, 0))\n"
             "}\n\n"
             "rule rail size 3 0.05 1 {\n"
             "  a = split(p, 0.1, 0, 0, 8)\n"
             "  b = split(a, 2.85, 0.05, 1, 1)\n"
             "  P(subdivide(b, 5, 1, 1, 0.7, 0, 0))\n"
             "}\n\n"
             "rule grid size 23.7 0.16 11.4 {\n"
             "  C(subdivide(p, 10, 1, 4, 2.5, 0, 3.2))\n"
             "}\n\n"
             "axiom box 0 0 0 %.17g 0.3 7 {\n"
             "  facade(p)\n"
             "}\n",
             L, L, (n - 1) * 2.5 + 1.2, n, L);
    ag_grammar *g = NULL;
    ag_error err = {0};
    long col = 0;
    if (ag_grammar_text_parse(text, strlen(text), &g, &err, &col))
        fail_msg("parse: %ld:%ld: %s", err.element, col, err.text);
    return g;
}

static const ag_grule *rule(const ag_grammar *g, const char *name)
{
    for (size_t i = 0; i < g->nrules; i++)
        if (!strcmp(g->rules[i].name, name))
            return &g->rules[i];
    fail_msg("no rule %s", name);
    return NULL;
}

static void free_body(ag_grule *r)
{
    for (size_t i = 0; i < r->nstmts; i++) {
        free(r->stmts[i].node);
        free(r->stmts[i].parent);
        free(r->stmts[i].callee);
    }
    free(r->stmts);
}

/* The pattern of callee in body r (fitted: not resolved). */
static const ag_gstmt *pattern_of(const ag_grule *r, const char *callee)
{
    for (size_t i = 0; i < r->nstmts; i++)
        if (r->stmts[i].kind == AG_GSTMT_APPLY && r->stmts[i].subdivide &&
            !strcmp(r->stmts[i].callee, callee))
            return &r->stmts[i];
    fail_msg("no pattern of %s", callee);
    return NULL;
}

/* The pattern's min corner along x: the pivot of the split it hangs by (split_to: p -> a -> b). */
static double pattern_min_x(const ag_grule *r, const ag_gstmt *s)
{
    for (size_t i = 0; i < r->nstmts; i++)
        if (r->stmts[i].kind == AG_GSTMT_SPLIT && !strcmp(r->stmts[i].node, s->node))
            for (size_t j = 0; j < r->nstmts; j++)
                if (r->stmts[j].kind == AG_GSTMT_SPLIT &&
                    !strcmp(r->stmts[j].node, r->stmts[i].parent))
                    return r->stmts[j].v[0];
    fail_msg("the pattern's node is not split from p");
    return 0;
}

/* Ten windows into 0.6, 0.77, 1.5 and 2 times the length: round(10 x) windows that fit, still
 * 1.2 wide every 2.5 m, the row inside the box with its margins in proportion. */
static void test_row_of_windows(void **state)
{
    (void)state;
    ag_grammar *g = parse_body(10);
    const ag_grule *f = rule(g, "facade");
    double L = f->size[0];
    const double ratios[] = {0.6, 0.77, 1.5, 2.0};
    const unsigned want[] = {6, 8, 15, 20};
    for (int i = 0; i < 4; i++) {
        double size[3] = {ratios[i] * L, 0.3, 7};
        ag_grule out = {0};
        ag_fit_report rep;
        ag_error err = {0};
        if (ag_fit_body(g, f, size, &out, &rep, &err))
            fail_msg("fit: %s", err.text);
        assert_int_equal(rep.columns[0][0], 10);
        assert_int_equal(rep.columns[0][1], want[i]);
        const ag_gstmt *s = pattern_of(&out, "C");
        assert_int_equal(s->counts[0], want[i]);
        assert_true(fabs(s->step[0] - 2.5) < 1e-9);
        /* the row's extent (from the split that places it) keeps the window 1.2 wide */
        double x0 = pattern_min_x(&out, s), span = (want[i] - 1) * 2.5 + 1.2;
        double room = size[0] - span;
        assert_true(x0 > 0 && x0 + span < size[0]);
        assert_true(fabs(x0 - room / 2) < 1e-9); /* equal margins stay equal */
        free_body(&out);
    }
    ag_grammar_free(g);
}

/* Shorter and taller: the columns re-laid along the length, the height left to the solve
 * (one row: no lattice there), which keeps every coordinate along the length. */
static void test_row_shorter_and_taller(void **state)
{
    (void)state;
    ag_grammar *g = parse_body(10);
    const ag_grule *f = rule(g, "facade");
    double size[3] = {0.77 * f->size[0], 0.3, 8.4};
    ag_grule out = {0};
    ag_fit_report rep;
    ag_error err = {0};
    if (ag_fit_body(g, f, size, &out, &rep, &err))
        fail_msg("fit: %s", err.text);
    assert_int_equal(rep.columns[0][1], 8);
    assert_int_equal(rep.columns[2][1], 0);
    assert_true(rep.equations > 0);
    const ag_gstmt *s = pattern_of(&out, "C");
    assert_int_equal(s->counts[0], 8);
    assert_true(fabs(s->step[0] - 2.5) < 1e-9);
    double x0 = pattern_min_x(&out, s), room = size[0] - (7 * 2.5 + 1.2);
    assert_true(fabs(x0 - room / 2) < 1e-9);
    free_body(&out);
    ag_grammar_free(g);
}

/* Thin posts are spaced out over a rail twice as long, never added to; two windows are no
 * lattice: the solve keeps their count. */
static void test_thin_and_short_rows_keep_counts(void **state)
{
    (void)state;
    ag_grammar *g = parse_body(2);
    double size[3] = {6, 0.05, 1};
    ag_grule out = {0};
    ag_fit_report rep;
    ag_error err = {0};
    assert_int_equal(ag_fit_body(g, rule(g, "rail"), size, &out, &rep, &err), AG_OK);
    assert_int_equal(rep.columns[0][1], 0);
    assert_int_equal(pattern_of(&out, "P")->counts[0], 5);
    free_body(&out);
    const ag_grule *f = rule(g, "facade");
    double wide[3] = {2 * f->size[0], 0.3, 7};
    memset(&out, 0, sizeof out);
    assert_int_equal(ag_fit_body(g, f, wide, &out, &rep, &err), AG_OK);
    assert_int_equal(rep.columns[0][1], 0);
    size_t windows = 0; /* as a pattern of two, or two applications */
    for (size_t i = 0; i < out.nstmts; i++)
        if (out.stmts[i].kind == AG_GSTMT_APPLY && !strcmp(out.stmts[i].callee, "C"))
            windows += out.stmts[i].subdivide ? out.stmts[i].counts[0] : 1;
    assert_int_equal(windows, 2);
    free_body(&out);
    ag_grammar_free(g);
}

/* A grid of 10 x 4 windows (no margins) into 0.77 of its length and half its height: both
 * axes re-laid, 7 columns (8 at 2.5 m would need 18.7 m of the 18.25) and 2 rows, the
 * windows' size and periods kept, nothing left to solve. */
static void test_grid_both_axes(void **state)
{
    (void)state;
    ag_grammar *g = parse_body(10);
    const ag_grule *r = rule(g, "grid");
    double size[3] = {0.77 * r->size[0], 0.16, 0.5 * r->size[2]};
    ag_grule out = {0};
    ag_fit_report rep;
    ag_error err = {0};
    if (ag_fit_body(g, r, size, &out, &rep, &err))
        fail_msg("fit: %s", err.text);
    assert_int_equal(rep.columns[0][0], 10);
    assert_int_equal(rep.columns[0][1], 7);
    assert_int_equal(rep.columns[2][0], 4);
    assert_int_equal(rep.columns[2][1], 2);
    assert_int_equal(rep.equations, 0); /* no solve */
    const ag_gstmt *s = pattern_of(&out, "C");
    assert_int_equal(s->counts[0], 7);
    assert_int_equal(s->counts[2], 2);
    assert_true(fabs(s->step[0] - 2.5) < 1e-9 && fabs(s->step[2] - 3.2) < 1e-9);
    free_body(&out);
    ag_grammar_free(g);
}

/* A row stretched 30000 times would hold 300000 windows: refused, naming the columns. */
static void test_too_many_columns(void **state)
{
    (void)state;
    ag_grammar *g = parse_body(10);
    const ag_grule *f = rule(g, "facade");
    double size[3] = {30000 * f->size[0], 0.3, 7};
    ag_grule out = {0};
    ag_fit_report rep;
    ag_error err = {0};
    assert_int_equal(ag_fit_body(g, f, size, &out, &rep, &err), AG_ERR_TOO_LARGE);
    assert_non_null(strstr(err.text, "columns"));
    free_body(&out);
    ag_grammar_free(g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_row_of_windows),
        cmocka_unit_test(test_thin_and_short_rows_keep_counts),
        cmocka_unit_test(test_row_shorter_and_taller),
        cmocka_unit_test(test_grid_both_axes),
        cmocka_unit_test(test_too_many_columns),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
