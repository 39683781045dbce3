/* Grammar text: canonical printing, parse errors with line and column, terminal files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/grammar_text.h"
#include "io/terminals.h"

#define DATA AG_REPO_DIR "/tests/data/proc"

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)n + 1);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    b[n] = 0;
    fclose(f);
    *len = (size_t)n;
    return b;
}

static void test_canonical_text_round_trips(void **state)
{
    (void)state;
    size_t len;
    char *src = slurp(DATA "/canonical.txt", &len);
    ag_grammar *g;
    ag_error err = {0};
    long col;
    assert_int_equal(ag_grammar_text_parse(src, len, &g, &err, &col), AG_OK);
    assert_int_equal(g->nterminals, 2);
    assert_int_equal(g->nrules, 1);
    assert_int_equal(g->axiom.nstmts, 7);
    const ag_gstmt *rep = &g->axiom.stmts[6];
    assert_int_equal(rep->subdivide, 2);
    assert_int_equal(rep->nvec, 2);
    assert_int_equal(rep->rot, 3);
    assert_true(rep->vec[0][1] == 0.001 && rep->vec[1][2] == 2);
    char *out;
    size_t olen;
    assert_int_equal(ag_grammar_text_print(g, &out, &olen, NULL), AG_OK);
    assert_int_equal(olen, len);
    assert_memory_equal(out, src, len);
    /* the fixture derives: 12 + 4 cells of R1, 2 wedges each, plus one wedge */
    assert_int_equal(ag_terminals_load(g, DATA, &err), AG_OK);
    ag_mesh *d;
    assert_int_equal(ag_grammar_derive(g, NULL, &d, &err), AG_OK);
    assert_int_equal(d->ntris, (16 * 2 + 1) * 4);
    ag_mesh_free(d);
    free(out);
    ag_grammar_free(g);

    /* comments, other spacing and "-0" print canonically */
    const char *loose = "archgram-grammar 1 # header\n"
                        "terminal T1 \"terminals/wedge.obj\" size 1.000 2 1e0\n"
                        "axiom box -0 0 0 1 2 1 { n1 = split(p,0,0,0,1) T1(n1) rot 0 }\n";
    assert_int_equal(ag_grammar_text_parse(loose, strlen(loose), &g, &err, &col), AG_OK);
    assert_int_equal(ag_grammar_text_print(g, &out, &olen, NULL), AG_OK);
    const char *want = "archgram-grammar 1\n\n"
                       "terminal T1 \"terminals/wedge.obj\" size 1 2 1\n\n"
                       "axiom box 0 0 0 1 2 1 {\n  n1 = split(p, 0, 0, 0, 1)\n  T1(n1)\n}\n";
    assert_string_equal(out, want);
    free(out);
    ag_grammar_free(g);
    free(src);
}

/* Every number of a grammar nudged off its printed digits (a fraction of an ulp of the 12th
 * digit, either way, and -0): the grammar rounded (ag_grammar_text_round) is the grammar its
 * printed text parses into, number for number, bit for bit. A number the printer prints and
 * the rounding misses fails here. */
static double nudged(double v, unsigned k)
{
    static const double by[4] = {1 + 3.3e-14, 1 - 4.1e-14, 1 + 1.7e-15, 1 - 2.9e-13};
    return v == 0 ? (k & 1 ? -0.0 : 1e-19) : v * by[k & 3] + (k & 4 ? 1.0 / 3.0 : 0);
}

static void nudge(double *v, int n, unsigned *k)
{
    for (int i = 0; i < n; i++)
        v[i] = nudged(v[i], (*k)++);
}

static void nudge_body(ag_grule *r, unsigned *k)
{
    for (size_t i = 0; i < r->nstmts; i++) {
        ag_gstmt *t = &r->stmts[i];
        nudge(t->v, 3, k);
        nudge(t->step, 3, k);
        for (int a = 0; a < 3; a++)
            nudge(t->vec[a], 3, k);
    }
}

static void same_numbers(const double *a, const double *b, int n, const char *what, size_t at)
{
    for (int i = 0; i < n; i++)
        if (memcmp(&a[i], &b[i], sizeof a[i]))
            fail_msg("%s %zu [%d]: rounded %.17g, read back %.17g", what, at, i, a[i], b[i]);
}

static void same_body(const ag_grule *a, const ag_grule *b, const char *what)
{
    assert_int_equal(a->nstmts, b->nstmts);
    for (size_t i = 0; i < a->nstmts; i++) {
        const ag_gstmt *x = &a->stmts[i], *y = &b->stmts[i];
        assert_int_equal(x->kind, y->kind);
        assert_int_equal(x->subdivide, y->subdivide);
        if (x->kind == AG_GSTMT_SPLIT)
            same_numbers(x->v, y->v, 3, what, i);
        else if (x->subdivide == 2)
            for (int v = 0; v < x->nvec; v++)
                same_numbers(x->vec[v], y->vec[v], 3, what, i);
        else if (x->subdivide)
            same_numbers(x->step, y->step, 3, what, i);
    }
}

static void test_rounding_is_the_printed_text(void **state)
{
    (void)state;
    size_t len;
    char *src = slurp(DATA "/canonical.txt", &len);
    ag_grammar *g, *back;
    ag_error err = {0};
    long col;
    assert_int_equal(ag_grammar_text_parse(src, len, &g, &err, &col), AG_OK);
    unsigned k = 0;
    for (size_t i = 0; i < g->nterminals; i++)
        nudge(g->terminals[i].size, 3, &k);
    for (size_t i = 0; i < g->nrules; i++) {
        nudge(g->rules[i].size, 3, &k);
        nudge_body(&g->rules[i], &k);
    }
    nudge(g->axiom.box.min, 3, &k);
    nudge(g->axiom.box.max, 3, &k);
    nudge_body(&g->axiom, &k);
    char *out;
    size_t olen;
    assert_int_equal(ag_grammar_text_print(g, &out, &olen, NULL), AG_OK);
    assert_int_equal(ag_grammar_text_parse(out, olen, &back, &err, &col), AG_OK);
    ag_grammar_text_round(g);
    assert_int_equal(g->nterminals, back->nterminals);
    for (size_t i = 0; i < g->nterminals; i++)
        same_numbers(g->terminals[i].size, back->terminals[i].size, 3, "terminal", i);
    assert_int_equal(g->nrules, back->nrules);
    for (size_t i = 0; i < g->nrules; i++) {
        same_numbers(g->rules[i].size, back->rules[i].size, 3, "rule size", i);
        same_body(&g->rules[i], &back->rules[i], "rule statement");
    }
    same_numbers(g->axiom.box.min, back->axiom.box.min, 3, "axiom box min", 0);
    same_numbers(g->axiom.box.max, back->axiom.box.max, 3, "axiom box max", 0);
    same_body(&g->axiom, &back->axiom, "axiom statement");
    /* and it prints the same text again */
    char *again;
    size_t alen;
    assert_int_equal(ag_grammar_text_print(g, &again, &alen, NULL), AG_OK);
    assert_int_equal(alen, olen);
    assert_memory_equal(again, out, olen);
    free(again);
    free(out);
    ag_grammar_free(back);
    ag_grammar_free(g);
    free(src);
}

static void expect_error(const char *text, long line, long col, const char *needle)
{
    ag_grammar *g = (ag_grammar *)1;
    ag_error err = {0};
    long c = -1;
    assert_int_equal(ag_grammar_text_parse(text, strlen(text), &g, &err, &c), AG_ERR_PARSE);
    assert_null(g);
    if (err.element != line || c != col || !strstr(err.text, needle))
        fail_msg("got %ld:%ld: %s, want %ld:%ld: ...%s...", err.element, c, err.text, line, col,
                 needle);
}

static void test_errors_have_line_and_column(void **state)
{
    (void)state;
    const char *h = "archgram-grammar 1\n";
    char buf[512];
    expect_error("grammar 1\n", 1, 1, "header");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  T9(p)\n}\n", h);
    expect_error(buf, 3, 3, "'T9' is neither a terminal nor a rule");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  n1 = split(q, 0, 0, 0, 1)\n}\n", h);
    expect_error(buf, 3, 3, "node 'q' is not defined");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  n1 = split(p, 0, 0, 0, 9)\n}\n", h);
    expect_error(buf, 3, 26, "octant");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  n1 = split(p, nan, 0, 0, 1)\n}\n", h);
    expect_error(buf, 3, 17, "expected a number");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  n1 = split(p, 1e999, 0, 0, 1)\n}\n", h);
    expect_error(buf, 3, 17, "not a finite number");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n  n1 = split(p, 0, 0, 0, 1)\n", h);
    expect_error(buf, 4, 1, "missing '}'");
    snprintf(buf, sizeof buf,
             "%srule A size 1 1 1 {\n  B(p)\n}\nrule B size 1 1 1 {\n}\naxiom box 0 0 0 1 1 1 {\n}\n",
             h);
    expect_error(buf, 3, 3, "rule 'B' is used before it is declared");
    snprintf(buf, sizeof buf,
             "%srule R size 1 1 1 {\n}\naxiom box 0 0 0 1 1 1 {\n  R(repeat(p))\n}\n", h);
    expect_error(buf, 5, 13, "repeat needs a count and a vector");
    snprintf(buf, sizeof buf,
             "%srule R size 1 1 1 {\n}\naxiom box 0 0 0 1 1 1 {\n  R(repeat(p, 0, 1, 0, 0))\n}\n", h);
    expect_error(buf, 5, 15, "count");
    snprintf(buf, sizeof buf, "%saxiom box 0 0 0 1 1 1 {\n}\nextra\n", h);
    expect_error(buf, 4, 1, "expected end of file");
    snprintf(buf, sizeof buf, "%sterminal T1 \"x.obj size 1 1 1\n", h);
    expect_error(buf, 2, 13, "unterminated string");
    size_t len;
    char *src = slurp(DATA "/bad_rot.txt", &len);
    ag_grammar *g;
    ag_error err = {0};
    long col;
    assert_int_equal(ag_grammar_text_parse(src, len, &g, &err, &col), AG_ERR_PARSE);
    assert_int_equal(err.element, 6);
    assert_int_equal(col, 13);
    free(src);
}

static void test_terminal_paths_cannot_escape(void **state)
{
    (void)state;
    ag_grammar *g;
    ag_error err = {0};
    long col;
    assert_int_equal(ag_grammar_text_read_file(DATA "/escape.txt", &g, &err, &col), AG_OK);
    assert_int_equal(ag_terminals_load(g, DATA, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "unsafe"));
    free(g->terminals[0].path);
    g->terminals[0].path = strdup("/etc/passwd");
    assert_int_equal(ag_terminals_load(g, DATA, &err), AG_ERR_INVALID);
    ag_grammar_free(g);
}

static void test_exported_grammar_round_trips_through_files(void **state)
{
    (void)state;
    ag_mesh *m;
    ag_gen_facade_options o = {.cols = 4, .rows = 3, .side_cols = 2, .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    ag_proceduralize_result *r;
    assert_int_equal(ag_proceduralize_run(m, NULL, &r, NULL), AG_OK);
    char dir[] = "/tmp/archgram_test_grammar_XXXXXX";
    assert_non_null(mkdtemp(dir));
    /* two terminals with the same geometry share one file */
    size_t extra;
    ag_gterminal *t0 = &r->grammar->terminals[0];
    double size[3] = {t0->size[0], t0->size[1], t0->size[2]};
    assert_int_equal(ag_grammar_add_terminal(r->grammar, "Tcopy", size, &extra), AG_OK);
    t0 = &r->grammar->terminals[0];
    assert_int_equal(ag_grammar_set_terminal_geometry(&r->grammar->terminals[extra], t0->pos,
                                                      t0->nverts, t0->tri, t0->ntris),
                     AG_OK);
    size_t bytes;
    assert_int_equal(ag_terminals_write(r->grammar, dir, &bytes, NULL), AG_OK);
    assert_string_equal(r->grammar->terminals[extra].path, r->grammar->terminals[0].path);
    size_t sum = 0;
    for (size_t i = 0; i < r->grammar->nterminals; i++) {
        if (i == extra)
            continue;
        char *txt;
        size_t n;
        assert_int_equal(ag_terminals_format(&r->grammar->terminals[i], &txt, &n, NULL), AG_OK);
        sum += n;
        free(txt);
    }
    assert_int_equal(bytes, sum);

    char *text;
    size_t len;
    assert_int_equal(ag_grammar_text_print(r->grammar, &text, &len, NULL), AG_OK);
    ag_grammar *back;
    ag_error err = {0};
    long col;
    assert_int_equal(ag_grammar_text_parse(text, len, &back, &err, &col), AG_OK);
    char *again;
    size_t alen;
    assert_int_equal(ag_grammar_text_print(back, &again, &alen, NULL), AG_OK);
    assert_int_equal(alen, len);
    assert_memory_equal(again, text, len);
    assert_int_equal(ag_terminals_load(back, dir, &err), AG_OK);
    /* the same geometry from memory */
    {
        char *txt;
        size_t n;
        assert_int_equal(ag_terminals_format(&back->terminals[0], &txt, &n, NULL), AG_OK);
        ag_gterminal copy = {.name = "copy"};
        assert_int_equal(ag_terminals_load_buffer(&copy, txt, n, &err), AG_OK);
        assert_int_equal(copy.ntris, back->terminals[0].ntris);
        assert_int_equal(copy.nverts, back->terminals[0].nverts);
        assert_memory_equal(copy.tri, back->terminals[0].tri, 3 * copy.ntris * sizeof *copy.tri);
        free(copy.pos);
        free(copy.tri);
        assert_int_equal(ag_terminals_load_buffer(&copy, "v 0 0 0\nf 1 2 3\n", 16, &err),
                         AG_ERR_PARSE);
        free(txt);
    }
    ag_mesh *d;
    assert_int_equal(ag_grammar_derive(back, NULL, &d, &err), AG_OK);
    ag_fidelity f;
    assert_int_equal(ag_grammar_fidelity(m, d, 0, &f, NULL), AG_OK);
    assert_int_equal(f.unmatched, 0);
    assert_true(f.relative < 1e-8); /* printed with 10-12 significant digits */
    ag_mesh_free(d);
    ag_grammar_free(back);
    free(text);
    free(again);
    for (size_t i = 0; i < r->grammar->nterminals; i++) {
        char p[512];
        snprintf(p, sizeof p, "%s/%s", dir, r->grammar->terminals[i].path);
        unlink(p);
    }
    char p[512];
    snprintf(p, sizeof p, "%s/terminals", dir);
    rmdir(p);
    rmdir(dir);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_canonical_text_round_trips),
        cmocka_unit_test(test_rounding_is_the_printed_text),
        cmocka_unit_test(test_errors_have_line_and_column),
        cmocka_unit_test(test_terminal_paths_cannot_escape),
        cmocka_unit_test(test_exported_grammar_round_trips_through_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
