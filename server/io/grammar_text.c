#include "grammar_text.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "numtext.h"

/* ---- printing --------------------------------------------------------------------------- */

typedef struct {
    char *buf;
    size_t len, cap;
    int oom;
} sbuf;

static void sput(sbuf *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sput(sbuf *s, const char *fmt, ...)
{
    if (s->oom)
        return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(s->buf ? s->buf + s->len : NULL, s->buf ? s->cap - s->len : 0, fmt, ap);
        va_end(ap);
        if (n < 0) {
            s->oom = 1;
            return;
        }
        if (s->buf && s->len + (size_t)n < s->cap) {
            s->len += (size_t)n;
            return;
        }
        if (AG_ARRAY_RESERVE_MORE(s->buf, s->cap, s->len, (size_t)n + 1)) {
            s->oom = 1;
            return;
        }
    }
}

/* "%.12g" (numtext's, byte for byte and many times faster: a facade part prints ~100k). */
static void num(char *b, size_t cap, double v)
{
    if (v == 0)
        v = 0; /* no "-0" */
    char t[AG_NUMTEXT_MAX];
    ag_numtext_double_g(t, v, 12);
    snprintf(b, cap, "%s", strcmp(t, "-0") ? t : "0");
}

/* Appends n bytes (no format: the numbers are the bulk of a large grammar's text). */
static void sput_bytes(sbuf *s, const char *text, size_t n)
{
    if (s->oom)
        return;
    if (s->len + n + 1 > s->cap && AG_ARRAY_RESERVE_MORE(s->buf, s->cap, s->len, n + 1)) {
        s->oom = 1;
        return;
    }
    memcpy(s->buf + s->len, text, n);
    s->len += n;
    s->buf[s->len] = '\0';
}

static void put_nums(sbuf *s, const double *v, int n, const char *sep)
{
    char b[40];
    for (int i = 0; i < n; i++) {
        num(b, sizeof b, v[i]);
        if (i)
            sput_bytes(s, sep, strlen(sep));
        sput_bytes(s, b, strlen(b));
    }
}

static void put_body(sbuf *s, const ag_grule *r)
{
    sput(s, " {\n");
    for (size_t i = 0; i < r->nstmts; i++) {
        const ag_gstmt *t = &r->stmts[i];
        if (t->kind == AG_GSTMT_SPLIT) {
            sput(s, "  %s = split(%s, ", t->node, t->parent);
            put_nums(s, t->v, 3, ", ");
            sput(s, ", %d)\n", t->octant);
        } else if (t->subdivide == 2) {
            sput(s, "  %s(repeat(%s", t->callee, t->node);
            for (int k = 0; k < t->nvec; k++) {
                sput(s, ", %u, ", t->counts[k]);
                put_nums(s, t->vec[k], 3, ", ");
            }
            sput(s, "))");
            if (t->rot)
                sput(s, " rot %d", 90 * t->rot);
            sput(s, "\n");
        } else if (t->subdivide) {
            sput(s, "  %s(subdivide(%s, %u, %u, %u, ", t->callee, t->node, t->counts[0],
                 t->counts[1], t->counts[2]);
            put_nums(s, t->step, 3, ", ");
            sput(s, "))");
            if (t->rot)
                sput(s, " rot %d", 90 * t->rot);
            sput(s, "\n");
        } else {
            sput(s, "  %s(%s)", t->callee, t->node);
            if (t->rot)
                sput(s, " rot %d", 90 * t->rot);
            sput(s, "\n");
        }
    }
    sput(s, "}\n");
}

ag_status ag_grammar_text_print(const ag_grammar *g, char **out, size_t *len, ag_error *err)
{
    sbuf s = {0};
    sput(&s, "archgram-grammar 1\n");
    if (g->nterminals)
        sput(&s, "\n");
    for (size_t i = 0; i < g->nterminals; i++) {
        const ag_gterminal *t = &g->terminals[i];
        sput(&s, "terminal %s \"%s\" size ", t->name, t->path ? t->path : "");
        put_nums(&s, t->size, 3, " ");
        if (t->label_name)
            sput(&s, " label %s", t->label_name);
        sput(&s, "\n");
    }
    for (size_t i = 0; i < g->nrules; i++) {
        const ag_grule *r = &g->rules[i];
        sput(&s, "\nrule %s size ", r->name);
        put_nums(&s, r->size, 3, " ");
        put_body(&s, r);
    }
    if (g->has_axiom) {
        sput(&s, "\naxiom box ");
        put_nums(&s, g->axiom.box.min, 3, " ");
        sput(&s, " ");
        put_nums(&s, g->axiom.box.max, 3, " ");
        put_body(&s, &g->axiom);
    }
    if (s.oom || !s.buf) {
        free(s.buf);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while printing the grammar");
    }
    *out = s.buf;
    *len = s.len;
    return AG_OK;
}

/* v as its printed text reads back (num's digits through strtod, as number() reads them). */
static void round_num(double *v, int n)
{
    char t[AG_NUMTEXT_MAX];
    for (int i = 0; i < n; i++) {
        ag_numtext_double_g(t, v[i], 12);
        double x = strtod(t, NULL);
        v[i] = x == 0 ? 0 : x; /* "-0" prints as 0 */
    }
}

static void round_body(ag_grule *r)
{
    for (size_t i = 0; i < r->nstmts; i++) {
        ag_gstmt *t = &r->stmts[i];
        if (t->kind == AG_GSTMT_SPLIT)
            round_num(t->v, 3);
        else if (t->subdivide == 2)
            for (int k = 0; k < t->nvec; k++)
                round_num(t->vec[k], 3);
        else if (t->subdivide)
            round_num(t->step, 3);
    }
}

void ag_grammar_text_round(ag_grammar *g)
{
    for (size_t i = 0; i < g->nterminals; i++)
        round_num(g->terminals[i].size, 3);
    for (size_t i = 0; i < g->nrules; i++) {
        round_num(g->rules[i].size, 3);
        round_body(&g->rules[i]);
    }
    if (g->has_axiom) {
        round_num(g->axiom.box.min, 3);
        round_num(g->axiom.box.max, 3);
        round_body(&g->axiom);
    }
}

/* ---- parsing ---------------------------------------------------------------------------- */

enum { TK_EOF, TK_IDENT, TK_NUM, TK_STR, TK_PUNCT };

typedef struct {
    const char *src, *end, *p;
    long line;
    const char *line_start;
    /* current token */
    int kind;
    const char *ts;
    size_t tl;
    long tline, tcol;
    ag_error *err;
    long *col;
    ag_status st;
} lexer;

static ag_status lerr(lexer *L, long line, long col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static ag_status lerr(lexer *L, long line, long col, const char *fmt, ...)
{
    if (L->st)
        return L->st;
    char msg[AG_ERROR_TEXT];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (L->col)
        *L->col = col;
    L->st = ag_error_set(L->err, AG_ERR_PARSE, line, "%s", msg);
    return L->st;
}

static void next(lexer *L)
{
    for (;;) {
        while (L->p < L->end && (*L->p == ' ' || *L->p == '\t' || *L->p == '\r' || *L->p == '\n')) {
            if (*L->p == '\n') {
                L->line++;
                L->line_start = L->p + 1;
            }
            L->p++;
        }
        if (L->p < L->end && *L->p == '#') {
            while (L->p < L->end && *L->p != '\n')
                L->p++;
            continue;
        }
        break;
    }
    L->ts = L->p;
    L->tline = L->line;
    L->tcol = (long)(L->p - L->line_start) + 1;
    if (L->p >= L->end) {
        L->kind = TK_EOF;
        L->tl = 0;
        return;
    }
    char c = *L->p;
    if (isalpha((unsigned char)c) || c == '_') {
        while (L->p < L->end && (isalnum((unsigned char)*L->p) || *L->p == '_'))
            L->p++;
        L->kind = TK_IDENT;
    } else if (isdigit((unsigned char)c) || c == '-' || c == '+' || c == '.') {
        while (L->p < L->end && (isalnum((unsigned char)*L->p) || *L->p == '.' || *L->p == '-' ||
                                 *L->p == '+'))
            L->p++;
        L->kind = TK_NUM;
    } else if (c == '"') {
        L->p++;
        while (L->p < L->end && *L->p != '"' && *L->p != '\n')
            L->p++;
        if (L->p >= L->end || *L->p != '"') {
            lerr(L, L->tline, L->tcol, "unterminated string");
            L->kind = TK_EOF;
            return;
        }
        L->p++;
        L->kind = TK_STR;
    } else if (strchr("(){},=", c)) {
        L->p++;
        L->kind = TK_PUNCT;
    } else {
        lerr(L, L->tline, L->tcol, "unexpected character '%c'", isprint((unsigned char)c) ? c : '?');
        L->kind = TK_EOF;
        L->p++;
        return;
    }
    L->tl = (size_t)(L->p - L->ts);
}

static const char *tokname(lexer *L, char *b, size_t cap)
{
    if (L->kind == TK_EOF)
        return "end of file";
    size_t n = L->tl < cap - 3 ? L->tl : cap - 3;
    snprintf(b, cap, "'%.*s'", (int)n, L->ts);
    return b;
}

static int is_punct(lexer *L, char c)
{
    return L->kind == TK_PUNCT && *L->ts == c;
}

static int expect_punct(lexer *L, char c)
{
    if (L->st)
        return -1;
    if (!is_punct(L, c)) {
        char b[48];
        lerr(L, L->tline, L->tcol, "expected '%c', found %s", c, tokname(L, b, sizeof b));
        return -1;
    }
    next(L);
    return 0;
}

static int is_kw(lexer *L, const char *kw)
{
    return L->kind == TK_IDENT && strlen(kw) == L->tl && !memcmp(L->ts, kw, L->tl);
}

static int expect_kw(lexer *L, const char *kw)
{
    if (L->st)
        return -1;
    if (!is_kw(L, kw)) {
        char b[48];
        lerr(L, L->tline, L->tcol, "expected '%s', found %s", kw, tokname(L, b, sizeof b));
        return -1;
    }
    next(L);
    return 0;
}

static int ident(lexer *L, char *out, size_t cap, const char *what)
{
    if (L->st)
        return -1;
    if (L->kind != TK_IDENT) {
        char b[48];
        lerr(L, L->tline, L->tcol, "expected %s, found %s", what, tokname(L, b, sizeof b));
        return -1;
    }
    if (L->tl >= cap) {
        lerr(L, L->tline, L->tcol, "name longer than %zu characters", cap - 1);
        return -1;
    }
    memcpy(out, L->ts, L->tl);
    out[L->tl] = 0;
    next(L);
    return 0;
}

static int number(lexer *L, double *v)
{
    if (L->st)
        return -1;
    if (L->kind != TK_NUM || L->tl > 60) {
        char b[48];
        lerr(L, L->tline, L->tcol, "expected a number, found %s", tokname(L, b, sizeof b));
        return -1;
    }
    char tmp[64];
    memcpy(tmp, L->ts, L->tl);
    tmp[L->tl] = 0;
    char *e;
    errno = 0;
    double x = strtod(tmp, &e);
    if (*e || e == tmp || !isfinite(x)) {
        lerr(L, L->tline, L->tcol, "'%s' is not a finite number", tmp);
        return -1;
    }
    *v = x;
    next(L);
    return 0;
}

static int integer(lexer *L, long lo, long hi, long *v, const char *what)
{
    long line = L->tline, col = L->tcol;
    double x;
    if (number(L, &x))
        return -1;
    if (x != floor(x) || x < lo || x > hi) {
        lerr(L, line, col, "%s must be an integer from %ld to %ld", what, lo, hi);
        return -1;
    }
    *v = (long)x;
    return 0;
}

static int comma(lexer *L)
{
    return expect_punct(L, ',');
}

#define NAME_MAX_LEN 64

static int parse_body(lexer *L, ag_grule *r)
{
    if (expect_punct(L, '{'))
        return -1;
    while (!L->st && !is_punct(L, '}')) {
        long line = L->tline, col = L->tcol;
        char a[NAME_MAX_LEN], b[NAME_MAX_LEN];
        if (L->kind == TK_EOF) {
            lerr(L, line, col, "missing '}' at end of file");
            return -1;
        }
        if (ident(L, a, sizeof a, "a statement"))
            return -1;
        if (is_punct(L, '=')) {
            next(L);
            double v[3];
            long q;
            if (expect_kw(L, "split") || expect_punct(L, '(') ||
                ident(L, b, sizeof b, "the node to split") || comma(L) || number(L, &v[0]) ||
                comma(L) || number(L, &v[1]) || comma(L) || number(L, &v[2]) || comma(L) ||
                integer(L, 1, 8, &q, "the octant") || expect_punct(L, ')'))
                return -1;
            if (ag_grammar_add_split(r, a, b, v, (int)q, line, col))
                return lerr(L, line, col, "out of memory"), -1;
            continue;
        }
        if (expect_punct(L, '('))
            return -1;
        uint32_t counts[3];
        double step[3];
        int sub = 0;
        if (is_kw(L, "subdivide")) {
            next(L);
            long c[3];
            if (expect_punct(L, '(') || ident(L, b, sizeof b, "the node to subdivide") ||
                comma(L) || integer(L, 1, 10000000, &c[0], "a count") || comma(L) ||
                integer(L, 1, 10000000, &c[1], "a count") || comma(L) ||
                integer(L, 1, 10000000, &c[2], "a count") || comma(L) || number(L, &step[0]) ||
                comma(L) || number(L, &step[1]) || comma(L) || number(L, &step[2]) ||
                expect_punct(L, ')'))
                return -1;
            for (int k = 0; k < 3; k++)
                counts[k] = (uint32_t)c[k];
            sub = 1;
        } else if (is_kw(L, "repeat")) {
            next(L);
            long c[3];
            double vec[3][3];
            int nvec = 0;
            if (expect_punct(L, '(') || ident(L, b, sizeof b, "the node to repeat in"))
                return -1;
            while (nvec < 3 && is_punct(L, ',')) {
                next(L);
                if (integer(L, 1, 10000000, &c[nvec], "a count") || comma(L) ||
                    number(L, &vec[nvec][0]) || comma(L) || number(L, &vec[nvec][1]) ||
                    comma(L) || number(L, &vec[nvec][2]))
                    return -1;
                nvec++;
            }
            if (!nvec)
                return lerr(L, L->tline, L->tcol, "repeat needs a count and a vector"), -1;
            if (expect_punct(L, ')'))
                return -1;
            for (int k = 0; k < 3; k++)
                counts[k] = k < nvec ? (uint32_t)c[k] : 1;
            sub = 2;
            if (expect_punct(L, ')'))
                return -1;
            int rot = 0;
            if (is_kw(L, "rot")) {
                next(L);
                long rl = L->tline, rc = L->tcol, deg;
                if (integer(L, 0, 270, &deg, "rot"))
                    return -1;
                if (deg % 90)
                    return lerr(L, rl, rc, "rot must be 0, 90, 180 or 270"), -1;
                rot = (int)(deg / 90);
            }
            if (ag_grammar_add_repeat(r, a, b, rot, nvec, counts, vec, line, col))
                return lerr(L, line, col, "out of memory"), -1;
            continue;
        } else if (ident(L, b, sizeof b, "a node name")) {
            return -1;
        }
        if (expect_punct(L, ')'))
            return -1;
        int rot = 0;
        if (is_kw(L, "rot")) {
            next(L);
            long rl = L->tline, rc = L->tcol;
            long deg;
            if (integer(L, 0, 270, &deg, "rot"))
                return -1;
            if (deg % 90)
                return lerr(L, rl, rc, "rot must be 0, 90, 180 or 270"), -1;
            rot = (int)(deg / 90);
        }
        if (ag_grammar_add_apply(r, a, b, rot, sub ? counts : NULL, sub ? step : NULL, line, col))
            return lerr(L, line, col, "out of memory"), -1;
    }
    if (L->st)
        return -1;
    next(L); /* '}' */
    return 0;
}

ag_status ag_grammar_text_parse(const char *text, size_t len, ag_grammar **out, ag_error *err,
                                long *col)
{
    *out = NULL;
    if (col)
        *col = 0;
    lexer L = {.src = text, .end = text + len, .p = text, .line = 1, .line_start = text,
               .err = err, .col = col};
    for (size_t i = 0; i < len; i++)
        if (text[i] == 0) {
            long line = 1;
            for (size_t k = 0; k < i; k++)
                line += text[k] == '\n';
            if (col)
                *col = 1;
            return ag_error_set(err, AG_ERR_PARSE, line, "NUL byte in the grammar");
        }
    ag_grammar *g = ag_grammar_create();
    if (!g)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* the header is matched literally */
    {
        const char *h = "archgram-grammar";
        size_t hl = strlen(h);
        const char *p = text;
        while (p < text + len && (*p == ' ' || *p == '\t'))
            p++;
        if ((size_t)(text + len - p) < hl || memcmp(p, h, hl)) {
            ag_grammar_free(g);
            if (col)
                *col = 1;
            return ag_error_set(err, AG_ERR_PARSE, 1, "expected the header 'archgram-grammar 1'");
        }
        L.p = p + hl;
    }
    next(&L);
    long version;
    if (!integer(&L, 1, 1, &version, "the format version")) {
        while (!L.st && (is_kw(&L, "terminal"))) {
            next(&L);
            char name[NAME_MAX_LEN];
            long line = L.tline, c = L.tcol;
            if (ident(&L, name, sizeof name, "a terminal name"))
                break;
            if (L.kind != TK_STR) {
                char b[48];
                lerr(&L, L.tline, L.tcol, "expected a quoted file name, found %s",
                     tokname(&L, b, sizeof b));
                break;
            }
            char *path = strndup(L.ts + 1, L.tl - 2);
            next(&L);
            double s[3];
            if (!path || expect_kw(&L, "size") || number(&L, &s[0]) || number(&L, &s[1]) ||
                number(&L, &s[2])) {
                free(path);
                if (!L.st)
                    lerr(&L, line, c, "out of memory");
                break;
            }
            size_t ti;
            if (ag_grammar_add_terminal(g, name, s, &ti)) {
                free(path);
                lerr(&L, line, c, "out of memory");
                break;
            }
            g->terminals[ti].path = path;
            if (is_kw(&L, "label")) {
                next(&L);
                char lab[NAME_MAX_LEN];
                if (ident(&L, lab, sizeof lab, "a label name"))
                    break;
                if (!(g->terminals[ti].label_name = strdup(lab))) {
                    lerr(&L, line, c, "out of memory");
                    break;
                }
            }
        }
        while (!L.st && is_kw(&L, "rule")) {
            long line = L.tline, c = L.tcol;
            next(&L);
            char name[NAME_MAX_LEN];
            double s[3];
            if (ident(&L, name, sizeof name, "a rule name") || expect_kw(&L, "size") ||
                number(&L, &s[0]) || number(&L, &s[1]) || number(&L, &s[2]))
                break;
            size_t ri;
            if (ag_grammar_add_rule(g, name, s, &ri)) {
                lerr(&L, line, c, "out of memory");
                break;
            }
            g->rules[ri].line = line;
            g->rules[ri].col = c;
            if (parse_body(&L, &g->rules[ri]))
                break;
        }
        if (!L.st) {
            long line = L.tline, c = L.tcol;
            double v[6];
            if (!expect_kw(&L, "axiom") && !expect_kw(&L, "box") && !number(&L, &v[0]) &&
                !number(&L, &v[1]) && !number(&L, &v[2]) && !number(&L, &v[3]) &&
                !number(&L, &v[4]) && !number(&L, &v[5])) {
                for (int a = 0; a < 3; a++) {
                    g->axiom.box.min[a] = v[a];
                    g->axiom.box.max[a] = v[3 + a];
                    if (v[3 + a] < v[a]) {
                        lerr(&L, line, c, "the axiom box has max < min");
                        break;
                    }
                }
                g->axiom.line = line;
                g->axiom.col = c;
                g->has_axiom = 1;
                if (!L.st && !parse_body(&L, &g->axiom) && L.kind != TK_EOF) {
                    char b[48];
                    lerr(&L, L.tline, L.tcol, "expected end of file after the axiom, found %s",
                         tokname(&L, b, sizeof b));
                }
            }
        }
    }
    if (L.st) {
        ag_grammar_free(g);
        return L.st;
    }
    ag_status st = ag_grammar_resolve(g, err, col);
    if (st) {
        ag_grammar_free(g);
        return st;
    }
    *out = g;
    return AG_OK;
}

ag_status ag_grammar_text_read_file(const char *path, ag_grammar **out, ag_error *err, long *col)
{
    *out = NULL;
    if (col)
        *col = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot open %s: %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    size_t n;
    while (buf && (n = fread(buf + len, 1, cap - len, f)) > 0) {
        len += n;
        if (len == cap) {
            if (cap >= (64u << 20)) {
                free(buf);
                fclose(f);
                return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%s is larger than 64 MiB", path);
            }
            if (AG_ARRAY_RESERVE(buf, cap, len + 1)) {
                free(buf);
                buf = NULL;
                break;
            }
        }
    }
    int bad = ferror(f);
    fclose(f);
    if (!buf)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading %s", path);
    if (bad) {
        free(buf);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot read %s", path);
    }
    ag_status st = ag_grammar_text_parse(buf, len, out, err, col);
    free(buf);
    return st;
}
