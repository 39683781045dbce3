#include "part_bundle.h"

#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../core/base/array.h"
#include "../core/parts/gcopy.h"
#include "../core/utf8.h"
#include "grammar_text.h"
#include "numtext.h"
#include "sha256.h"
#include "terminals.h"

/* ---- writing ---------------------------------------------------------------------------- */

static const char *kind_name(int kind)
{
    switch (kind) {
    case AG_NODE_ROOT: return "root";
    case AG_NODE_SPLIT: return "split";
    case AG_NODE_COMPONENT: return "component";
    case AG_NODE_PATTERN: return "pattern";
    default: return "removed";
    }
}

static int kind_of(const char *s)
{
    return !strcmp(s, "root") ? AG_NODE_ROOT : !strcmp(s, "split") ? AG_NODE_SPLIT
           : !strcmp(s, "component") ? AG_NODE_COMPONENT : !strcmp(s, "pattern") ? AG_NODE_PATTERN
                                                                                  : -1;
}

/* Compact JSON text written straight into one growing buffer: a large part's entry (thousands
 * of nodes) cost several times more as a tree of jansson values built, printed and freed. */
typedef struct {
    char *p;
    size_t n, cap;
    const char *bad; /* the first member that could not be written, or NULL */
    int nomem;
} jtext;

static void jt_put(jtext *j, const char *s, size_t n)
{
    if (j->nomem || AG_ARRAY_RESERVE_MORE(j->p, j->cap, j->n, n + 1) != AG_OK) {
        j->nomem = 1;
        return;
    }
    memcpy(j->p + j->n, s, n);
    j->n += n;
    j->p[j->n] = '\0';
}

static void jt_lit(jtext *j, const char *s)
{
    jt_put(j, s, strlen(s));
}

/* A JSON string escaped as jansson escapes it (quote, backslash, control characters); what
 * is not valid UTF-8 is not written and named as bad. */
static void jt_string(jtext *j, const char *s, size_t n, const char *what)
{
    if (ag_utf8_valid_prefix(s, n) != n) {
        if (!j->bad)
            j->bad = what;
        return;
    }
    jt_put(j, "\"", 1);
    size_t run = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c >= 0x20 && c != '"' && c != '\\')
            continue;
        jt_put(j, s + run, i - run);
        run = i + 1;
        char esc[8];
        switch (c) {
        case '"': jt_put(j, "\\\"", 2); break;
        case '\\': jt_put(j, "\\\\", 2); break;
        case '\n': jt_put(j, "\\n", 2); break;
        case '\t': jt_put(j, "\\t", 2); break;
        case '\r': jt_put(j, "\\r", 2); break;
        case '\b': jt_put(j, "\\b", 2); break;
        case '\f': jt_put(j, "\\f", 2); break;
        default:
            snprintf(esc, sizeof esc, "\\u%04X", c);
            jt_put(j, esc, 6);
        }
    }
    jt_put(j, s + run, n - run);
    jt_put(j, "\"", 1);
}

/* "key": then a string, or nothing at all when s is NULL (as a jansson member set to NULL). */
static void jt_member_string(jtext *j, const char *key, const char *s, const char *what)
{
    if (!s)
        return;
    jt_lit(j, key);
    jt_string(j, s, strlen(s), what);
}

static void jt_int(jtext *j, long long v)
{
    char b[AG_NUMTEXT_MAX + 1];
    size_t n = v < 0 ? (b[0] = '-', 1 + ag_numtext_u64(b + 1, 0ull - (unsigned long long)v))
                     : ag_numtext_u64(b, (unsigned long long)v);
    jt_put(j, b, n);
}

/* The shortest decimal that reads back to v, always read as a real (a fraction or an
 * exponent: "3.0", "-0.0"). */
static void jt_real(jtext *j, double v, const char *what)
{
    if (!isfinite(v)) {
        if (!j->bad)
            j->bad = what;
        return;
    }
    char b[AG_NUMTEXT_MAX + 2];
    size_t n = ag_numtext_double(b, v);
    if (!memchr(b, '.', n) && !memchr(b, 'e', n)) {
        memcpy(b + n, ".0", 2);
        n += 2;
    }
    jt_put(j, b, n);
}

static void jt_box(jtext *j, const double *v, const char *what)
{
    jt_put(j, "[", 1);
    for (int i = 0; i < 6; i++) {
        if (i)
            jt_put(j, ",", 1);
        jt_real(j, v[i], what);
    }
    jt_put(j, "]", 1);
}

ag_status ag_part_bundle_entry_text(const ag_part *p, json_t *terminals, char **out, size_t *len,
                                    ag_error *err)
{
    *out = NULL;
    *len = 0;
    ag_grammar *g = NULL;
    ag_status st = ag_gcopy_grammar(p->grammar, &g, err);
    if (st)
        return st;
    for (size_t i = 0; i < g->nterminals && !st; i++) {
        ag_gterminal *t = &g->terminals[i];
        char *text = NULL;
        size_t tlen = 0;
        char hex[AG_SHA256_HEX], path[96];
        if ((st = ag_terminals_format(t, &text, &tlen, err)) ||
            (st = ag_sha256_hex(text, tlen, hex, err))) {
            free(text);
            break;
        }
        snprintf(path, sizeof path, "terminals/%s.obj", hex);
        free(t->path);
        t->path = strdup(path);
        if (!json_object_get(terminals, hex))
            json_object_set_new(terminals, hex, json_stringn(text, tlen));
        free(text);
        if (!t->path)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    char *text = NULL;
    size_t tlen = 0;
    if (!st)
        st = ag_grammar_text_print(g, &text, &tlen, err);
    ag_grammar_free(g);
    if (st)
        return st;
    jtext j = {0};
    /* about 160 bytes a node: reserved at once, not grown node by node */
    if (AG_ARRAY_RESERVE_MORE(j.p, j.cap, 0, tlen + 160 * p->nnodes + 4096) != AG_OK)
        j.nomem = 1;
    jt_put(&j, "{", 1);
    if (p->name) {
        jt_lit(&j, "\"name\":");
        jt_string(&j, p->name, strlen(p->name), "name");
        jt_put(&j, ",", 1);
    }
    jt_lit(&j, "\"version\":");
    jt_int(&j, (long long)p->version);
    if (p->description)
        jt_member_string(&j, ",\"description\":", p->description, "description");
    jt_lit(&j, ",\"tags\":[");
    for (size_t i = 0, k = 0; i < p->ntags; i++) {
        if (!p->tags[i])
            continue;
        if (k++)
            jt_put(&j, ",", 1);
        jt_string(&j, p->tags[i], strlen(p->tags[i]), "tags");
    }
    jt_lit(&j, "],\"provenance\":{");
    if (p->source) {
        jt_member_string(&j, "\"source\":", p->source, "provenance.source");
        jt_put(&j, ",", 1);
    }
    jt_lit(&j, "\"source_version\":");
    jt_int(&j, (long long)p->source_version);
    jt_lit(&j, ",\"node\":");
    jt_int(&j, (long long)p->source_node);
    jt_lit(&j, "}");
    jt_member_string(&j, ",\"root\":", p->root, "root");
    double b[6] = {p->box.min[0], p->box.min[1], p->box.min[2],
                   p->box.max[0], p->box.max[1], p->box.max[2]};
    jt_lit(&j, ",\"box\":");
    jt_box(&j, b, "box");
    jt_lit(&j, ",\"facing\":");
    jt_int(&j, p->facing);
    jt_lit(&j, ",\"grammar\":");
    jt_string(&j, text, tlen, "grammar");
    free(text);
    jt_lit(&j, ",\"nodes\":[");
    for (size_t i = 0; i < p->nnodes; i++) {
        const ag_part_node *n = &p->nodes[i];
        jt_lit(&j, i ? ",{\"parent\":" : "{\"parent\":");
        jt_int(&j, n->parent);
        jt_lit(&j, ",\"kind\":\"");
        jt_lit(&j, kind_name(n->kind));
        jt_put(&j, "\"", 1);
        jt_lit(&j, ",\"label\":");
        jt_int(&j, n->label);
        jt_member_string(&j, ",\"rule\":", n->rule, "nodes.rule");
        jt_lit(&j, ",\"box\":");
        jt_box(&j, n->box, "nodes.box");
        jt_put(&j, "}", 1);
    }
    jt_lit(&j, "],\"attributes\":{");
    for (size_t i = 0, k = 0; i < p->nattrs; i++) {
        if (!p->attrs[i].key || !p->attrs[i].value)
            continue;
        if (k++)
            jt_put(&j, ",", 1);
        jt_string(&j, p->attrs[i].key, strlen(p->attrs[i].key), "attributes");
        jt_put(&j, ":", 1);
        jt_string(&j, p->attrs[i].value, strlen(p->attrs[i].value), "attributes");
    }
    jt_lit(&j, "}}");
    if (j.nomem || j.bad) {
        free(j.p);
        return j.nomem ? ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory")
                       : ag_error_set(err, AG_ERR_INVALID, 0,
                                      "%s: not valid UTF-8 or not a finite number", j.bad);
    }
    *out = j.p;
    *len = j.n;
    return AG_OK;
}

ag_status ag_part_bundle_entry(const ag_part *p, json_t *terminals, json_t **out, ag_error *err)
{
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    ag_status st = ag_part_bundle_entry_text(p, terminals, &text, &len, err);
    if (st)
        return st;
    json_error_t je;
    *out = json_loadb(text, len, 0, &je);
    free(text);
    if (!*out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the entry back");
    return AG_OK;
}

static int by_string(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

ag_status ag_part_bundle_print(json_t *parts, json_t *terminals, char **out, size_t *len,
                               ag_error *err)
{
    *out = NULL;
    *len = 0;
    /* terminals in the order of their hashes, however they were gathered */
    size_t nt = json_object_size(terminals);
    const char **keys = malloc((nt ? nt : 1) * sizeof *keys);
    json_t *sorted = json_object(), *root = json_object();
    char *s = NULL;
    if (keys && sorted && root) {
        size_t k = 0;
        const char *key;
        json_t *v;
        json_object_foreach(terminals, key, v) keys[k++] = key;
        qsort(keys, nt, sizeof *keys, by_string);
        for (k = 0; k < nt; k++)
            json_object_set(sorted, keys[k], json_object_get(terminals, keys[k]));
        json_object_set_new(root, "format", json_string(AG_PART_BUNDLE_FORMAT));
        json_object_set_new(root, "version", json_integer(AG_PART_BUNDLE_VERSION));
        json_object_set(root, "parts", parts);
        json_object_set(root, "terminals", sorted);
        s = json_dumps(root, JSON_INDENT(1) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
    }
    free(keys);
    json_decref(sorted);
    json_decref(root);
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    *out = s;
    *len = strlen(s);
    return AG_OK;
}

ag_status ag_part_bundle_write(const ag_part *const *parts, size_t n, char **out, size_t *len,
                               ag_error *err)
{
    *out = NULL;
    if (n == 0 || n > AG_PART_BUNDLE_MAX_PARTS)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a bundle holds 1 to %d parts",
                            AG_PART_BUNDLE_MAX_PARTS);
    json_t *jp = json_array(), *terms = json_object();
    ag_status st = AG_OK;
    for (size_t i = 0; i < n && !st; i++) {
        json_t *o = NULL;
        if ((st = ag_part_validate(parts[i], err)) ||
            (st = ag_part_bundle_entry(parts[i], terms, &o, err)))
            break;
        json_array_append_new(jp, o);
    }
    if (!st)
        st = ag_part_bundle_print(jp, terms, out, len, err);
    json_decref(jp);
    json_decref(terms);
    return st;
}

ag_status ag_part_bundle_write_file(const ag_part *const *parts, size_t n, const char *path,
                                    ag_error *err)
{
    char *text = NULL;
    size_t len = 0;
    ag_status st = ag_part_bundle_write(parts, n, &text, &len, err);
    if (st)
        return st;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(text, 1, len, f) == len;
    if (f && fclose(f))
        ok = 0;
    free(text);
    if (!ok || rename(tmp, path)) {
        int e = errno;
        unlink(tmp);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(e));
    }
    return AG_OK;
}

/* ---- reading ---------------------------------------------------------------------------- */

typedef struct {
    const char *key;
    double *pos;
    uint32_t *tri;
    size_t nverts, ntris;
} bterm;

static int by_key(const void *a, const void *b)
{
    return strcmp(((const bterm *)a)->key, ((const bterm *)b)->key);
}

static int is_identifier(const char *s, size_t max)
{
    if (!s || !*s || strlen(s) > max)
        return 0;
    if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || *s == '_'))
        return 0;
    for (const char *p = s; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
              *p == '_'))
            return 0;
    return 1;
}

/* Rules that apply each other, found in the text before it is parsed (the parser would only
 * say that a rule is used before it is declared): rule names and the names applied in their
 * bodies, then a depth-first search. */
typedef struct {
    char name[64];
    long line;
    size_t first, n; /* callees in the flat list */
} srule;

static int scan_ident(const char *s, size_t len, size_t *i, char out[64])
{
    size_t k = 0;
    char c = s[*i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'))
        return 0;
    while (*i < len && ((s[*i] >= 'a' && s[*i] <= 'z') || (s[*i] >= 'A' && s[*i] <= 'Z') ||
                        (s[*i] >= '0' && s[*i] <= '9') || s[*i] == '_')) {
        if (k < 63)
            out[k++] = s[*i];
        (*i)++;
    }
    out[k] = 0;
    return 1;
}

static ag_status find_cycle(const char *s, size_t len, char *msg, size_t msgcap, long *line_out)
{
    srule *rules = NULL;
    size_t nr = 0, cr = 0;
    char (*callees)[64] = NULL;
    size_t nc = 0, cc = 0;
    long line = 1;
    int in_body = 0, want_rule_name = 0, axiom = 0;
    ag_status st = AG_OK;
    for (size_t i = 0; i < len;) {
        char c = s[i];
        if (c == '\n') {
            line++;
            i++;
        } else if (c == '#') {
            while (i < len && s[i] != '\n')
                i++;
        } else if (c == '"') {
            i++;
            while (i < len && s[i] != '"' && s[i] != '\n')
                i++;
            i++;
        } else if (c == '{') {
            in_body = 1;
            i++;
        } else if (c == '}') {
            in_body = 0;
            axiom = 0;
            i++;
        } else {
            char id[64];
            if (!scan_ident(s, len, &i, id)) {
                i++;
                continue;
            }
            if (!in_body && want_rule_name) {
                if (nr == cr) {
                    cr = cr ? 2 * cr : 16;
                    srule *q = realloc(rules, cr * sizeof *q);
                    if (!q) {
                        st = AG_ERR_NOMEM;
                        break;
                    }
                    rules = q;
                }
                snprintf(rules[nr].name, 64, "%s", id);
                rules[nr].line = line;
                rules[nr].first = nc;
                rules[nr].n = 0;
                nr++;
                want_rule_name = 0;
            } else if (!in_body) {
                want_rule_name = !strcmp(id, "rule");
                if (!strcmp(id, "axiom"))
                    axiom = 1; /* its body applies rules but is never applied */
                else if (want_rule_name)
                    axiom = 0;
            } else if (in_body && nr && !axiom) {
                size_t j = i;
                while (j < len && (s[j] == ' ' || s[j] == '\t'))
                    j++;
                if (j < len && s[j] == '(' && strcmp(id, "split") && strcmp(id, "subdivide") &&
                    strcmp(id, "repeat")) {
                    if (nc == cc) {
                        cc = cc ? 2 * cc : 64;
                        char(*q)[64] = realloc(callees, cc * sizeof *q);
                        if (!q) {
                            st = AG_ERR_NOMEM;
                            break;
                        }
                        callees = q;
                    }
                    snprintf(callees[nc++], 64, "%s", id);
                    rules[nr - 1].n++;
                }
            }
        }
    }
    if (!st && nr) {
        /* depth-first search with colours */
        uint8_t *col = calloc(nr, 1);
        size_t *stack = malloc(2 * (nr + 1) * sizeof *stack);
        if (!col || !stack)
            st = AG_ERR_NOMEM;
        for (size_t r0 = 0; r0 < nr && !st; r0++) {
            if (col[r0])
                continue;
            size_t sp = 0;
            stack[sp++] = r0;
            stack[sp++] = 0;
            col[r0] = 1;
            while (sp && !st) {
                size_t r = stack[sp - 2], k = stack[sp - 1];
                if (k == rules[r].n) {
                    col[r] = 2;
                    sp -= 2;
                    continue;
                }
                stack[sp - 1] = k + 1;
                const char *cn = callees[rules[r].first + k];
                size_t t = 0;
                while (t < nr && strcmp(rules[t].name, cn))
                    t++;
                if (t == nr)
                    continue;
                if (col[t] == 1) {
                    snprintf(msg, msgcap, "rule '%s' applies itself (through '%s'): rules may not "
                             "be cyclic", rules[t].name, rules[r].name);
                    *line_out = rules[t].line;
                    st = AG_ERR_INVALID;
                } else if (!col[t]) {
                    col[t] = 1;
                    stack[sp++] = t;
                    stack[sp++] = 0;
                }
            }
        }
        free(col);
        free(stack);
    }
    free(rules);
    free(callees);
    return st;
}

/* Triangles the grammar derives and how deep its rules nest, by rule (declare-before-use
 * order); the triangles capped. */
static double derived_triangles(const ag_grammar *g, size_t *depth)
{
    double *tr = calloc(g->nrules + 1, sizeof *tr);
    size_t *dp = calloc(g->nrules + 1, sizeof *dp);
    if (!tr || !dp) {
        free(tr);
        free(dp);
        return INFINITY;
    }
    double axiom = 0;
    *depth = 0;
    for (size_t i = 0; i <= g->nrules; i++) {
        const ag_grule *r = i < g->nrules ? &g->rules[i] : &g->axiom;
        double n = 0;
        size_t d = 0;
        for (size_t k = 0; k < r->nstmts; k++) {
            const ag_gstmt *s = &r->stmts[k];
            if (s->kind != AG_GSTMT_APPLY)
                continue;
            double cells = s->subdivide ? (double)s->counts[0] * s->counts[1] * s->counts[2] : 1;
            n += cells * (s->callee_is_rule ? tr[s->callee_ix] : (double)g->terminals[s->callee_ix].ntris);
            if (s->callee_is_rule && dp[s->callee_ix] + 1 > d)
                d = dp[s->callee_ix] + 1;
        }
        if (i < g->nrules) {
            tr[i] = fmin(n, 1e300);
            dp[i] = d;
        } else {
            axiom = n;
            *depth = d;
        }
    }
    free(tr);
    free(dp);
    return axiom;
}

static ag_status read_box(json_t *j, double v[6], double lo, double hi, const char *what,
                          ag_error *err)
{
    if (!json_is_array(j) || json_array_size(j) != 6)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s: must be an array of 6 numbers", what);
    for (int i = 0; i < 6; i++) {
        json_t *x = json_array_get(j, i);
        if (!json_is_number(x) || !isfinite(json_number_value(x)) ||
            json_number_value(x) < lo || json_number_value(x) > hi)
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s[%d]: must be a number in [%g, %g]",
                                what, i, lo, hi);
        v[i] = json_number_value(x);
    }
    for (int a = 0; a < 3; a++)
        if (v[a] > v[a + 3])
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s: min above max on axis %d", what, a);
    return AG_OK;
}

static const char *opt_string(json_t *o, const char *key, int *bad)
{
    json_t *v = json_object_get(o, key);
    if (!v)
        return NULL;
    if (!json_is_string(v)) {
        *bad = 1;
        return NULL;
    }
    return json_string_value(v);
}

static ag_status read_part(json_t *o, size_t pi, const bterm *terms, size_t nterms,
                           ag_part **out, ag_error *err)
{
    *out = NULL;
    char where[48];
    snprintf(where, sizeof where, "parts[%zu]", pi);
    if (!json_is_object(o))
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1, "%s: must be an object", where);
    int bad = 0;
    const char *name = opt_string(o, "name", &bad), *desc = opt_string(o, "description", &bad);
    const char *root = opt_string(o, "root", &bad), *gtext = opt_string(o, "grammar", &bad);
    if (bad)
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                            "%s: name, description, root and grammar must be strings", where);
    json_t *jtags = json_object_get(o, "tags");
    if (jtags && (!json_is_array(jtags) || json_array_size(jtags) > AG_PART_TAGS_MAX))
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                            "%s.tags: must be an array of at most %d strings", where,
                            AG_PART_TAGS_MAX);
    const char *tags[AG_PART_TAGS_MAX];
    size_t ntags = jtags ? json_array_size(jtags) : 0;
    for (size_t i = 0; i < ntags; i++) {
        json_t *t = json_array_get(jtags, i);
        if (!json_is_string(t))
            return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1, "%s.tags[%zu]: not a string",
                                where, i);
        tags[i] = json_string_value(t);
    }
    json_t *prov = json_object_get(o, "provenance");
    const char *source = NULL;
    long sver = 0, snode = -1;
    if (prov) {
        if (!json_is_object(prov))
            return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                                "%s.provenance: must be an object", where);
        source = opt_string(prov, "source", &bad);
        json_t *v = json_object_get(prov, "source_version"), *nd = json_object_get(prov, "node");
        if (bad || (v && !json_is_integer(v)) || (nd && !json_is_integer(nd)))
            return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                                "%s.provenance: source is a string, source_version and node "
                                "integers", where);
        sver = v ? (long)json_integer_value(v) : 0;
        snode = nd ? (long)json_integer_value(nd) : -1;
    }
    ag_part_meta meta = {.name = name, .description = desc, .tags = tags, .ntags = ntags,
                         .source = source, .source_version = sver};
    ag_error e = {0};
    if (ag_part_check_meta(&meta, &e))
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1, "%s.%s", where, e.text);
    json_t *ver = json_object_get(o, "version");
    if (!json_is_integer(ver) || json_integer_value(ver) < 1 || json_integer_value(ver) > 1000000000)
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                            "%s.version: must be an integer >= 1", where);
    if (!is_identifier(root, 63))
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                            "%s.root: '%s' is not an identifier", where, root ? root : "");
    if (!gtext)
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1, "%s.grammar: missing", where);
    json_t *jf = json_object_get(o, "facing");
    if (!json_is_integer(jf) || json_integer_value(jf) < 0 || json_integer_value(jf) > 3)
        return ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                            "%s.facing: must be an integer 0..3", where);
    double box[6];
    char what[96];
    snprintf(what, sizeof what, "%s.box", where);
    ag_status st = read_box(json_object_get(o, "box"), box, -AG_PART_MAX_COORD,
                            AG_PART_MAX_COORD, what, err);
    if (st)
        return st;

    /* the grammar */
    size_t glen = strlen(gtext);
    char msg[200];
    long line = 0, col = 0;
    if ((st = find_cycle(gtext, glen, msg, sizeof msg, &line))) {
        if (st == AG_ERR_NOMEM)
            return ag_error_set(err, st, 0, "out of memory");
        return ag_error_set(err, AG_ERR_INVALID, line, "%s.grammar:%ld: %s", where, line, msg);
    }
    ag_part *p = calloc(1, sizeof *p);
    if (!p)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (ag_grammar_text_parse(gtext, glen, &p->grammar, &e, &col)) {
        st = ag_error_set(err, e.code == AG_ERR_NOMEM ? AG_ERR_NOMEM : AG_ERR_PARSE, e.element,
                          "%s.grammar:%ld:%ld: %s", where, e.element, col, e.text);
        goto fail;
    }
    ag_grammar *g = p->grammar;
    for (size_t i = 0; i < g->nterminals; i++) {
        ag_gterminal *t = &g->terminals[i];
        const char *path = t->path ? t->path : "";
        char key[AG_SHA256_HEX] = "";
        if (strlen(path) == 10 + 64 + 4 && !strncmp(path, "terminals/", 10) &&
            !strcmp(path + 74, ".obj")) {
            memcpy(key, path + 10, 64);
            key[64] = 0;
        }
        if (!ag_sha256_is_hex(key)) {
            st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                              "%s.grammar: terminal '%s' names \"%s\", not a terminal of the "
                              "bundle (terminals/<sha256>.obj)", where, t->name, path);
            goto fail;
        }
        bterm k = {.key = key};
        const bterm *f = bsearch(&k, terms, nterms, sizeof *terms, by_key);
        if (!f) {
            st = ag_error_set(err, AG_ERR_NOT_FOUND, (long)i + 1,
                              "%s.grammar: terminal '%s' needs terminals.%s, which the bundle "
                              "does not hold", where, t->name, key);
            goto fail;
        }
        for (size_t v = 0; v < f->nverts; v++)
            for (int a = 0; a < 3; a++) {
                double x = f->pos[3 * v + a], tol = 1e-6 * (1 + t->size[a]);
                if (x < -tol || x > t->size[a] + tol) {
                    st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                      "%s.grammar: the geometry of terminal '%s' does not fit "
                                      "its size", where, t->name);
                    goto fail;
                }
            }
        if (ag_grammar_set_terminal_geometry(t, f->pos, f->nverts, f->tri, f->ntris)) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto fail;
        }
    }
    size_t depth = 0;
    double dt = derived_triangles(g, &depth);
    if (depth > 512) {
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                          "%s.grammar: rules are nested %zu deep (at most 512)", where, depth);
        goto fail;
    }
    if (!(dt <= AG_PART_BUNDLE_MAX_TRIANGLES)) {
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                          "%s.grammar: derives %.3g triangles (at most %d)", where, dt,
                          AG_PART_BUNDLE_MAX_TRIANGLES);
        goto fail;
    }
    if (ag_part_set_meta(p, &meta) || !(p->root = strdup(root))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto fail;
    }
    p->version = (unsigned)json_integer_value(ver);
    p->source_node = (int32_t)snode;
    p->facing = (int)json_integer_value(jf);
    for (int a = 0; a < 3; a++) {
        p->box.min[a] = box[a];
        p->box.max[a] = box[a + 3];
    }
    /* proportions */
    json_t *jn = json_object_get(o, "nodes");
    if (!json_is_array(jn) || json_array_size(jn) < 1 ||
        json_array_size(jn) > AG_PART_BUNDLE_MAX_NODES) {
        st = ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                          "%s.nodes: must be an array of 1 to %d nodes", where,
                          AG_PART_BUNDLE_MAX_NODES);
        goto fail;
    }
    p->nnodes = json_array_size(jn);
    if (!(p->nodes = calloc(p->nnodes, sizeof *p->nodes))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto fail;
    }
    for (size_t i = 0; i < p->nnodes; i++) {
        json_t *n = json_array_get(jn, i);
        json_t *par = json_object_get(n, "parent"), *lab = json_object_get(n, "label");
        const char *kind = opt_string(n, "kind", &bad), *rule = opt_string(n, "rule", &bad);
        if (!json_is_object(n) || bad || !json_is_integer(par) || !json_is_integer(lab) || !kind ||
            kind_of(kind) < 0 || json_integer_value(lab) < -1 ||
            json_integer_value(lab) > INT32_MAX ||
            (rule && rule[0] && !is_identifier(rule, 63))) {
            st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                              "%s.nodes[%zu]: needs parent, label (integers), kind (root, "
                              "split, component, pattern) and rule (an identifier or \"\")",
                              where, i);
            goto fail;
        }
        ag_part_node *d = &p->nodes[i];
        json_int_t pv = json_integer_value(par);
        d->parent = pv < -1 || pv > (json_int_t)p->nnodes ? -2 : (int32_t)pv;
        d->kind = kind_of(kind);
        d->label = (int32_t)json_integer_value(lab);
        snprintf(d->rule, sizeof d->rule, "%s", rule ? rule : "");
        snprintf(what, sizeof what, "%s.nodes[%zu].box", where, i);
        if ((st = read_box(json_object_get(n, "box"), d->box, 0, 1, what, err)))
            goto fail;
    }
    json_t *attrs = json_object_get(o, "attributes");
    if (attrs) {
        if (!json_is_object(attrs) || json_object_size(attrs) > AG_PART_BUNDLE_MAX_ATTRS) {
            st = ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                              "%s.attributes: must be an object of at most %d strings", where,
                              AG_PART_BUNDLE_MAX_ATTRS);
            goto fail;
        }
        const char *k;
        json_t *v;
        json_object_foreach(attrs, k, v) {
            if (!json_is_string(v) || strlen(k) > AG_PART_NAME_MAX ||
                json_string_length(v) > AG_PART_TEXT_MAX) {
                st = ag_error_set(err, AG_ERR_INVALID, (long)pi + 1,
                                  "%s.attributes.%.60s: must be a string of at most %d bytes",
                                  where, k, AG_PART_TEXT_MAX);
                goto fail;
            }
            if (ag_part_add_attr(p, k, json_string_value(v))) {
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                goto fail;
            }
        }
    }
    if (ag_part_validate(p, &e)) {
        st = ag_error_set(err, e.code, e.element, "%s.%s", where, e.text);
        goto fail;
    }
    *out = p;
    return AG_OK;
fail:
    ag_part_free(p);
    return st;
}

void ag_part_bundle_free(ag_part **parts, size_t n)
{
    if (!parts)
        return;
    for (size_t i = 0; i < n; i++)
        ag_part_free(parts[i]);
    free(parts);
}

ag_status ag_part_bundle_read(const char *data, size_t len, ag_part ***parts, size_t *n,
                              ag_error *err)
{
    *parts = NULL;
    *n = 0;
    if (len > AG_PART_BUNDLE_MAX_BYTES)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "bundle: %zu bytes (at most %u)", len,
                            AG_PART_BUNDLE_MAX_BYTES);
    json_error_t je;
    json_t *root = json_loadb(data, len, JSON_REJECT_DUPLICATES, &je);
    if (!root)
        return ag_error_set(err, AG_ERR_PARSE, je.line > 0 ? je.line : 0,
                            "bundle: line %d column %d: %s", je.line, je.column, je.text);
    ag_status st = AG_OK;
    bterm *terms = NULL;
    size_t nt = 0;
    ag_part **out = NULL;
    size_t np = 0;
    json_t *fmt = json_object_get(root, "format"), *ver = json_object_get(root, "version");
    json_t *jp = json_object_get(root, "parts"), *jt = json_object_get(root, "terminals");
    if (!json_is_object(root) || !json_is_string(fmt) ||
        strcmp(json_string_value(fmt), AG_PART_BUNDLE_FORMAT)) {
        st = ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "format: not an %s", AG_PART_BUNDLE_FORMAT);
        goto done;
    }
    if (!json_is_integer(ver) || json_integer_value(ver) != AG_PART_BUNDLE_VERSION) {
        st = ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "version: this build reads version %d",
                          AG_PART_BUNDLE_VERSION);
        goto done;
    }
    if (!json_is_array(jp) || json_array_size(jp) < 1 ||
        json_array_size(jp) > AG_PART_BUNDLE_MAX_PARTS) {
        st = ag_error_set(err, AG_ERR_INVALID, 0, "parts: must be an array of 1 to %d parts",
                          AG_PART_BUNDLE_MAX_PARTS);
        goto done;
    }
    if (!json_is_object(jt) || json_object_size(jt) > AG_PART_BUNDLE_MAX_TERMINALS) {
        st = ag_error_set(err, AG_ERR_INVALID, 0,
                          "terminals: must be an object of at most %d terminals",
                          AG_PART_BUNDLE_MAX_TERMINALS);
        goto done;
    }
    terms = calloc(json_object_size(jt) + 1, sizeof *terms);
    if (!terms) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    size_t total = 0;
    const char *key;
    json_t *val;
    json_object_foreach(jt, key, val) {
        if (!ag_sha256_is_hex(key)) {
            st = ag_error_set(err, AG_ERR_INVALID, 0,
                              "terminals.%.80s: a key must be the SHA-256 of its content "
                              "(64 lowercase hex digits)", key);
            goto done;
        }
        if (!json_is_string(val)) {
            st = ag_error_set(err, AG_ERR_INVALID, 0, "terminals.%s: must be OBJ text", key);
            goto done;
        }
        const char *text = json_string_value(val);
        size_t tl = json_string_length(val);
        char hex[AG_SHA256_HEX];
        if ((st = ag_sha256_hex(text, tl, hex, err)))
            goto done;
        if (strcmp(hex, key)) {
            st = ag_error_set(err, AG_ERR_INVALID, 0,
                              "terminals.%s: the content does not match its hash (it has %s)",
                              key, hex);
            goto done;
        }
        ag_gterminal tmp = {.name = (char *)key};
        ag_error e = {0};
        if (ag_terminals_load_buffer(&tmp, text, tl, &e)) {
            st = ag_error_set(err, e.code, e.element, "terminals.%s: %s", key, e.text);
            free(tmp.pos);
            free(tmp.tri);
            goto done;
        }
        total += tmp.ntris;
        terms[nt++] = (bterm){key, tmp.pos, tmp.tri, tmp.nverts, tmp.ntris};
        if (total > AG_PART_BUNDLE_MAX_TRIANGLES) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                              "terminals: more than %d triangles", AG_PART_BUNDLE_MAX_TRIANGLES);
            goto done;
        }
    }
    qsort(terms, nt, sizeof *terms, by_key);
    size_t want = json_array_size(jp);
    out = calloc(want, sizeof *out);
    if (!out) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < want && !st; i++) {
        st = read_part(json_array_get(jp, i), i, terms, nt, &out[i], err);
        if (!st)
            np++;
    }
    if (!st) {
        *parts = out;
        *n = np;
        out = NULL;
    }
done:
    ag_part_bundle_free(out, np);
    for (size_t i = 0; i < nt; i++) {
        free(terms[i].pos);
        free(terms[i].tri);
    }
    free(terms);
    json_decref(root);
    return st;
}

ag_status ag_part_bundle_read_file(const char *path, ag_part ***parts, size_t *n, ag_error *err)
{
    *parts = NULL;
    *n = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot open: %s", strerror(errno));
    struct stat sb;
    if (fstat(fileno(f), &sb) || !S_ISREG(sb.st_mode)) {
        fclose(f);
        return ag_error_set(err, AG_ERR_IO, 0, "not a regular file");
    }
    if ((unsigned long long)sb.st_size > AG_PART_BUNDLE_MAX_BYTES) {
        fclose(f);
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "bundle: %lld bytes (at most %u)",
                            (long long)sb.st_size, AG_PART_BUNDLE_MAX_BYTES);
    }
    size_t len = (size_t)sb.st_size;
    char *buf = malloc(len + 1);
    if (!buf) {
        fclose(f);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t got = fread(buf, 1, len, f);
    fclose(f);
    if (got != len) {
        free(buf);
        return ag_error_set(err, AG_ERR_IO, 0, "read error");
    }
    ag_status st = ag_part_bundle_read(buf, len, parts, n, err);
    free(buf);
    return st;
}
