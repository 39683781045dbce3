/* Part bundles (io/part_bundle.c): a round trip that composes the same as the original, and
 * bad bundles refused whole with the element named. */
#include <jansson.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

#include "core/parts/compose.h"
#include "core/parts/part.h"
#include "io/grammar_text.h"
#include "io/part_bundle.h"
#include "io/sha256.h"
#include "parts_fixture.h"

#define TOL 1e-6

static ag_part *P[2];
static ag_proceduralize_result *B;
static ag_mesh *MB;
static ag_box *SB;
static size_t NSB;

static ag_part *save(const pf_options *o, int which, const char *name)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(o, &slots, &ns);
    ag_proceduralize_result *r = pf_proc(m);
    int32_t node = pf_node_with_box(r, &slots[which], TOL);
    const char *tags[] = {"window", "sash"};
    ag_part_meta meta = {.name = name, .description = "a sash window", .tags = tags, .ntags = 2,
                         .source = "generated A", .source_version = 3};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(r, node, &meta, &p, &err))
        fail_msg("extract: %s", err.text);
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return p;
}

static int setup(void **state)
{
    (void)state;
    pf_options a = {.cols = 3, .rows = 2, .ww = 1.2, .wh = 1.8, .frame = 0.08, .mullions = 1};
    pf_options c = {.cols = 2, .rows = 2, .ww = 1.0, .wh = 1.5, .frame = 0.06, .mullions = 3,
                    .depth = PF_PROUD, .turn = 1};
    P[0] = save(&a, 0, "sash window");
    P[1] = save(&c, 1, "triple mullion");
    pf_options b = {.cols = 4, .rows = 3, .side_cols = 2, .ww = 1.6, .wh = 2.0, .frame = 0.12,
                    .mullions = 2};
    MB = pf_building(&b, &SB, &NSB);
    B = pf_proc(MB);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    ag_part_free(P[0]);
    ag_part_free(P[1]);
    ag_proceduralize_result_free(B);
    ag_mesh_free(MB);
    free(SB);
    return 0;
}

static char *print(const ag_grammar *g)
{
    char *t = NULL;
    size_t n;
    assert_int_equal(ag_grammar_text_print(g, &t, &n, NULL), AG_OK);
    return t;
}

static char *bundle_text(void)
{
    char *text = NULL;
    size_t len = 0;
    ag_error err = {0};
    if (ag_part_bundle_write((const ag_part *const *)P, 2, &text, &len, &err))
        fail_msg("write: %s", err.text);
    return text;
}

static char *compose_text(const ag_part *p)
{
    ag_compose_op op = {.target = pf_node_with_box(B, &SB[4], TOL), .mode = AG_COMPOSE_REPLACE,
                        .scope = AG_COMPOSE_RULE};
    ag_grammar *g = NULL;
    ag_error err = {0};
    if (ag_compose(B, p, &op, &g, NULL, &err))
        fail_msg("compose: %s", err.text);
    /* where terminal files go is the writer's business (ag_terminals_write names them) */
    for (size_t i = 0; i < g->nterminals; i++) {
        free(g->terminals[i].path);
        g->terminals[i].path = NULL;
    }
    char *t = print(g);
    ag_grammar_free(g);
    return t;
}

static void test_roundtrip(void **state)
{
    (void)state;
    char *text = bundle_text();
    ag_part **parts = NULL;
    size_t n = 0;
    ag_error err = {0};
    if (ag_part_bundle_read(text, strlen(text), &parts, &n, &err))
        fail_msg("read: %s", err.text);
    assert_int_equal(n, 2);
    for (size_t i = 0; i < 2; i++) {
        const ag_part *a = P[i], *b = parts[i];
        assert_string_equal(a->name, b->name);
        assert_string_equal(a->description, b->description);
        assert_int_equal(a->ntags, b->ntags);
        assert_string_equal(a->tags[1], b->tags[1]);
        assert_string_equal(a->source, b->source);
        assert_int_equal(a->source_version, b->source_version);
        assert_int_equal(a->source_node, b->source_node);
        assert_int_equal(a->version, b->version);
        assert_int_equal(a->facing, b->facing);
        assert_string_equal(a->root, b->root);
        assert_memory_equal(&a->box, &b->box, sizeof a->box);
        assert_int_equal(a->nnodes, b->nnodes);
        for (size_t k = 0; k < a->nnodes; k++) {
            assert_int_equal(a->nodes[k].parent, b->nodes[k].parent);
            assert_int_equal(a->nodes[k].kind, b->nodes[k].kind);
            assert_string_equal(a->nodes[k].rule, b->nodes[k].rule);
            for (int c = 0; c < 6; c++)
                assert_true(a->nodes[k].box[c] == b->nodes[k].box[c]);
        }
        assert_int_equal(a->nattrs, b->nattrs);
        /* the same grammar and geometry: derived meshes agree to the terminals' 10 digits */
        ag_mesh *da = NULL, *db = NULL;
        assert_int_equal(ag_grammar_derive(a->grammar, NULL, &da, NULL), AG_OK);
        assert_int_equal(ag_grammar_derive(b->grammar, NULL, &db, NULL), AG_OK);
        assert_int_equal(da->ntris, db->ntris);
        for (size_t v = 0; v < 3 * da->nverts; v++)
            assert_true(fabs(da->pos[v] - db->pos[v]) < 1e-8);
        ag_mesh_free(da);
        ag_mesh_free(db);
        /* and it composes the same */
        char *ca = compose_text(a), *cb = compose_text(b);
        assert_string_equal(ca, cb);
        free(ca);
        free(cb);
    }
    /* the terminals are content-addressed: every key is the hash of its text */
    json_t *j = json_loads(text, 0, NULL);
    const char *key;
    json_t *val;
    json_object_foreach(json_object_get(j, "terminals"), key, val) {
        char hex[AG_SHA256_HEX];
        assert_int_equal(ag_sha256_hex(json_string_value(val), json_string_length(val), hex, NULL), AG_OK);
        assert_string_equal(hex, key);
    }
    json_decref(j);
    ag_part_bundle_free(parts, n);
    free(text);
}

/* Reads the JSON text j (dumped) and expects failure code with every needle in the message. */
static void expect_refused(json_t *j, ag_status code, const char *needle, const char *needle2)
{
    char *s = json_dumps(j, 0);
    ag_part **parts = (ag_part **)1;
    size_t n = 99;
    ag_error err = {0};
    ag_status st = ag_part_bundle_read(s, strlen(s), &parts, &n, &err);
    if (st != code)
        fail_msg("expected %s, got %s: %s", ag_status_name(code), ag_status_name(st), err.text);
    assert_null(parts);
    assert_int_equal(n, 0);
    if (!strstr(err.text, needle) || (needle2 && !strstr(err.text, needle2)))
        fail_msg("message '%s' lacks '%s' / '%s'", err.text, needle, needle2 ? needle2 : "");
    free(s);
    json_decref(j);
}

static json_t *fresh(void)
{
    char *text = bundle_text();
    json_t *j = json_loads(text, 0, NULL);
    free(text);
    return j;
}

static json_t *part0(json_t *j) { return json_array_get(json_object_get(j, "parts"), 0); }

static char *replace(const char *s, const char *from, const char *to)
{
    const char *at = strstr(s, from);
    assert_non_null(at);
    size_t n = strlen(s) - strlen(from) + strlen(to);
    char *o = malloc(n + 1);
    memcpy(o, s, (size_t)(at - s));
    strcpy(o + (at - s), to);
    strcat(o, at + strlen(from));
    return o;
}

static void set_grammar(json_t *j, const char *g)
{
    json_object_set_new(part0(j), "grammar", json_string(g));
}

static void test_bad_json(void **state)
{
    (void)state;
    char *text = bundle_text();
    ag_part **parts = NULL;
    size_t n = 0;
    ag_error err = {0};
    assert_int_equal(ag_part_bundle_read(text, strlen(text) / 2, &parts, &n, &err), AG_ERR_PARSE);
    assert_non_null(strstr(err.text, "line"));
    assert_true(err.element > 0);
    assert_null(parts);
    free(text);
    json_t *j = fresh();
    json_object_set_new(j, "format", json_string("something else"));
    expect_refused(j, AG_ERR_UNSUPPORTED, "format", NULL);
    j = fresh();
    json_object_set_new(j, "version", json_integer(2));
    expect_refused(j, AG_ERR_UNSUPPORTED, "version", NULL);
    j = fresh();
    json_object_set_new(j, "parts", json_array());
    expect_refused(j, AG_ERR_INVALID, "parts", NULL);
}

static void test_missing_and_tampered_terminal(void **state)
{
    (void)state;
    json_t *j = fresh();
    json_t *terms = json_object_get(j, "terminals");
    const char *g = json_string_value(json_object_get(part0(j), "grammar"));
    const char *at = strstr(g, "terminals/");
    char key[65];
    memcpy(key, at + 10, 64);
    key[64] = 0;
    json_object_del(terms, key);
    expect_refused(j, AG_ERR_NOT_FOUND, "parts[0].grammar", key);

    j = fresh();
    terms = json_object_get(j, "terminals");
    const char *k;
    json_t *v;
    json_object_foreach(terms, k, v) {
        char *t = replace(json_string_value(v), "v ", "v 9");
        json_object_set_new(terms, k, json_string(t));
        free(t);
        break;
    }
    expect_refused(j, AG_ERR_INVALID, "does not match its hash", NULL);

    /* a path instead of a key */
    j = fresh();
    g = json_string_value(json_object_get(part0(j), "grammar"));
    at = strstr(g, "\"terminals/");
    char *bad = malloc(strlen(g) + 1);
    memcpy(bad, g, (size_t)(at - g));
    strcpy(bad + (at - g), "\"/etc/passwd\"");
    strcat(bad, at + 1 + 10 + 64 + 4 + 1);
    set_grammar(j, bad);
    free(bad);
    expect_refused(j, AG_ERR_INVALID, "/etc/passwd", "not a terminal of the bundle");
}

static void test_bad_terminal_obj(void **state)
{
    (void)state;
    json_t *j = fresh();
    const char *obj = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 7\n";
    char hex[AG_SHA256_HEX];
    assert_int_equal(ag_sha256_hex(obj, strlen(obj), hex, NULL), AG_OK);
    json_object_set_new(json_object_get(j, "terminals"), hex, json_string(obj));
    expect_refused(j, AG_ERR_PARSE, hex, "line 4");
}

static void test_cyclic_and_bad_names(void **state)
{
    (void)state;
    json_t *j = fresh();
    const char *g = json_string_value(json_object_get(part0(j), "grammar"));
    /* the first rule applies the part's root, which applies it back */
    const char *root = json_string_value(json_object_get(part0(j), "root"));
    const char *r1 = strstr(g, "\nrule ");
    assert_non_null(r1);
    const char *brace = strchr(r1, '{');
    char call[96];
    snprintf(call, sizeof call, "{\n  %s(p)", root);
    char *head = strndup(g, (size_t)(brace - g));
    char *text = malloc(strlen(g) + 100);
    sprintf(text, "%s%s%s", head, call, brace + 1);
    set_grammar(j, text);
    free(head);
    free(text);
    expect_refused(j, AG_ERR_INVALID, "parts[0].grammar", "cyclic");

    j = fresh();
    g = json_string_value(json_object_get(part0(j), "grammar"));
    char *t = replace(g, "\nrule ", "\nrule 9");
    set_grammar(j, t);
    free(t);
    expect_refused(j, AG_ERR_PARSE, "parts[0].grammar:", NULL);

    j = fresh();
    json_object_set_new(part0(j), "root", json_string("not an-identifier"));
    expect_refused(j, AG_ERR_INVALID, "parts[0].root", NULL);

    j = fresh();
    json_object_set_new(part0(j), "root", json_string("T1"));
    expect_refused(j, AG_ERR_INVALID, "parts[0]", "root");
}

/* A copy of P[0] moved by (dx, 0, 0): its box and its axiom's box. */
static ag_part *moved(double dx)
{
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_copy(P[0], &p, &err))
        fail_msg("copy: %s", err.text);
    p->box.min[0] += dx;
    p->box.max[0] += dx;
    p->grammar->axiom.box.min[0] += dx;
    p->grammar->axiom.box.max[0] += dx;
    return p;
}

/* What the writer writes the reader reads: a part saved 2e7 m from the origin (web-mercator)
 * reads back where it stood; one past AG_PART_MAX_COORD is refused by the writer, naming the
 * coordinate, and by the reader, whichever wrote it. */
static void test_far_box_round_trips_or_is_refused(void **state)
{
    (void)state;
    assert_true(AG_PART_MAX_COORD >= 1e8);
    ag_part *far = moved(2e7);
    char *text = NULL;
    size_t len = 0;
    ag_error err = {0};
    if (ag_part_bundle_write((const ag_part *const *)&far, 1, &text, &len, &err))
        fail_msg("write: %s", err.text);
    ag_part **parts = NULL;
    size_t n = 0;
    if (ag_part_bundle_read(text, len, &parts, &n, &err))
        fail_msg("read: %s", err.text);
    assert_int_equal(n, 1);
    /* independently of the code: P[0]'s box plus the offset, to the last bit the text holds */
    assert_true(fabs(parts[0]->box.min[0] - (P[0]->box.min[0] + 2e7)) < 1e-8);
    assert_true(fabs(parts[0]->box.max[0] - (P[0]->box.max[0] + 2e7)) < 1e-8);
    assert_true(parts[0]->box.min[0] > 1e7);
    ag_part_bundle_free(parts, n);

    /* the same bundle with its box moved past the bound is refused on reading */
    json_error_t je;
    json_t *j = json_loadb(text, len, 0, &je);
    assert_non_null(j);
    json_t *box = json_object_get(json_array_get(json_object_get(j, "parts"), 0), "box");
    json_array_set_new(box, 3, json_real(1.5e8));
    char *bad = json_dumps(j, 0);
    assert_int_equal(ag_part_bundle_read(bad, strlen(bad), &parts, &n, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "parts[0].box[3]"));
    free(bad);
    json_decref(j);
    free(text);
    ag_part_free(far);

    /* past the bound, saving is refused before anything is written, naming the coordinate */
    ag_part *beyond = moved(1.5e8);
    text = NULL;
    assert_int_equal(ag_part_validate(beyond, &err), AG_ERR_INVALID);
    assert_int_equal(ag_part_bundle_write((const ag_part *const *)&beyond, 1, &text, &len, &err),
                     AG_ERR_INVALID);
    assert_null(text);
    char want[64];
    snprintf(want, sizeof want, "box: min x = %.15g m", P[0]->box.min[0] + 1.5e8);
    if (!strstr(err.text, want) || !strstr(err.text, "beyond"))
        fail_msg("%s (wanted '%s')", err.text, want);
    ag_part_free(beyond);
}

static void test_absurd_sizes(void **state)
{
    (void)state;
    json_t *j = fresh();
    json_t *box = json_object_get(part0(j), "box");
    json_array_set_new(box, 3, json_real(1e30));
    expect_refused(j, AG_ERR_INVALID, "parts[0].box[3]", NULL);

    j = fresh();
    json_object_set_new(part0(j), "facing", json_integer(7));
    expect_refused(j, AG_ERR_INVALID, "parts[0].facing", NULL);

    j = fresh();
    json_t *n0 = json_array_get(json_object_get(part0(j), "nodes"), 1);
    json_object_set_new(n0, "kind", json_string("bogus"));
    expect_refused(j, AG_ERR_INVALID, "parts[0].nodes[1]", NULL);

    j = fresh();
    char big[AG_PART_NAME_MAX + 10];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = 0;
    json_object_set_new(part0(j), "name", json_string(big));
    expect_refused(j, AG_ERR_INVALID, "parts[0].name", NULL);

    /* patterns of patterns that derive 90 million copies of a terminal */
    j = fresh();
    const char *g = json_string_value(json_object_get(part0(j), "grammar"));
    const char *root = json_string_value(json_object_get(part0(j), "root"));
    char *ax = strstr(g, "axiom box");
    assert_non_null(ax);
    char *text = malloc(strlen(g) + 400);
    size_t head = (size_t)(ax - g);
    memcpy(text, g, head);
    sprintf(text + head,
            "rule Huge1 size 1 1 1 {\n  %s(subdivide(p, 3000, 1, 1, 0, 0, 0))\n}\n\n"
            "rule Huge2 size 1 1 1 {\n  Huge1(subdivide(p, 3000, 1, 1, 0, 0, 0))\n}\n\n"
            "axiom box 0 0 0 1 1 1 {\n  Huge2(p)\n}\n",
            root);
    set_grammar(j, text);
    free(text);
    expect_refused(j, AG_ERR_TOO_LARGE, "parts[0].grammar", "derives");

    /* rules nested 2000 deep */
    j = fresh();
    g = json_string_value(json_object_get(part0(j), "grammar"));
    root = json_string_value(json_object_get(part0(j), "root"));
    ax = strstr(g, "axiom box");
    size_t cap = strlen(g) + 2000 * 80 + 200;
    text = malloc(cap);
    head = (size_t)(ax - g);
    memcpy(text, g, head);
    size_t at = head;
    at += (size_t)sprintf(text + at, "rule Deep0 size 1 1 1 {\n  %s(p)\n}\n\n", root);
    for (int k = 1; k < 2000; k++)
        at += (size_t)sprintf(text + at, "rule Deep%d size 1 1 1 {\n  Deep%d(p)\n}\n\n", k, k - 1);
    sprintf(text + at, "axiom box 0 0 0 1 1 1 {\n  Deep1999(p)\n}\n");
    set_grammar(j, text);
    free(text);
    expect_refused(j, AG_ERR_TOO_LARGE, "parts[0].grammar", "nested");
}


/* Deterministic mutations of a good bundle: every read either succeeds or fails with a message,
 * never crashes; mutations inside the grammar and the terminals are read through their parsers. */
static void test_mutations(void **state)
{
    (void)state;
    char *text = bundle_text();
    size_t len = strlen(text);
    uint32_t seed = 7;
    size_t refused = 0, read = 0;
    for (int i = 0; i < 400; i++) {
        char *m = strdup(text);
        int edits = 1 + i % 4;
        for (int e = 0; e < edits; e++) {
            seed = seed * 1664525u + 1013904223u;
            size_t at = (seed >> 4) % len;
            static const char pool[] = "{}[],:\"0123456789-.e \\nvfT_aZ";
            seed = seed * 1664525u + 1013904223u;
            m[at] = pool[(seed >> 8) % (sizeof pool - 1)];
        }
        ag_part **parts = NULL;
        size_t n = 0;
        ag_error err = {0};
        ag_status st = ag_part_bundle_read(m, len, &parts, &n, &err);
        if (st) {
            assert_null(parts);
            assert_true(err.text[0] != 0);
            refused++;
        } else {
            assert_true(n >= 1);
            read++;
            ag_part_bundle_free(parts, n);
        }
        free(m);
    }
    print_message("%zu mutated bundles refused, %zu still valid\n", refused, read);
    assert_true(refused > 0);
    /* inside the grammar text, and inside a terminal's OBJ text kept under its new hash */
    size_t deep_refused = 0;
    for (int i = 0; i < 300; i++) {
        json_t *j = json_loads(text, 0, NULL);
        int in_obj = i & 1;
        json_t *terms = json_object_get(j, "terminals");
        char *g = strdup(json_string_value(json_object_get(part0(j), "grammar")));
        char *target = g;
        const char *key = NULL;
        json_t *val = NULL;
        if (in_obj) {
            const char *k;
            json_t *v;
            json_object_foreach(terms, k, v) {
                if (strstr(g, k)) {
                    key = k;
                    val = v;
                    break;
                }
            }
            assert_non_null(key);
            target = strdup(json_string_value(val));
        }
        size_t tl = strlen(target);
        for (int e = 0; e < 1 + i % 3; e++) {
            seed = seed * 1664525u + 1013904223u;
            size_t at = (seed >> 4) % tl;
            static const char pool[] = "(){}=,.-0123456789 \nvfpR_Tsplitrot";
            seed = seed * 1664525u + 1013904223u;
            target[at] = pool[(seed >> 8) % (sizeof pool - 1)];
        }
        if (in_obj) {
            char hex[AG_SHA256_HEX], oldkey[AG_SHA256_HEX];
            snprintf(oldkey, sizeof oldkey, "%s", key);
            assert_int_equal(ag_sha256_hex(target, tl, hex, NULL), AG_OK);
            json_object_set_new(terms, hex, json_string(target));
            char *g2 = replace(g, oldkey, hex);
            free(g);
            g = g2;
            free(target);
        }
        set_grammar(j, g);
        free(g);
        char *m = json_dumps(j, 0);
        json_decref(j);
        ag_part **parts = NULL;
        size_t n = 0;
        ag_error err = {0};
        ag_status st = ag_part_bundle_read(m, strlen(m), &parts, &n, &err);
        if (st) {
            assert_null(parts);
            assert_true(err.text[0] != 0);
            deep_refused++;
        } else {
            /* a part that reads composes, or is refused with a message */
            for (size_t k = 0; k < n; k++) {
                ag_compose_op op = {.target = pf_node_with_box(B, &SB[4], TOL),
                                    .mode = (int)(k + i) % 3, .scope = AG_COMPOSE_RULE};
                ag_grammar *cg = NULL;
                ag_error ce = {0};
                if (ag_compose(B, parts[k], &op, &cg, NULL, &ce) == AG_OK) {
                    ag_mesh *d = NULL;
                    if (ag_grammar_derive(cg, NULL, &d, &ce) == AG_OK)
                        ag_mesh_free(d);
                    ag_grammar_free(cg);
                } else {
                    assert_true(ce.text[0] != 0);
                }
            }
            ag_part_bundle_free(parts, n);
        }
        free(m);
    }
    print_message("%zu of 300 grammar and terminal mutations refused\n", deep_refused);
    assert_true(deep_refused > 0);
    free(text);
}

/* The stored entry text is written without jansson: checked here against the part itself,
 * read back by jansson (an independent parser): every real exactly the part's double and
 * still a real, names with quotes, backslashes, control characters and UTF-8 unchanged, and
 * text that is not UTF-8 refused naming the member. */
static void expect_box(json_t *a, const double *v)
{
    assert_true(json_is_array(a));
    assert_int_equal(json_array_size(a), 6);
    for (int i = 0; i < 6; i++) {
        json_t *x = json_array_get(a, i);
        assert_true(json_is_real(x));
        double got = json_real_value(x);
        assert_memory_equal(&got, &v[i], sizeof got); /* bit for bit: -0.0 stays -0.0 */
    }
}

static void test_entry_text(void **state)
{
    (void)state;
    for (int w = 0; w < 2; w++) {
        ag_part *p = P[w];
        char *oldname = p->name, *olddesc = p->description;
        double oldbox = p->nodes[0].box[0];
        char name[] = "a \"quoted\" \\ name\twith\nlines \x01 and \xc3\xa9\xe2\x82\xac";
        p->name = name;
        p->description = w ? NULL : "plain";
        p->nodes[0].box[0] = -0.0;
        json_t *terms = json_object();
        char *text = NULL;
        size_t len = 0;
        ag_error err = {0};
        assert_int_equal(ag_part_bundle_entry_text(p, terms, &text, &len, &err), AG_OK);
        assert_int_equal(strlen(text), len);
        json_error_t je;
        json_t *e = json_loadb(text, len, JSON_REJECT_DUPLICATES, &je);
        if (!e)
            fail_msg("the entry does not parse: %s (column %d)", je.text, je.column);
        assert_string_equal(json_string_value(json_object_get(e, "name")), name);
        if (w)
            assert_null(json_object_get(e, "description"));
        else
            assert_string_equal(json_string_value(json_object_get(e, "description")), "plain");
        assert_int_equal(json_integer_value(json_object_get(e, "version")), p->version);
        json_t *tags = json_object_get(e, "tags");
        assert_int_equal(json_array_size(tags), p->ntags);
        for (size_t i = 0; i < p->ntags; i++)
            assert_string_equal(json_string_value(json_array_get(tags, i)), p->tags[i]);
        json_t *prov = json_object_get(e, "provenance");
        assert_string_equal(json_string_value(json_object_get(prov, "source")), p->source);
        assert_int_equal(json_integer_value(json_object_get(prov, "source_version")),
                         p->source_version);
        assert_int_equal(json_integer_value(json_object_get(prov, "node")), p->source_node);
        assert_string_equal(json_string_value(json_object_get(e, "root")), p->root);
        double b[6] = {p->box.min[0], p->box.min[1], p->box.min[2],
                       p->box.max[0], p->box.max[1], p->box.max[2]};
        expect_box(json_object_get(e, "box"), b);
        assert_int_equal(json_integer_value(json_object_get(e, "facing")), p->facing);
        /* the grammar as the part's own, with the terminals named by their content */
        const char *gt = json_string_value(json_object_get(e, "grammar"));
        assert_non_null(gt);
        ag_grammar *g = NULL;
        assert_int_equal(ag_grammar_text_parse(gt, strlen(gt), &g, &err, NULL), AG_OK);
        assert_int_equal(g->nrules, p->grammar->nrules);
        assert_int_equal(g->nterminals, p->grammar->nterminals);
        assert_int_equal(json_object_size(terms), p->grammar->nterminals);
        for (size_t i = 0; i < g->nterminals; i++) {
            const char *path = g->terminals[i].path;
            assert_int_equal(strncmp(path, "terminals/", 10), 0);
            char hex[AG_SHA256_HEX];
            snprintf(hex, sizeof hex, "%.64s", path + 10);
            assert_non_null(json_object_get(terms, hex));
        }
        ag_grammar_free(g);
        json_t *nodes = json_object_get(e, "nodes");
        assert_int_equal(json_array_size(nodes), p->nnodes);
        for (size_t i = 0; i < p->nnodes; i++) {
            json_t *n = json_array_get(nodes, i);
            assert_int_equal(json_integer_value(json_object_get(n, "parent")), p->nodes[i].parent);
            assert_int_equal(json_integer_value(json_object_get(n, "label")), p->nodes[i].label);
            assert_string_equal(json_string_value(json_object_get(n, "rule")), p->nodes[i].rule);
            expect_box(json_object_get(n, "box"), p->nodes[i].box);
        }
        json_t *attrs = json_object_get(e, "attributes");
        assert_int_equal(json_object_size(attrs), p->nattrs);
        for (size_t i = 0; i < p->nattrs; i++)
            assert_string_equal(json_string_value(json_object_get(attrs, p->attrs[i].key)),
                                p->attrs[i].value);
        json_decref(e);
        free(text);
        /* not UTF-8: refused, naming the member */
        char bad[] = "broken \xc3(";
        p->name = bad;
        text = NULL;
        assert_int_equal(ag_part_bundle_entry_text(p, terms, &text, &len, &err), AG_ERR_INVALID);
        assert_null(text);
        assert_non_null(strstr(err.text, "name"));
        p->name = name;
        p->nodes[0].box[0] = NAN;
        assert_int_equal(ag_part_bundle_entry_text(p, terms, &text, &len, &err), AG_ERR_INVALID);
        assert_non_null(strstr(err.text, "nodes.box"));
        json_decref(terms);
        p->name = oldname;
        p->description = olddesc;
        p->nodes[0].box[0] = oldbox;
    }
}

static void test_write_file_leaves_nothing(void **state)
{
    (void)state;
    char dir[] = "/tmp/ag_bundle_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256], tmp[300];
    snprintf(path, sizeof path, "%s/none/lib.agpart", dir);
    ag_error err = {0};
    assert_int_equal(ag_part_bundle_write_file((const ag_part *const *)P, 2, path, &err), AG_ERR_IO);
    assert_int_equal(access(path, F_OK), -1);
    snprintf(path, sizeof path, "%s/lib.agpart", dir);
    assert_int_equal(ag_part_bundle_write_file((const ag_part *const *)P, 2, path, &err), AG_OK);
    ag_part **parts;
    size_t n;
    assert_int_equal(ag_part_bundle_read_file(path, &parts, &n, &err), AG_OK);
    assert_int_equal(n, 2);
    ag_part_bundle_free(parts, n);
    unlink(path);
    snprintf(tmp, sizeof tmp, "%s", dir);
    rmdir(tmp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_bad_json),
        cmocka_unit_test(test_missing_and_tampered_terminal),
        cmocka_unit_test(test_bad_terminal_obj),
        cmocka_unit_test(test_cyclic_and_bad_names),
        cmocka_unit_test(test_absurd_sizes),
        cmocka_unit_test(test_far_box_round_trips_or_is_refused),
        cmocka_unit_test(test_mutations),
        cmocka_unit_test(test_write_file_leaves_nothing),
        cmocka_unit_test(test_entry_text),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
