#include "ply.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h"

#define MAX_HEADER (1u << 20) /* bytes */
#define MAX_LINE 4096
#define MAX_ELEMENTS 64
#define MAX_TOKEN 96 /* characters of one ASCII value */

enum { TARGET_SKIP = -1, TARGET_X = 0, TARGET_NX = 3, TARGET_PROP = 6 };

typedef struct {
    char name[AG_CLOUD_NAME_MAX];
    ag_scalar_type type;       /* the value type; for a list the item type */
    int is_list;
    ag_scalar_type count_type; /* for a list */
    int target;                /* TARGET_SKIP, TARGET_X + axis, TARGET_NX + axis, TARGET_PROP */
    size_t prop;               /* index in the cloud for TARGET_PROP */
    size_t offset;             /* byte offset in a fixed-size binary row */
} ply_prop;

typedef struct {
    char name[64];
    uint64_t count;
    size_t nprops;
    ply_prop *props;
    int has_list;
    size_t row_bytes; /* fixed part of a binary row (all of it without lists) */
} ply_element;

typedef struct {
    enum { FMT_ASCII, FMT_LE, FMT_BE } format;
    size_t nelements;
    ply_element elements[MAX_ELEMENTS];
    int has_offset;
    double offset[3];
    size_t data_start; /* first byte after end_header's newline */
    size_t header_lines;
} ply_header;

static const struct {
    const char *name;
    ag_scalar_type type;
} type_names[] = {
    {"char", AG_SCALAR_INT8},      {"int8", AG_SCALAR_INT8},     {"uchar", AG_SCALAR_UINT8},
    {"uint8", AG_SCALAR_UINT8},    {"short", AG_SCALAR_INT16},   {"int16", AG_SCALAR_INT16},
    {"ushort", AG_SCALAR_UINT16},  {"uint16", AG_SCALAR_UINT16}, {"int", AG_SCALAR_INT32},
    {"int32", AG_SCALAR_INT32},    {"uint", AG_SCALAR_UINT32},   {"uint32", AG_SCALAR_UINT32},
    {"float", AG_SCALAR_FLOAT32},  {"float32", AG_SCALAR_FLOAT32},
    {"double", AG_SCALAR_FLOAT64}, {"float64", AG_SCALAR_FLOAT64},
};

static int parse_type(const char *s, ag_scalar_type *t)
{
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++)
        if (!strcmp(s, type_names[i].name)) {
            *t = type_names[i].type;
            return 0;
        }
    return -1;
}

static void header_free(ply_header *h)
{
    for (size_t i = 0; i < h->nelements; i++)
        free(h->elements[i].props);
    h->nelements = 0;
}

/* Splits a NUL-terminated line into at most max whitespace-separated tokens. */
static size_t split(char *line, char **tok, size_t max)
{
    size_t n = 0;
    char *p = line;
    while (*p && n < max) {
        while (*p == ' ' || *p == '\t' || *p == '\r')
            p++;
        if (!*p)
            break;
        tok[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r')
            p++;
        if (*p)
            *p++ = 0;
    }
    return n;
}

static int parse_count(const char *s, uint64_t *out)
{
    if (!*s || *s == '-' || *s == '+')
        return -1;
    errno = 0;
    char *end;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end)
        return -1;
    *out = v;
    return 0;
}

static ag_status parse_header(const uint8_t *data, size_t len, ply_header *h, ag_error *err)
{
    memset(h, 0, sizeof *h);
    if (len < 4 || memcmp(data, "ply", 3) != 0 || (data[3] != '\n' && data[3] != '\r'))
        return ag_error_set(err, AG_ERR_PARSE, 1, "line 1: not a PLY file (no 'ply' magic line)");
    size_t pos = 0, line_no = 0;
    int have_format = 0;
    char line[MAX_LINE + 1];
    for (;;) {
        if (pos >= len || pos >= MAX_HEADER) {
            header_free(h);
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                pos >= len ? "the header has no end_header line"
                                           : "the header is longer than %u bytes", MAX_HEADER);
        }
        const uint8_t *nl = memchr(data + pos, '\n', len - pos);
        size_t end = nl ? (size_t)(nl - data) : len;
        size_t n = end - pos;
        line_no++;
        if (n > MAX_LINE) {
            header_free(h);
            return ag_error_set(err, AG_ERR_PARSE, (long)line_no,
                                "line %zu: header line longer than %d characters", line_no,
                                MAX_LINE);
        }
        memcpy(line, data + pos, n);
        line[n] = 0;
        if (memchr(line, 0, n)) {
            header_free(h);
            return ag_error_set(err, AG_ERR_PARSE, (long)line_no,
                                "line %zu: NUL byte in the header", line_no);
        }
        pos = nl ? end + 1 : len;
        char *tok[8];
        size_t nt = split(line, tok, 8);
        if (line_no == 1 || nt == 0)
            continue;
#define HEADER_FAIL(...)                                                                      \
    do {                                                                                       \
        header_free(h);                                                                        \
        char msg_[200];                                                                        \
        snprintf(msg_, sizeof msg_, __VA_ARGS__);                                              \
        return ag_error_set(err, AG_ERR_PARSE, (long)line_no, "line %zu: %s", line_no, msg_); \
    } while (0)
        if (!strcmp(tok[0], "format")) {
            if (nt < 3 || strcmp(tok[2], "1.0"))
                HEADER_FAIL("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
            if (!strcmp(tok[1], "ascii"))
                h->format = FMT_ASCII;
            else if (!strcmp(tok[1], "binary_little_endian"))
                h->format = FMT_LE;
            else if (!strcmp(tok[1], "binary_big_endian"))
                h->format = FMT_BE;
            else
                HEADER_FAIL("unknown format '%.40s'", tok[1]);
            have_format = 1;
        } else if (!strcmp(tok[0], "comment") || !strcmp(tok[0], "obj_info")) {
            if (nt == 5 && !strcmp(tok[0], "comment") && !strcmp(tok[1], "offset")) {
                double o[3];
                for (int a = 0; a < 3; a++) {
                    char *e;
                    o[a] = strtod(tok[2 + a], &e);
                    if (*e || !isfinite(o[a]))
                        HEADER_FAIL("'comment offset' needs three finite numbers");
                }
                memcpy(h->offset, o, sizeof o);
                h->has_offset = 1;
            }
        } else if (!strcmp(tok[0], "element")) {
            if (nt != 3)
                HEADER_FAIL("expected 'element NAME COUNT'");
            if (h->nelements == MAX_ELEMENTS)
                HEADER_FAIL("more than %d elements", MAX_ELEMENTS);
            ply_element *el = &h->elements[h->nelements++];
            snprintf(el->name, sizeof el->name, "%s", tok[1]);
            if (parse_count(tok[2], &el->count))
                HEADER_FAIL("element '%.40s' has a bad count '%.40s'", tok[1], tok[2]);
        } else if (!strcmp(tok[0], "property")) {
            if (!h->nelements)
                HEADER_FAIL("property before any element");
            ply_element *el = &h->elements[h->nelements - 1];
            if (el->nprops == AG_CLOUD_MAX_PROPERTIES)
                HEADER_FAIL("element '%s' has more than %d properties", el->name,
                            AG_CLOUD_MAX_PROPERTIES);
            ply_prop pr;
            memset(&pr, 0, sizeof pr);
            const char *name;
            if (nt >= 2 && !strcmp(tok[1], "list")) {
                if (nt != 5)
                    HEADER_FAIL("expected 'property list COUNT_TYPE ITEM_TYPE NAME'");
                if (parse_type(tok[2], &pr.count_type) || ag_scalar_is_float(pr.count_type) ||
                    parse_type(tok[3], &pr.type))
                    HEADER_FAIL("bad list types '%.20s %.20s'", tok[2], tok[3]);
                pr.is_list = 1;
                name = tok[4];
                el->has_list = 1;
            } else {
                if (nt != 3)
                    HEADER_FAIL("expected 'property TYPE NAME'");
                if (parse_type(tok[1], &pr.type))
                    HEADER_FAIL("unknown property type '%.40s'", tok[1]);
                name = tok[2];
            }
            if (strlen(name) >= AG_CLOUD_NAME_MAX)
                HEADER_FAIL("property name longer than %d characters", AG_CLOUD_NAME_MAX - 1);
            for (size_t i = 0; i < el->nprops; i++)
                if (!strcmp(el->props[i].name, name))
                    HEADER_FAIL("property '%s' appears twice in element '%s'", name, el->name);
            strcpy(pr.name, name);
            ply_prop *props = realloc(el->props, (el->nprops + 1) * sizeof *props);
            if (!props) {
                header_free(h);
                return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            }
            el->props = props;
            if (!pr.is_list) {
                pr.offset = el->row_bytes;
                el->row_bytes += ag_scalar_size(pr.type);
            } else {
                el->row_bytes += ag_scalar_size(pr.count_type);
            }
            el->props[el->nprops++] = pr;
        } else if (!strcmp(tok[0], "end_header")) {
            break;
        } else {
            HEADER_FAIL("unknown header keyword '%.40s'", tok[0]);
        }
#undef HEADER_FAIL
    }
    if (!have_format) {
        header_free(h);
        return ag_error_set(err, AG_ERR_PARSE, 0, "the header has no format line");
    }
    h->data_start = pos;
    h->header_lines = line_no;
    return AG_OK;
}

/* Whether the rows h declares fit the bytes after it (see ag_ply_check_header). */
static ag_status check_rows_fit(const ply_header *h, size_t len, ag_error *err)
{
    ag_status st = AG_OK;
    /* every row of an element with properties takes bytes: its fixed part (binary), or a
     * character and a separator per value (ASCII, the last value of the file without one) */
    size_t remaining = len - h->data_start;
    uint64_t room = (uint64_t)remaining + (h->format == FMT_ASCII), need = 0;
    for (size_t i = 0; i < h->nelements && st == AG_OK; i++) {
        const ply_element *el = &h->elements[i];
        uint64_t row = h->format == FMT_ASCII ? 2 * (uint64_t)el->nprops : el->row_bytes;
        if (!row)
            continue;
        if (el->count > room / row || (need += el->count * row) > room)
            st = ag_error_set(err, AG_ERR_PARSE, 0,
                              "the header declares %llu %s rows of at least %llu bytes, more "
                              "than the %zu bytes of data after the header hold",
                              (unsigned long long)el->count, el->name, (unsigned long long)row,
                              remaining);
    }
    return st;
}

ag_status ag_ply_check_header(const uint8_t *data, size_t len, ag_error *err)
{
    ply_header h;
    ag_status st = parse_header(data, len, &h, err);
    if (st != AG_OK)
        return st;
    st = check_rows_fit(&h, len, err);
    header_free(&h);
    return st;
}

int ag_ply_has_faces(const uint8_t *data, size_t len)
{
    ply_header h;
    if (parse_header(data, len, &h, NULL) != AG_OK)
        return 0;
    int faces = 0;
    for (size_t i = 0; i < h.nelements; i++)
        if (!strcmp(h.elements[i].name, "face") && h.elements[i].count > 0)
            faces = 1;
    header_free(&h);
    return faces;
}

int ag_ply_vertex_count(const uint8_t *data, size_t len, uint64_t *count)
{
    ply_header h;
    if (parse_header(data, len, &h, NULL) != AG_OK)
        return -1;
    int found = -1;
    for (size_t i = 0; i < h.nelements; i++)
        if (!strcmp(h.elements[i].name, "vertex")) {
            *count = (uint64_t)h.elements[i].count;
            found = 0;
        }
    header_free(&h);
    return found;
}

/* ---- reading values ------------------------------------------------------------------ */

static double value_to_double(const void *v, ag_scalar_type t)
{
    switch (t) {
    case AG_SCALAR_INT8: return *(const int8_t *)v;
    case AG_SCALAR_UINT8: return *(const uint8_t *)v;
    case AG_SCALAR_INT16: return *(const int16_t *)v;
    case AG_SCALAR_UINT16: return *(const uint16_t *)v;
    case AG_SCALAR_INT32: return *(const int32_t *)v;
    case AG_SCALAR_UINT32: return *(const uint32_t *)v;
    case AG_SCALAR_INT64: return (double)*(const int64_t *)v;
    case AG_SCALAR_UINT64: return (double)*(const uint64_t *)v;
    case AG_SCALAR_FLOAT32: return *(const float *)v;
    case AG_SCALAR_FLOAT64: return *(const double *)v;
    default: return 0;
    }
}

/* Stores a host-order value into its destination in the cloud. */
static void store(ag_cloud *c, const ply_prop *pr, size_t i, const void *v)
{
    if (pr->target >= TARGET_X && pr->target < TARGET_NX)
        c->xyz[3 * i + (size_t)(pr->target - TARGET_X)] = value_to_double(v, pr->type);
    else if (pr->target >= TARGET_NX && pr->target < TARGET_PROP)
        c->normals[3 * i + (size_t)(pr->target - TARGET_NX)] = (float)value_to_double(v, pr->type);
    else if (pr->target == TARGET_PROP) {
        size_t s = ag_scalar_size(pr->type);
        memcpy((char *)c->props[pr->prop].values + i * s, v, s);
    }
}

/* Reads an unsigned list count stored in count_type; -1 when negative. */
static int64_t list_count(const void *v, ag_scalar_type t)
{
    double d = value_to_double(v, t);
    return d < 0 ? -1 : (int64_t)d;
}

typedef struct {
    const uint8_t *p, *end;
    size_t line;
} ascii_cursor;

/* The next whitespace-separated token, copied NUL-terminated into buf; -1 at the end of
 * the data, -2 when the token is too long. */
static int next_token(ascii_cursor *cur, char *buf)
{
    while (cur->p < cur->end) {
        uint8_t ch = *cur->p;
        if (ch == '\n')
            cur->line++;
        else if (ch != ' ' && ch != '\t' && ch != '\r' && ch != '\f' && ch != '\v')
            break;
        cur->p++;
    }
    if (cur->p >= cur->end)
        return -1;
    size_t n = 0;
    while (cur->p < cur->end) {
        uint8_t ch = *cur->p;
        if (ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\f' || ch == '\v')
            break;
        if (n == MAX_TOKEN)
            return -2;
        buf[n++] = (char)ch;
        cur->p++;
    }
    buf[n] = 0;
    return 0;
}

/* Parses token s as a value of type t into v (host order); -1 when it is not one. */
static int parse_ascii_value(const char *s, ag_scalar_type t, void *v)
{
    char *end;
    errno = 0;
    if (ag_scalar_is_float(t)) {
        double d = strtod(s, &end);
        if (*end || end == s)
            return -1;
        if (t == AG_SCALAR_FLOAT32) {
            float f = (float)d;
            memcpy(v, &f, sizeof f);
        } else {
            memcpy(v, &d, sizeof d);
        }
        return 0;
    }
    long long x = strtoll(s, &end, 10);
    if (*end || end == s || errno)
        return -1;
    switch (t) {
    case AG_SCALAR_INT8: if (x < INT8_MIN || x > INT8_MAX) return -1; *(int8_t *)v = (int8_t)x; break;
    case AG_SCALAR_UINT8: if (x < 0 || x > UINT8_MAX) return -1; *(uint8_t *)v = (uint8_t)x; break;
    case AG_SCALAR_INT16: if (x < INT16_MIN || x > INT16_MAX) return -1; *(int16_t *)v = (int16_t)x; break;
    case AG_SCALAR_UINT16: if (x < 0 || x > UINT16_MAX) return -1; *(uint16_t *)v = (uint16_t)x; break;
    case AG_SCALAR_INT32: if (x < INT32_MIN || x > INT32_MAX) return -1; *(int32_t *)v = (int32_t)x; break;
    case AG_SCALAR_UINT32: if (x < 0 || x > (long long)UINT32_MAX) return -1; *(uint32_t *)v = (uint32_t)x; break;
    default: return -1;
    }
    return 0;
}

/* ---- the reader ------------------------------------------------------------------------ */

typedef struct {
    const uint8_t *data;
    size_t len;
    ply_header h;
    ag_cloud *c;
    ag_error *err;
    /* ag_ply_check_mesh: the vertex count faces' corners index into; 0: corners unchecked */
    int check_corners;
    uint64_t vertices;
} reader;

/* Whether el's list pr holds a face's corners (the names PLY writers use). */
static int is_corner_list(const reader *r, const ply_element *el, const ply_prop *pr)
{
    return r->check_corners && !strcmp(el->name, "face") &&
           (!strcmp(pr->name, "vertex_indices") || !strcmp(pr->name, "vertex_index"));
}

/* A face without corners or with one outside the vertex list: AG_ERR_PARSE naming the face
 * (and the line, for ASCII), as the importer would otherwise abort or read past its arrays on
 * it. (One or two corners make a point or a line, which the importer drops.) */
static ag_status no_corners_problem(reader *r, uint64_t face, size_t line)
{
    if (line)
        return ag_error_set(r->err, AG_ERR_PARSE, (long)line,
                            "line %zu: face %llu has no corners", line,
                            (unsigned long long)face + 1);
    return ag_error_set(r->err, AG_ERR_PARSE, (long)face + 1, "face %llu has no corners",
                        (unsigned long long)face + 1);
}

static ag_status corner_problem(reader *r, uint64_t face, double index, size_t line)
{
    char where[48] = "";
    if (line)
        snprintf(where, sizeof where, "line %zu: ", line);
    return ag_error_set(r->err, AG_ERR_PARSE, line ? (long)line : (long)face + 1,
                        "%sface %llu names vertex %.17g, but the vertices are numbered 0 to "
                        "%llu",
                        where, (unsigned long long)face + 1, index,
                        (unsigned long long)r->vertices - 1);
}

static int corner_ok(const reader *r, double index)
{
    return index >= 0 && index < (double)r->vertices && index == floor(index);
}

/* Decides where each vertex property goes and creates the cloud's properties. */
static ag_status plan_vertex(reader *r, ply_element *v)
{
    static const char *const xyz[3] = {"x", "y", "z"};
    static const char *const nrm[2][3] = {{"nx", "ny", "nz"}, {"normal_x", "normal_y", "normal_z"}};
    int found[3] = {-1, -1, -1};
    int normal_set = -1;
    for (size_t i = 0; i < v->nprops; i++)
        v->props[i].target = TARGET_PROP;
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < v->nprops; i++)
            if (!v->props[i].is_list && !strcmp(v->props[i].name, xyz[a])) {
                found[a] = (int)i;
                v->props[i].target = TARGET_X + a;
            }
    if (found[0] < 0 || found[1] < 0 || found[2] < 0)
        return ag_error_set(r->err, AG_ERR_PARSE, 0,
                            "the vertex element has no %s property",
                            found[0] < 0 ? "x" : found[1] < 0 ? "y" : "z");
    for (int set = 0; set < 2 && normal_set < 0; set++) {
        int idx[3];
        int all = 1;
        for (int a = 0; a < 3; a++) {
            idx[a] = -1;
            for (size_t i = 0; i < v->nprops; i++)
                if (!v->props[i].is_list && !strcmp(v->props[i].name, nrm[set][a]))
                    idx[a] = (int)i;
            all &= idx[a] >= 0;
        }
        if (all) {
            normal_set = set;
            for (int a = 0; a < 3; a++)
                v->props[idx[a]].target = TARGET_NX + a;
        }
    }
    if (normal_set >= 0) {
        ag_status st = ag_cloud_add_normals(r->c, r->err);
        if (st != AG_OK)
            return st;
    }
    for (size_t i = 0; i < v->nprops; i++) {
        ply_prop *pr = &v->props[i];
        if (pr->is_list) {
            pr->target = TARGET_SKIP;
        } else if (pr->target == TARGET_PROP) {
            ag_status st = ag_cloud_add_property(r->c, pr->name, pr->type, &pr->prop, r->err);
            if (st != AG_OK)
                return st;
        }
    }
    return AG_OK;
}

/* Binary rows of element el starting at *pos; stores into the cloud when store_rows. */
static ag_status read_binary(reader *r, ply_element *el, size_t *pos, int store_rows)
{
    int big = r->h.format == FMT_BE;
    size_t remaining = r->len - *pos;
    if (el->count && el->row_bytes && el->count > remaining / el->row_bytes)
        return ag_error_set(r->err, AG_ERR_PARSE, 0,
                            "the header declares %llu %s rows of at least %zu bytes, but only %zu "
                            "bytes of data follow",
                            (unsigned long long)el->count, el->name, el->row_bytes, remaining);
    if (!el->nprops)
        return AG_OK; /* rows of nothing take no bytes, however many the header declares */
    const uint8_t *p = r->data + *pos, *end = r->data + r->len;
    uint8_t value[8];
    for (uint64_t row = 0; row < el->count; row++) {
        if (!el->has_list) {
            if (store_rows)
                for (size_t k = 0; k < el->nprops; k++) {
                    const ply_prop *pr = &el->props[k];
                    ag_bytes_load(value, p + pr->offset, ag_scalar_size(pr->type), big);
                    store(r->c, pr, (size_t)row, value);
                }
            p += el->row_bytes;
            continue;
        }
        for (size_t k = 0; k < el->nprops; k++) {
            const ply_prop *pr = &el->props[k];
            size_t s = ag_scalar_size(pr->is_list ? pr->count_type : pr->type);
            if ((size_t)(end - p) < s)
                return ag_error_set(r->err, AG_ERR_PARSE, 0,
                                    "the data ends inside %s row %llu of %llu", el->name,
                                    (unsigned long long)row + 1, (unsigned long long)el->count);
            ag_bytes_load(value, p, s, big);
            p += s;
            if (!pr->is_list) {
                if (store_rows)
                    store(r->c, pr, (size_t)row, value);
                continue;
            }
            int64_t n = list_count(value, pr->count_type);
            size_t item = ag_scalar_size(pr->type);
            if (n < 0 || (uint64_t)n > (uint64_t)(end - p) / item)
                return ag_error_set(r->err, AG_ERR_PARSE, 0,
                                    "%s row %llu: list '%s' claims %lld items, more than the data "
                                    "holds",
                                    el->name, (unsigned long long)row + 1, pr->name, (long long)n);
            if (is_corner_list(r, el, pr)) {
                if (n == 0)
                    return no_corners_problem(r, row, 0);
                for (int64_t j = 0; j < n; j++) {
                    ag_bytes_load(value, p + (size_t)j * item, item, big);
                    double index = value_to_double(value, pr->type);
                    if (!corner_ok(r, index))
                        return corner_problem(r, row, index, 0);
                }
            }
            p += (size_t)n * item;
        }
    }
    *pos = (size_t)(p - r->data);
    return AG_OK;
}

static ag_status read_ascii(reader *r, ply_element *el, ascii_cursor *cur, int store_rows)
{
    if (!el->nprops)
        return AG_OK; /* rows of nothing, as in read_binary */
    /* every value takes at least one character and one separator */
    size_t remaining = (size_t)(cur->end - cur->p);
    size_t per_row = el->nprops;
    if (el->count && el->count > (remaining / 2 + 1) / per_row)
        return ag_error_set(r->err, AG_ERR_PARSE, 0,
                            "the header declares %llu %s rows, more than the %zu bytes of data can "
                            "hold",
                            (unsigned long long)el->count, el->name, remaining);
    char tok[MAX_TOKEN + 1];
    uint8_t value[8];
    for (uint64_t row = 0; row < el->count; row++) {
        for (size_t k = 0; k < el->nprops; k++) {
            const ply_prop *pr = &el->props[k];
            int t = next_token(cur, tok);
            if (t == -1)
                return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                    "line %zu: the data ends inside %s row %llu of %llu",
                                    cur->line, el->name, (unsigned long long)row + 1,
                                    (unsigned long long)el->count);
            if (t == -2)
                return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                    "line %zu: a value longer than %d characters", cur->line,
                                    MAX_TOKEN);
            if (!pr->is_list) {
                if (parse_ascii_value(tok, pr->type, value))
                    return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                        "line %zu: '%.40s' is not a valid %s for property '%s'",
                                        cur->line, tok, ag_scalar_name(pr->type), pr->name);
                if (pr->target >= TARGET_X && pr->target < TARGET_NX &&
                    !isfinite(value_to_double(value, pr->type)))
                    return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                        "line %zu: point %llu has %s = %s, not a finite number",
                                        cur->line, (unsigned long long)row + 1, pr->name, tok);
                if (store_rows)
                    store(r->c, pr, (size_t)row, value);
                continue;
            }
            uint8_t cnt[8];
            if (parse_ascii_value(tok, pr->count_type, cnt))
                return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                    "line %zu: '%.40s' is not a valid list count for '%s'",
                                    cur->line, tok, pr->name);
            int64_t n = list_count(cnt, pr->count_type);
            if (n < 0 || (uint64_t)n > (uint64_t)(cur->end - cur->p) / 2 + 1)
                return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                    "line %zu: list '%s' claims %lld items, more than the data "
                                    "holds",
                                    cur->line, pr->name, (long long)n);
            int corners = is_corner_list(r, el, pr);
            if (corners && n == 0)
                return no_corners_problem(r, row, cur->line);
            for (int64_t j = 0; j < n; j++) {
                t = next_token(cur, tok);
                if (t)
                    return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                        "line %zu: the data ends inside list '%s'", cur->line,
                                        pr->name);
                if (parse_ascii_value(tok, pr->type, value))
                    return ag_error_set(r->err, AG_ERR_PARSE, (long)cur->line,
                                        "line %zu: '%.40s' is not a valid %s in list '%s'",
                                        cur->line, tok, ag_scalar_name(pr->type), pr->name);
                if (corners && !corner_ok(r, value_to_double(value, pr->type)))
                    return corner_problem(r, row, value_to_double(value, pr->type), cur->line);
            }
        }
    }
    return AG_OK;
}

ag_status ag_ply_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    reader r = {data, len, {0}, NULL, err, 0, 0};
    ag_status st = parse_header(data, len, &r.h, err);
    if (st != AG_OK)
        return st;
    ply_element *vertex = NULL;
    size_t vertex_index = 0;
    for (size_t i = 0; i < r.h.nelements; i++)
        if (!strcmp(r.h.elements[i].name, "vertex")) {
            vertex = &r.h.elements[i];
            vertex_index = i;
            break;
        }
    if (!vertex) {
        header_free(&r.h);
        return ag_error_set(err, AG_ERR_PARSE, 0, "the header declares no vertex element");
    }
    r.c = ag_cloud_create();
    if (!r.c) {
        header_free(&r.h);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    st = plan_vertex(&r, vertex);
    /* the count is checked against the data before the points are allocated */
    size_t pos = r.h.data_start;
    ascii_cursor cur = {data + pos, data + len, r.h.header_lines + 1};
    for (size_t i = 0; st == AG_OK && i <= vertex_index; i++) {
        ply_element *el = &r.h.elements[i];
        int is_vertex = i == vertex_index;
        if (is_vertex) {
            /* size check first (without storing), then allocation, then the real pass */
            size_t remaining = len - (r.h.format == FMT_ASCII ? (size_t)(cur.p - data) : pos);
            size_t min_row = r.h.format == FMT_ASCII ? 2 * (el->nprops ? el->nprops : 1)
                                                     : (el->row_bytes ? el->row_bytes : 1);
            if (el->count > (remaining + 1) / min_row) {
                st = ag_error_set(err, AG_ERR_PARSE, 0,
                                  "the header declares %llu vertices, more than the %zu bytes of "
                                  "data can hold",
                                  (unsigned long long)el->count, remaining);
                break;
            }
            st = ag_cloud_resize(r.c, (size_t)el->count, err);
            if (st != AG_OK)
                break;
        }
        st = r.h.format == FMT_ASCII ? read_ascii(&r, el, &cur, is_vertex)
                                     : read_binary(&r, el, &pos, is_vertex);
    }
    header_free(&r.h);
    if (st == AG_OK)
        st = ag_cloud_check_finite(r.c, err);
    if (st != AG_OK) {
        ag_cloud_free(r.c);
        return st;
    }
    if (r.h.has_offset) {
        memcpy(r.c->offset, r.h.offset, sizeof r.c->offset);
    } else {
        double mn[3], mx[3], origin[3];
        ag_cloud_bounds(r.c, mn, mx);
        ag_cloud_choose_origin(mn, mx, origin);
        ag_cloud_rebase(r.c, origin);
    }
    *out = r.c;
    return AG_OK;
}

ag_status ag_ply_check_mesh(const uint8_t *data, size_t len, ag_error *err)
{
    reader r = {data, len, {0}, NULL, err, 1, 0};
    ag_status st = parse_header(data, len, &r.h, err);
    if (st != AG_OK)
        return st;
    if ((st = check_rows_fit(&r.h, len, err)) != AG_OK) {
        header_free(&r.h);
        return st;
    }
    for (size_t i = 0; i < r.h.nelements; i++)
        if (!strcmp(r.h.elements[i].name, "vertex"))
            r.vertices = r.h.elements[i].count;
    size_t pos = r.h.data_start;
    ascii_cursor cur = {data + pos, data + len, r.h.header_lines + 1};
    for (size_t i = 0; st == AG_OK && i < r.h.nelements; i++)
        st = r.h.format == FMT_ASCII ? read_ascii(&r, &r.h.elements[i], &cur, 0)
                                     : read_binary(&r, &r.h.elements[i], &pos, 0);
    header_free(&r.h);
    return st;
}

/* ---- the writer ------------------------------------------------------------------------ */

static const char *ply_type_name(ag_scalar_type t)
{
    switch (t) {
    case AG_SCALAR_INT8: return "char";
    case AG_SCALAR_UINT8: return "uchar";
    case AG_SCALAR_INT16: return "short";
    case AG_SCALAR_UINT16: return "ushort";
    case AG_SCALAR_INT32: return "int";
    case AG_SCALAR_UINT32: return "uint";
    case AG_SCALAR_FLOAT32: return "float";
    default: return "double"; /* float64, and int64/uint64 which PLY cannot hold */
    }
}

static ag_scalar_type written_type(ag_scalar_type t)
{
    return t == AG_SCALAR_INT64 || t == AG_SCALAR_UINT64 ? AG_SCALAR_FLOAT64 : t;
}

/* Formats one value of a property for ASCII output. */
static int format_value(char *buf, size_t cap, const ag_cloud_property *p, size_t i)
{
    double v = ag_cloud_get(p, i);
    if (p->type == AG_SCALAR_FLOAT32)
        return snprintf(buf, cap, "%.9g", v);
    if (ag_scalar_is_float(written_type(p->type)))
        return snprintf(buf, cap, "%.17g", v);
    return snprintf(buf, cap, "%.0f", v);
}

ag_status ag_ply_write(const ag_cloud *c, const ag_ply_write_options *opt, FILE *f, ag_error *err)
{
    ag_ply_write_options o = opt ? *opt : (ag_ply_write_options){0};
    int has_offset = c->offset[0] != 0 || c->offset[1] != 0 || c->offset[2] != 0;
    int dbl = o.double_xyz;
    const char *fmt = o.encoding == AG_PLY_ASCII    ? "ascii"
                      : o.encoding == AG_PLY_BINARY_BE ? "binary_big_endian"
                                                       : "binary_little_endian";
    fprintf(f, "ply\nformat %s 1.0\ncomment written by archgram\n", fmt);
    if (has_offset && !dbl)
        fprintf(f, "comment offset %.17g %.17g %.17g\n", c->offset[0], c->offset[1],
                c->offset[2]);
    fprintf(f, "element vertex %zu\n", c->n);
    const char *xyz_type = dbl ? "double" : "float";
    fprintf(f, "property %s x\nproperty %s y\nproperty %s z\n", xyz_type, xyz_type, xyz_type);
    if (c->normals)
        fputs("property float nx\nproperty float ny\nproperty float nz\n", f);
    for (size_t p = 0; p < c->nprops; p++)
        fprintf(f, "property %s %s\n", ply_type_name(c->props[p].type), c->props[p].name);
    fputs("end_header\n", f);

    int big = o.encoding == AG_PLY_BINARY_BE;
    double add[3] = {0, 0, 0};
    if (dbl)
        memcpy(add, c->offset, sizeof add);
    if (o.encoding == AG_PLY_ASCII) {
        char buf[64];
        for (size_t i = 0; i < c->n; i++) {
            for (int a = 0; a < 3; a++)
                fprintf(f, a ? " %.*g" : "%.*g", dbl ? 17 : 9, c->xyz[3 * i + a] + add[a]);
            if (c->normals)
                fprintf(f, " %.9g %.9g %.9g", c->normals[3 * i], c->normals[3 * i + 1],
                        c->normals[3 * i + 2]);
            for (size_t p = 0; p < c->nprops; p++) {
                format_value(buf, sizeof buf, &c->props[p], i);
                fputc(' ', f);
                fputs(buf, f);
            }
            fputc('\n', f);
        }
    } else {
        size_t row = 3 * (dbl ? 8 : 4) + (c->normals ? 12 : 0);
        for (size_t p = 0; p < c->nprops; p++)
            row += ag_scalar_size(written_type(c->props[p].type));
        uint8_t *buf = malloc(row);
        if (!buf)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        for (size_t i = 0; i < c->n; i++) {
            uint8_t *q = buf;
            for (int a = 0; a < 3; a++) {
                double v = c->xyz[3 * i + a] + add[a];
                if (dbl) {
                    ag_bytes_store(q, &v, 8, big);
                    q += 8;
                } else {
                    float fv = (float)v;
                    ag_bytes_store(q, &fv, 4, big);
                    q += 4;
                }
            }
            if (c->normals)
                for (int a = 0; a < 3; a++) {
                    ag_bytes_store(q, &c->normals[3 * i + a], 4, big);
                    q += 4;
                }
            for (size_t p = 0; p < c->nprops; p++) {
                const ag_cloud_property *pr = &c->props[p];
                size_t s = ag_scalar_size(pr->type);
                if (written_type(pr->type) != pr->type) {
                    double v = ag_cloud_get(pr, i);
                    ag_bytes_store(q, &v, 8, big);
                    q += 8;
                } else {
                    ag_bytes_store(q, (const char *)pr->values + i * s, s, big);
                    q += s;
                }
            }
            if (fwrite(buf, 1, row, f) != row)
                break;
        }
        free(buf);
    }
    if (ferror(f))
        return ag_error_set(err, AG_ERR_IO, 0, "write error: %s", strerror(errno));
    return AG_OK;
}

ag_status ag_ply_write_file(const ag_cloud *c, const ag_ply_write_options *opt, const char *path,
                            ag_error *err)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
    ag_status st = ag_ply_write(c, opt, f, err);
    if (fclose(f) != 0 && st == AG_OK)
        st = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(errno));
    if (st != AG_OK)
        remove(path);
    return st;
}
