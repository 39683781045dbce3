#include "obj.h"

#include "../core/base/parallel.h"
#include "filemap.h"
#include "numtext.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_MAX_VERTICES 100000000u
#define DEFAULT_MAX_TRIANGLES 200000000u
#define PROGRESS_STEP (1u << 20)
#define NAME_SHOWN 40 /* characters of a bad token quoted in a message */

/* ---- numbers --------------------------------------------------------------------------- */

static inline int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static inline int is_digit(char c)
{
    return (unsigned char)(c - '0') < 10;
}

static const double pow10_tab[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                     1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                     1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* Parses a decimal number at *p (< e) that must end at whitespace or e. Returns 0 and
 * advances *p; -1 when the token is not a number; -2 when it is not finite. The fast path
 * (at most 19 digits, mantissa ≤ 2^53, |exponent| ≤ 22) is exact because both the
 * mantissa and the power of ten are exact doubles and one IEEE operation rounds once;
 * anything else goes through strtod on a bounded copy. */
static int parse_double(const char **pp, const char *e, double *out)
{
    const char *p = *pp, *s = p;
    int neg = 0;
    if (p < e && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    uint64_t mant = 0;
    int ndig = 0, sig = 0, exp10 = 0, overflow = 0;
    while (p < e && is_digit(*p)) {
        if (sig < 19) {
            mant = mant * 10 + (uint64_t)(*p - '0');
            if (mant)
                sig++;
        } else {
            overflow = 1;
            exp10++;
        }
        ndig++;
        p++;
    }
    if (p < e && *p == '.') {
        p++;
        while (p < e && is_digit(*p)) {
            if (sig < 19) {
                mant = mant * 10 + (uint64_t)(*p - '0');
                if (mant)
                    sig++;
                exp10--;
            } else {
                overflow = 1;
            }
            ndig++;
            p++;
        }
    }
    if (ndig == 0)
        goto slow;
    if (p < e && (*p == 'e' || *p == 'E')) {
        const char *q = p + 1;
        int eneg = 0;
        if (q < e && (*q == '-' || *q == '+')) {
            eneg = *q == '-';
            q++;
        }
        if (q >= e || !is_digit(*q))
            return -1;
        int ev = 0;
        while (q < e && is_digit(*q)) {
            if (ev < 100000)
                ev = ev * 10 + (*q - '0');
            q++;
        }
        exp10 += eneg ? -ev : ev;
        p = q;
    }
    if (p < e && !is_space(*p))
        goto slow;
    if (!overflow && mant <= (1ull << 53) && exp10 >= -22 && exp10 <= 22) {
        double v = (double)mant;
        v = exp10 < 0 ? v / pow10_tab[-exp10] : v * pow10_tab[exp10];
        *out = neg ? -v : v;
        *pp = p;
        return 0;
    }
slow:;
    /* Find the token's end, then let strtod judge it on a terminated copy. */
    const char *t = s;
    while (t < e && !is_space(*t))
        t++;
    char buf[512];
    size_t n = (size_t)(t - s);
    if (n == 0 || n >= sizeof buf)
        return -1;
    memcpy(buf, s, n);
    buf[n] = '\0';
    char *end;
    double v = strtod(buf, &end);
    if (end != buf + n)
        return -1;
    if (!isfinite(v))
        return -2;
    *out = v;
    *pp = t;
    return 0;
}

/* Parses an optionally signed decimal integer; 0 on success. Values beyond ±2^62 are
 * clamped (they are out of range for any mesh anyway). */
static int parse_long(const char **pp, const char *e, long long *out)
{
    const char *p = *pp;
    int neg = 0;
    if (p < e && (*p == '-' || *p == '+')) {
        neg = *p == '-';
        p++;
    }
    if (p >= e || !is_digit(*p))
        return -1;
    long long v = 0;
    while (p < e && is_digit(*p)) {
        if (v < (1ll << 58))
            v = v * 10 + (*p - '0');
        p++;
    }
    *out = neg ? -v : v;
    *pp = p;
    return 0;
}

/* ---- group names → components ------------------------------------------------------------ */

typedef struct {
    uint64_t *hash;
    uint32_t *group; /* group index + 1; 0 = empty slot */
    size_t cap, n;
} name_map;

static uint64_t hash_bytes(const char *s, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ (unsigned char)s[i]) * 1099511628211ull;
    return h;
}

static void map_free(name_map *mp)
{
    free(mp->hash);
    free(mp->group);
}

/* Finds name; returns the group index or -1. */
static long map_find(const name_map *mp, const ag_mesh *m, const char *name, size_t len,
                     uint64_t h)
{
    if (!mp->cap)
        return -1;
    for (size_t i = h & (mp->cap - 1);; i = (i + 1) & (mp->cap - 1)) {
        if (!mp->group[i])
            return -1;
        uint32_t g = mp->group[i] - 1;
        if (mp->hash[i] == h && strlen(m->group_names[g]) == len &&
            memcmp(m->group_names[g], name, len) == 0)
            return g;
    }
}

static int map_insert(name_map *mp, uint64_t h, uint32_t g)
{
    if (2 * (mp->n + 1) > mp->cap) {
        size_t ncap = mp->cap ? mp->cap * 2 : 64;
        uint64_t *nh = calloc(ncap, sizeof *nh);
        uint32_t *ng = calloc(ncap, sizeof *ng);
        if (!nh || !ng) {
            free(nh);
            free(ng);
            return -1;
        }
        for (size_t i = 0; i < mp->cap; i++)
            if (mp->group[i]) {
                size_t j = mp->hash[i] & (ncap - 1);
                while (ng[j])
                    j = (j + 1) & (ncap - 1);
                nh[j] = mp->hash[i];
                ng[j] = mp->group[i];
            }
        map_free(mp);
        mp->hash = nh;
        mp->group = ng;
        mp->cap = ncap;
    }
    size_t j = h & (mp->cap - 1);
    while (mp->group[j])
        j = (j + 1) & (mp->cap - 1);
    mp->hash[j] = h;
    mp->group[j] = g + 1;
    mp->n++;
    return 0;
}

/* ---- the reader ------------------------------------------------------------------------- */

typedef struct {
    ag_mesh *m;
    ag_error *err;
    int yup;
    size_t max_v, max_t;
    long line;
    size_t nvt, nvn;
    /* The group named by the last g/o line, resolved to a component at the first face. */
    const char *pend;
    size_t pend_len;
    int have_pend;
    long cur_comp;  /* component that faces go to, or -1 when not resolved yet */
    long nogroup_comp; /* the component of faces before any g/o, or -1 */
    uint32_t *comp_of_group;
    size_t cap_cg;
    name_map map;
    uint32_t *poly;
    size_t cap_poly;
    char *joined; /* scratch for lines with '\' continuations */
    size_t cap_joined;
    char *held_name; /* a group name from a continued line (names point into the input) */
    /* The later part of a split read (read_part): the counts before it are not known yet,
     * so its faces keep indices that merge() resolves, and what only a read in turn can
     * decide (an error, a face mixing absolute and relative indices) stops it: that part
     * is then read again after the first. */
    int later;
    size_t need_v, need_vt, need_vn; /* the most vertices (texture, normal) defined before
                                        the part that its faces need */
} reader;

/* A later part's vertex index: an absolute (1-based) index as it is, a relative one as
 * LATER_LOCAL + LATER_BIAS + its position among the part's own vertices (negative for the
 * vertices before the part), which merge() resolves. */
#define LATER_LOCAL 0x80000000u
#define LATER_BIAS 0x40000000

static ag_status perr(reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static ag_status perr(reader *r, const char *fmt, ...)
{
    if (r->err) {
        char msg[AG_ERROR_TEXT];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        ag_error_set(r->err, AG_ERR_PARSE, r->line, "line %ld: %s", r->line, msg);
    }
    return AG_ERR_PARSE;
}

static ag_status nomem(reader *r)
{
    return ag_error_set(r->err, AG_ERR_NOMEM, r->line, "line %ld: out of memory", r->line);
}

/* Quotes the token at p for a message (bounded, non-printable bytes escaped). */
static const char *quote(const char *p, const char *e, char *buf, size_t cap)
{
    size_t k = 0;
    while (p < e && !is_space(*p) && k + 5 < cap && k < NAME_SHOWN) {
        unsigned char c = (unsigned char)*p++;
        if (c < 0x20 || c == 0x7f)
            k += (size_t)snprintf(buf + k, cap - k, "\\x%02x", c);
        else
            buf[k++] = (char)c;
    }
    buf[k] = '\0';
    return buf;
}

static ag_status read_vertex(reader *r, const char *p, const char *e)
{
    double c[3];
    for (int k = 0; k < 3; k++) {
        while (p < e && is_space(*p))
            p++;
        if (p >= e)
            return perr(r, "vertex needs 3 coordinates, found %d", k);
        const char *s = p;
        int rc = parse_double(&p, e, &c[k]);
        if (rc) {
            char q[64];
            return perr(r, rc == -2 ? "coordinate '%s' is not a finite number"
                                    : "cannot parse coordinate '%s'",
                        quote(s, e, q, sizeof q));
        }
    }
    /* Anything after x y z (w, or a vertex colour) is ignored. */
    if (r->m->nverts >= r->max_v)
        return perr(r, "more than %zu vertices", r->max_v);
    ag_status st = r->yup ? ag_mesh_add_vertex(r->m, c[0], -c[2], c[1])
                          : ag_mesh_add_vertex(r->m, c[0], c[1], c[2]);
    if (st == AG_ERR_TOO_LARGE)
        return perr(r, "more than %u vertices", (unsigned)UINT32_MAX);
    return st == AG_OK ? AG_OK : nomem(r);
}

/* Resolves a 1-based or negative (relative) index against count defined elements. */
static int resolve(long long idx, size_t count, size_t *out)
{
    if (idx > 0) {
        if ((unsigned long long)idx > count)
            return -1;
        *out = (size_t)idx - 1;
        return 0;
    }
    if (idx < 0 && (unsigned long long)(-idx) <= count) {
        *out = count - (size_t)(-idx);
        return 0;
    }
    return -1;
}

static ag_status current_component(reader *r, uint32_t *comp)
{
    if (r->cur_comp >= 0) {
        *comp = (uint32_t)r->cur_comp;
        return AG_OK;
    }
    ag_mesh *m = r->m;
    size_t c;
    if (!r->have_pend) {
        if (r->nogroup_comp < 0) {
            if (ag_mesh_add_component(m, -1, &c) != AG_OK)
                return nomem(r);
            r->nogroup_comp = (long)c;
        }
        r->cur_comp = r->nogroup_comp;
    } else {
        uint64_t h = hash_bytes(r->pend, r->pend_len);
        long g = map_find(&r->map, m, r->pend, r->pend_len, h);
        if (g >= 0) {
            r->cur_comp = r->comp_of_group[g];
        } else {
            char *name = strndup(r->pend, r->pend_len);
            size_t gi;
            if (!name)
                return nomem(r);
            ag_status st = ag_mesh_add_group(m, name, &gi);
            free(name);
            if (st != AG_OK || ag_mesh_add_component(m, (int32_t)gi, &c) != AG_OK)
                return nomem(r);
            if (gi >= r->cap_cg) {
                size_t ncap = r->cap_cg ? 2 * r->cap_cg : 64;
                uint32_t *p = realloc(r->comp_of_group, ncap * sizeof *p);
                if (!p)
                    return nomem(r);
                r->comp_of_group = p;
                r->cap_cg = ncap;
            }
            r->comp_of_group[gi] = (uint32_t)c;
            if (map_insert(&r->map, h, (uint32_t)gi))
                return nomem(r);
            r->cur_comp = (long)c;
        }
    }
    *comp = (uint32_t)r->cur_comp;
    return AG_OK;
}

/* An index of a later part's face (reader.later): its encoding, what it needs defined
 * before the part, 0; -1 when only a read in turn can take it. */
static int later_index(reader *r, long long idx, size_t *v, int *kinds)
{
    size_t nv = r->m->nverts;
    if (idx > 0) {
        if ((unsigned long long)idx >= LATER_LOCAL)
            return -1;
        if ((unsigned long long)idx > nv && (size_t)idx - nv > r->need_v)
            r->need_v = (size_t)idx - nv;
        *v = (size_t)idx - 1;
        *kinds |= 1;
    } else {
        if (idx == 0 || nv >= LATER_BIAS || idx < -(long long)LATER_BIAS)
            return -1;
        long long local = (long long)nv + idx;
        if (local < 0 && (size_t)-local > r->need_v)
            r->need_v = (size_t)-local;
        *v = LATER_LOCAL + (size_t)(local + LATER_BIAS);
        *kinds |= 2;
    }
    /* one vertex named both ways is equal only once resolved: the dropped degenerate
     * triangles are decided in turn */
    return *kinds == 3 ? -1 : 0;
}

/* A later part's texture or normal index: what it needs before the part, 0; -1 for 0. */
static int later_count(long long j, size_t count, size_t *need)
{
    if (j == 0)
        return -1;
    unsigned long long a = j > 0 ? (unsigned long long)j : (unsigned long long)-j;
    if (a > count && a - count > *need)
        *need = (size_t)(a - count);
    return 0;
}

static ag_status read_face(reader *r, const char *p, const char *e)
{
    size_t n = 0;
    size_t nv = r->m->nverts;
    int kinds = 0; /* a later part: 1 absolute indices, 2 relative ones */
    for (;;) {
        while (p < e && is_space(*p))
            p++;
        if (p >= e)
            break;
        const char *s = p;
        long long idx;
        char q[64];
        if (parse_long(&p, e, &idx))
            return perr(r, "bad face vertex '%s'", quote(s, e, q, sizeof q));
        size_t v;
        if (r->later) {
            if (later_index(r, idx, &v, &kinds))
                return AG_ERR_PARSE;
        } else if (idx == 0)
            return perr(r, "face index 0 is invalid (OBJ indices start at 1)");
        else if (resolve(idx, nv, &v))
            return perr(r, "face index %lld out of range (file has %zu vertices so far)", idx,
                        nv);
        /* Optional /vt and /vn parts: checked, then ignored. */
        for (int part = 0; part < 2 && p < e && *p == '/'; part++) {
            p++;
            if (p < e && (is_digit(*p) || *p == '-' || *p == '+')) {
                long long j;
                size_t dummy, count = part == 0 ? r->nvt : r->nvn;
                if (parse_long(&p, e, &j))
                    return perr(r, "bad face vertex '%s'", quote(s, e, q, sizeof q));
                if (r->later) {
                    if (later_count(j, count, part == 0 ? &r->need_vt : &r->need_vn))
                        return AG_ERR_PARSE;
                } else if (resolve(j, count, &dummy))
                    return perr(r, "face %s index %lld out of range (file has %zu so far)",
                                part == 0 ? "texture" : "normal", j, count);
            }
        }
        if (p < e && !is_space(*p))
            return perr(r, "bad face vertex '%s'", quote(s, e, q, sizeof q));
        if (n == r->cap_poly) {
            size_t ncap = r->cap_poly ? 2 * r->cap_poly : 64;
            uint32_t *np = realloc(r->poly, ncap * sizeof *np);
            if (!np)
                return nomem(r);
            r->poly = np;
            r->cap_poly = ncap;
        }
        r->poly[n++] = (uint32_t)v;
    }
    if (n < 3)
        return perr(r, "face needs at least 3 vertices, found %zu", n);
    uint32_t comp = 0;
    ag_status st = current_component(r, &comp);
    if (st)
        return st;
    const uint32_t *f = r->poly;
    for (size_t i = 1; i + 1 < n; i++) {
        /* A repeated index makes no triangle; geometrically flat ones are kept. */
        if (f[0] == f[i] || f[0] == f[i + 1] || f[i] == f[i + 1])
            continue;
        if (r->m->ntris >= r->max_t)
            return perr(r, "more than %zu triangles", r->max_t);
        if (ag_mesh_add_triangle(r->m, f[0], f[i], f[i + 1], comp) != AG_OK)
            return nomem(r);
    }
    return AG_OK;
}

static void set_group(reader *r, const char *p, const char *e)
{
    while (p < e && is_space(*p))
        p++;
    while (e > p && is_space(e[-1]))
        e--;
    if (p == e) { /* `g` alone: OBJ's default group */
        p = "default";
        e = p + 7;
    }
    r->pend = p;
    r->pend_len = (size_t)(e - p);
    r->have_pend = 1;
    r->cur_comp = -1;
}

/* One logical line [p, e) (no newline). */
static ag_status read_line(reader *r, const char *p, const char *e)
{
    while (p < e && is_space(*p))
        p++;
    if (p >= e || *p == '#')
        return AG_OK;
    /* a comment after the data (`f 1 2 3 # roof`, as some exporters write): a '#' after
     * white space ends the line; one inside a name (`g wall#3`) does not */
    for (const char *c = p + 1; c < e; c++)
        if (*c == '#' && is_space(c[-1])) {
            e = c;
            break;
        }
    const char *k = p;
    while (p < e && !is_space(*p))
        p++;
    size_t kl = (size_t)(p - k);
    if (kl == 1) {
        switch (k[0]) {
        case 'v':
            return read_vertex(r, p, e);
        case 'f':
            return read_face(r, p, e);
        case 'g':
        case 'o':
            /* Resolved lazily at the next face; the name points into the input (or into
             * a copy the caller keeps for continued lines). */
            set_group(r, p, e);
            return AG_OK;
        default:
            break;
        }
    } else if (kl == 2 && k[0] == 'v' && k[1] == 't') {
        r->nvt++;
        return AG_OK;
    } else if (kl == 2 && k[0] == 'v' && k[1] == 'n') {
        r->nvn++;
        return AG_OK;
    }
    /* Other statements (usemtl, mtllib, s, l, p, vp, curves...) are accepted and ignored:
     * materials do not shape the mesh, and the reader opens no file (an upload's mtllib may
     * name any path of the server). Control characters mark binary data, not text. */
    for (const char *c = k; c < e; c++) {
        unsigned char u = (unsigned char)*c;
        if ((u < 0x20 && !is_space((char)u)) || u == 0x7f) {
            char q[64];
            return perr(r, "unexpected data '%s' (binary, not an OBJ statement)",
                        quote(k, k + kl, q, sizeof q));
        }
    }
    return AG_OK;
}

/* Reads the lines of [p, end) of data (len bytes in all) into r, counting them on from
 * *line; progress (NULL for none) is asked each PROGRESS_STEP bytes past *next_progress. */
static ag_status read_lines(reader *r, const char *data, size_t len, const char *p,
                            const char *end, long *line, const ag_obj_read_options *progress,
                            size_t *next_progress)
{
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        ++*line;
        r->line = *line;
        const char *q = le;
        while (q > p && (q[-1] == '\r' || q[-1] == ' ' || q[-1] == '\t'))
            q--;
        ag_status st;
        if (q > p && q[-1] == '\\' && nl) {
            /* Continuation: join the physical lines (backslash-newline → space). */
            size_t n = 0;
            const char *s = p;
            for (;;) {
                const char *ne = memchr(s, '\n', (size_t)(end - s));
                const char *se = ne ? ne : end;
                const char *t = se;
                while (t > s && (t[-1] == '\r' || t[-1] == ' ' || t[-1] == '\t'))
                    t--;
                int cont = ne && t > s && t[-1] == '\\';
                size_t piece = (size_t)((cont ? t - 1 : se) - s);
                if (n + piece + 1 > r->cap_joined) {
                    size_t ncap = (n + piece + 1) * 2;
                    char *nj = realloc(r->joined, ncap);
                    if (!nj)
                        return nomem(r);
                    r->joined = nj;
                    r->cap_joined = ncap;
                }
                memcpy(r->joined + n, s, piece);
                n += piece;
                r->joined[n++] = ' ';
                s = ne ? ne + 1 : end;
                if (!cont)
                    break;
                ++*line;
            }
            p = s;
            const char *js = r->joined, *je = r->joined + n;
            const char *ks = js;
            while (ks < je && is_space(*ks))
                ks++;
            if (je - ks >= 2 && (ks[0] == 'g' || ks[0] == 'o') && is_space(ks[1])) {
                /* The scratch buffer is reused: keep the group name elsewhere. */
                char *copy = malloc(n);
                if (!copy)
                    return nomem(r);
                memcpy(copy, js, n);
                free(r->held_name);
                r->held_name = copy;
                js = copy;
                je = copy + n;
            }
            st = read_line(r, js, je);
        } else {
            st = read_line(r, p, le);
            p = nl ? nl + 1 : end;
        }
        if (st != AG_OK)
            return st;
        if (progress && (size_t)(p - data) >= *next_progress) {
            *next_progress = (size_t)(p - data) + PROGRESS_STEP;
            if (progress->progress &&
                progress->progress(progress->user, (double)(p - data) / (double)len))
                return ag_error_set(r->err, AG_ERR_CANCELLED, *line, "cancelled at line %ld",
                                    *line);
        }
    }
    return AG_OK;
}

static void reader_free(reader *r)
{
    free(r->held_name);
    free(r->comp_of_group);
    free(r->poly);
    free(r->joined);
    map_free(&r->map);
}

/* Below this many bytes a file is read in one part: a thread costs more than it saves. */
#define SPLIT_BYTES ((size_t)1 << 20)

/* Where a read in two parts splits [p, end): after the newline ending the first line past
 * the middle that does not continue (no '\' at its end); NULL when there is none. */
static const char *split_point(const char *p, const char *end)
{
    const char *s = p + (size_t)(end - p) / 2;
    for (;;) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        if (!nl || nl + 1 >= end)
            return NULL;
        const char *t = nl;
        while (t > p && (t[-1] == '\r' || t[-1] == ' ' || t[-1] == '\t'))
            t--;
        if (!(t > p && t[-1] == '\\'))
            return nl + 1;
        s = nl + 1;
    }
}

/* The two parts of a split read: the first read as a read in turn reads it, the later one
 * on its own (reader.later) into a mesh of its own. */
typedef struct {
    reader *first, *later;
    const char *data, *start, *split, *end; /* start: past a byte order mark */
    size_t len;
    const ag_obj_read_options *opt;
    long line;                 /* the first part's last line */
    size_t next_progress;
    ag_status first_st, later_st;
} split_read;

static void read_part(void *ctx, size_t part)
{
    split_read *sr = ctx;
    if (part == 0) {
        sr->first_st = read_lines(sr->first, sr->data, sr->len, sr->start,
                                  sr->split, &sr->line, sr->opt, &sr->next_progress);
    } else {
        long line = 0;
        sr->later_st = read_lines(sr->later, sr->data, sr->len, sr->split, sr->end, &line, NULL,
                                  NULL);
    }
}
/* Appends the later part l to the first part r, as reading on in turn would have made
 * it: its vertices after r's, its relative indices resolved, its components those its
 * groups name in r (the first of them, when its faces start before any g/o line, r's
 * current one). The caller checked l's needs against r's counts. */
static ag_status merge(reader *r, const reader *l)
{
    ag_mesh *m = r->m;
    const ag_mesh *lm = l->m;
    size_t nv0 = m->nverts, nt0 = m->ntris;
    uint32_t *comp = malloc((lm->ncomponents + 1) * sizeof *comp);
    if (!comp)
        return nomem(r);
    ag_status st = AG_OK;
    for (size_t c = 0; c < lm->ncomponents && st == AG_OK; c++) {
        if ((long)c != l->nogroup_comp) { /* a group of the later part: resolved as its g line */
            const char *name = lm->group_names[lm->component_group[c]];
            r->pend = name;
            r->pend_len = strlen(name);
            r->have_pend = 1;
            r->cur_comp = -1;
        }
        st = current_component(r, &comp[c]);
    }
    r->have_pend = 0; /* the names were l's */
    if (st == AG_OK && ag_mesh_reserve(m, nv0 + lm->nverts, nt0 + lm->ntris) != AG_OK)
        st = nomem(r);
    if (st == AG_OK) {
        memcpy(m->pos + 3 * nv0, lm->pos, 3 * lm->nverts * sizeof *lm->pos);
        for (size_t t = 0; t < lm->ntris; t++) {
            for (int k = 0; k < 3; k++) {
                uint32_t v = lm->tri[3 * t + k];
                m->tri[3 * (nt0 + t) + k] =
                    v >= LATER_LOCAL
                        ? (uint32_t)((long long)nv0 + (long long)(v - LATER_LOCAL) - LATER_BIAS)
                        : v;
            }
            m->tri_component[nt0 + t] = comp[lm->tri_component[t]];
        }
        m->nverts += lm->nverts;
        m->ntris += lm->ntris;
        r->nvt += l->nvt;
        r->nvn += l->nvn;
    }
    free(comp);
    return st;
}

/* Whether the later part can be merged: it read to its end, the indices its faces need
 * before it are defined by the first part, and the counts stay within the limits (else it
 * is read again in turn, which says what is wrong where). */
static int mergeable(const split_read *sr)
{
    const reader *r = sr->first, *l = sr->later;
    return sr->later_st == AG_OK && l->need_v <= r->m->nverts && l->need_vt <= r->nvt &&
           l->need_vn <= r->nvn && r->m->nverts + l->m->nverts <= r->max_v &&
           r->m->nverts + l->m->nverts < LATER_LOCAL && r->m->ntris + l->m->ntris <= r->max_t;
}

static void reader_init(reader *r, const ag_obj_read_options *opt, ag_error *err)
{
    memset(r, 0, sizeof *r);
    r->err = err;
    r->yup = opt->up != AG_UP_Z;
    r->max_v = opt->max_vertices ? opt->max_vertices : DEFAULT_MAX_VERTICES;
    r->max_t = opt->max_triangles ? opt->max_triangles : DEFAULT_MAX_TRIANGLES;
    r->cur_comp = -1;
    r->nogroup_comp = -1;
    r->m = ag_mesh_create();
}

/* Room for about len bytes of lines: a typical OBJ line is ~30 bytes, so len/60 leaves
 * room for a balanced file. */
static void reserve_for(reader *r, size_t len)
{
    size_t guess_v = len / 60, guess_t = len / 60;
    if (guess_v > r->max_v)
        guess_v = r->max_v;
    if (guess_t > r->max_t)
        guess_t = r->max_t;
    if (guess_v > (1u << 24))
        guess_v = 1u << 24;
    if (guess_t > (1u << 24))
        guess_t = 1u << 24;
    (void)ag_mesh_reserve(r->m, guess_v, guess_t);
}

ag_status ag_obj_read_buffer(const char *data, size_t len, const ag_obj_read_options *opt,
                             ag_mesh **out, ag_error *err)
{
    static const ag_obj_read_options defaults;
    if (!opt)
        opt = &defaults;
    *out = NULL;
    ag_error_clear(err);

    /* NUL never occurs in an OBJ file; finding one early rejects binary input cheaply. */
    const char *nul = len ? memchr(data, '\0', len) : NULL;
    if (nul) {
        long line = 1;
        for (const char *c = data; c < nul; c++)
            line += *c == '\n';
        return ag_error_set(err, AG_ERR_PARSE, line, "line %ld: NUL byte (binary data, not an OBJ file)",
                            line);
    }

    reader r, later = {0};
    reader_init(&r, opt, err);
    if (!r.m)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    reserve_for(&r, len);

    ag_status st = AG_OK;
    const char *p = data, *end = data + len;
    if (len >= 3 && (unsigned char)p[0] == 0xEF && (unsigned char)p[1] == 0xBB &&
        (unsigned char)p[2] == 0xBF)
        p += 3; /* UTF-8 byte order mark */
    size_t next_progress = PROGRESS_STEP;
    long line = 0;
    /* a large file on a machine with threads: its second half read beside the first */
    size_t split_bytes = opt->split_bytes ? opt->split_bytes : SPLIT_BYTES;
    const char *split = len >= split_bytes && ag_parallel_threads() > 1
                            ? split_point(p, end)
                            : NULL;
    ag_error later_err;
    ag_error_clear(&later_err);
    if (split) {
        reader_init(&later, opt, &later_err);
        later.later = 1;
        if (!later.m)
            split = NULL;
        else
            reserve_for(&later, (size_t)(end - split));
    }
    if (split) {
        split_read sr = {.first = &r, .later = &later, .data = data, .start = p,
                         .split = split, .end = end, .len = len, .opt = opt,
                         .next_progress = next_progress};
        ag_parallel_run(2, read_part, &sr);
        line = sr.line;
        next_progress = sr.next_progress;
        if ((st = sr.first_st) != AG_OK)
            goto done;
        if (mergeable(&sr)) {
            if ((st = merge(&r, &later)) != AG_OK)
                goto done;
            p = end;
        } else {
            p = split; /* read on in turn */
        }
    }
    st = read_lines(&r, data, len, p, end, &line, opt, &next_progress);
    if (st != AG_OK)
        goto done;
    if (opt->progress && opt->progress(opt->user, 1.0)) {
        st = ag_error_set(err, AG_ERR_CANCELLED, line, "cancelled at line %ld", line);
        goto done;
    }
    if (r.m->ntris == 0) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0,
                          r.m->nverts ? "no faces (the file has %zu vertices and no triangle)"
                                      : "no geometry (%zu vertices, no faces)",
                          r.m->nverts);
        goto done;
    }
    /* Without any group the connected pieces are the components, and so they are when one
     * group (typically a lone `o`) holds the whole file: it carries no segmentation. Files
     * with several groups keep them whole, even with loose pieces inside (the
     * proceduralization stage decides). */
    if ((r.m->ngroups == 0 || (r.m->ngroups == 1 && r.m->ncomponents == 1)) &&
        (st = ag_mesh_split_connected(r.m)) != AG_OK) {
        st = ag_error_set(err, st, 0, "out of memory");
        goto done;
    }
done:
    reader_free(&r);
    reader_free(&later);
    ag_mesh_free(later.m);
    if (st != AG_OK) {
        ag_mesh_free(r.m);
        return st;
    }
    *out = r.m;
    return AG_OK;
}

ag_status ag_obj_read_file(const char *path, const ag_obj_read_options *opt, ag_mesh **out,
                           ag_error *err)
{
    *out = NULL;
    ag_filemap fm;
    ag_status st = ag_filemap_open(path, &fm, err);
    if (st != AG_OK)
        return st;
    if (fm.len == 0)
        st = ag_error_set(err, AG_ERR_EMPTY, 0, "%s: empty file", path);
    else
        st = ag_obj_read_buffer((const char *)fm.data, fm.len, opt, out, err);
    ag_filemap_close(&fm);
    return st;
}

/* ---- writer ----------------------------------------------------------------------------- */

/* The writer's output: lines are built in a buffer and written in large blocks (printf
 * per number was most of the time of writing a city). */
typedef struct {
    FILE *f;
    size_t n;
    char buf[1 << 16];
} out_buf;

static void flush(out_buf *o)
{
    if (o->n)
        fwrite(o->buf, 1, o->n, o->f);
    o->n = 0;
}

/* Room for at least `need` more bytes (need <= sizeof buf). */
static char *room(out_buf *o, size_t need)
{
    if (o->n + need > sizeof o->buf)
        flush(o);
    return o->buf + o->n;
}

static void put_text(out_buf *o, const char *s)
{
    for (; *s; s++) {
        room(o, 1);
        o->buf[o->n++] = *s;
    }
}

static void put_name(out_buf *o, const char *name)
{
    for (const char *c = name; *c; c++) {
        room(o, 1);
        o->buf[o->n++] = *c == '\n' || *c == '\r' || *c == '\\' ? '_' : *c;
    }
}

/* "v x y z\n" with every coordinate exact (io/numtext.h). */
static void put_vertex(out_buf *o, double x, double y, double z)
{
    char *p = room(o, 3 * AG_NUMTEXT_MAX + 4);
    size_t k = 0;
    p[k++] = 'v';
    p[k++] = ' ';
    k += ag_numtext_double(p + k, x);
    p[k++] = ' ';
    k += ag_numtext_double(p + k, y);
    p[k++] = ' ';
    k += ag_numtext_double(p + k, z);
    p[k++] = '\n';
    o->n += k;
}

static void put_face(out_buf *o, uint32_t a, uint32_t b, uint32_t c)
{
    char *p = room(o, 3 * AG_NUMTEXT_MAX + 4);
    size_t k = 0;
    p[k++] = 'f';
    p[k++] = ' ';
    k += ag_numtext_u64(p + k, (uint64_t)a + 1);
    p[k++] = ' ';
    k += ag_numtext_u64(p + k, (uint64_t)b + 1);
    p[k++] = ' ';
    k += ag_numtext_u64(p + k, (uint64_t)c + 1);
    p[k++] = '\n';
    o->n += k;
}

ag_status ag_obj_write_file(const ag_mesh *m, ag_up_axis up, const char *path, ag_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
    out_buf *o = malloc(sizeof *o);
    if (!o) {
        fclose(f);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    o->f = f;
    o->n = 0;
    int yup = up != AG_UP_Z;
    char head[160];
    snprintf(head, sizeof head, "# archgram: %zu vertices, %zu triangles, %zu components; %s up\n",
             m->nverts, m->ntris, m->ncomponents, yup ? "y" : "z");
    put_text(o, head);
    for (size_t i = 0; i < m->nverts; i++) {
        const double *p = m->pos + 3 * i;
        if (yup) /* inverse of the reader's (x, y, z) → (x, -z, y) */
            put_vertex(o, p[0], p[2], -p[1]);
        else
            put_vertex(o, p[0], p[1], p[2]);
    }
    /* Triangles grouped by component, in file order within each. */
    size_t nc = m->ncomponents;
    size_t *start = calloc(nc + 1, sizeof *start);
    uint32_t *order = malloc((m->ntris ? m->ntris : 1) * sizeof *order);
    if (!start || !order) {
        free(start);
        free(order);
        free(o);
        fclose(f);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t t = 0; t < m->ntris; t++)
        start[m->tri_component[t] + 1]++;
    for (size_t c = 0; c < nc; c++)
        start[c + 1] += start[c];
    for (size_t t = 0; t < m->ntris; t++)
        order[start[m->tri_component[t]]++] = (uint32_t)t;
    for (size_t c = nc; c > 0; c--) /* start[c] now holds the end of c; shift back */
        start[c] = start[c - 1];
    start[0] = 0;
    /* A mesh with no groups at all is written without g lines: reading it back splits it
     * into its connected pieces again. Components sharing a group merge when read back. */
    int named = m->ngroups > 0;
    for (size_t c = 0; c < nc; c++) {
        if (start[c] == start[c + 1])
            continue;
        int32_t g = m->component_group[c];
        /* A group-less first component is written before any g line, where the reader
         * puts group-less faces. */
        if (named && !(c == 0 && g < 0)) {
            put_text(o, "g ");
            if (g >= 0 && (size_t)g < m->ngroups && m->group_names[g][0]) {
                put_name(o, m->group_names[g]);
            } else {
                char name[48];
                snprintf(name, sizeof name, "component_%zu", c);
                put_text(o, name);
            }
            put_text(o, "\n");
        }
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            const uint32_t *t = m->tri + 3 * (size_t)order[i];
            put_face(o, t[0], t[1], t[2]);
        }
    }
    flush(o);
    free(o);
    free(start);
    free(order);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(errno));
    return AG_OK;
}
