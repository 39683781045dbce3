#include "jsondoc.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <yajl/yajl_parse.h>

#include "../core/base/array.h"

typedef struct {
    uint8_t type, is_int;
    uint32_t key;   /* offset of the member's key in text, or NONE */
    uint32_t first; /* first child */
    uint32_t next;  /* next sibling */
    uint32_t count;
    union {
        double num;   /* a number (is_int: ival) */
        int64_t ival; /* a number written as an integer */
        uint32_t str; /* a string's offset in text */
        uint32_t last; /* a container's last child, while it is open */
    } u;
} node;

struct ag_jsondoc {
    node *nodes;
    size_t n, cap;
    char *text;
    size_t ntext, cap_text;
    uint32_t *stack; /* open containers */
    size_t depth, cap_stack;
    uint32_t pending_key;
    uint32_t root;
    int nomem;
};

#define NONE AG_JSONDOC_NONE

static uint32_t add_text(ag_jsondoc *d, const unsigned char *s, size_t len)
{
    if (d->ntext + len + 1 > UINT32_MAX ||
        AG_ARRAY_RESERVE(d->text, d->cap_text, d->ntext + len + 1) != AG_OK) {
        d->nomem = 1;
        return NONE;
    }
    uint32_t at = (uint32_t)d->ntext;
    memcpy(d->text + at, s, len);
    d->text[at + len] = '\0';
    d->ntext += len + 1;
    return at;
}

/* A new node as the next child of the open container (or the root). */
static node *add_node(ag_jsondoc *d, ag_json_type type)
{
    if (d->n >= UINT32_MAX - 1 || AG_ARRAY_RESERVE(d->nodes, d->cap, d->n + 1) != AG_OK) {
        d->nomem = 1;
        return NULL;
    }
    uint32_t id = (uint32_t)d->n++;
    node *x = &d->nodes[id];
    memset(x, 0, sizeof *x);
    x->type = (uint8_t)type;
    x->key = NONE;
    x->first = x->next = NONE;
    x->u.last = NONE;
    if (d->depth) {
        node *p = &d->nodes[d->stack[d->depth - 1]];
        if (p->type == AG_JSON_OBJECT) {
            x->key = d->pending_key;
            d->pending_key = NONE;
        }
        if (p->u.last == NONE)
            p->first = id;
        else
            d->nodes[p->u.last].next = id;
        p->u.last = id;
        p->count++;
    } else if (d->root == NONE) {
        d->root = id;
    }
    return x;
}

static int push(ag_jsondoc *d, ag_json_type type)
{
    node *x = add_node(d, type);
    if (!x || AG_ARRAY_RESERVE(d->stack, d->cap_stack, d->depth + 1) != AG_OK) {
        d->nomem = 1;
        return 0;
    }
    d->stack[d->depth++] = (uint32_t)(x - d->nodes);
    return 1;
}

static int on_null(void *ctx)
{
    return add_node(ctx, AG_JSON_NULL) != NULL;
}

static int on_bool(void *ctx, int b)
{
    return add_node(ctx, b ? AG_JSON_TRUE : AG_JSON_FALSE) != NULL;
}

static int on_number(void *ctx, const char *s, size_t len)
{
    char buf[64];
    char *tmp = len < sizeof buf ? buf : malloc(len + 1);
    if (!tmp) {
        ((ag_jsondoc *)ctx)->nomem = 1;
        return 0;
    }
    memcpy(tmp, s, len);
    tmp[len] = '\0';
    node *x = add_node(ctx, AG_JSON_NUMBER);
    if (x) {
        x->u.num = strtod(tmp, NULL);
        if (!memchr(s, '.', len) && !memchr(s, 'e', len) && !memchr(s, 'E', len)) {
            errno = 0;
            long long v = strtoll(tmp, NULL, 10);
            if (errno == 0) {
                x->is_int = 1;
                x->u.ival = v;
            }
        }
    }
    if (tmp != buf)
        free(tmp);
    return x != NULL;
}

static int on_string(void *ctx, const unsigned char *s, size_t len)
{
    ag_jsondoc *d = ctx;
    uint32_t at = add_text(d, s, len);
    node *x = at == NONE ? NULL : add_node(d, AG_JSON_STRING);
    if (x)
        x->u.str = at;
    return x != NULL;
}

static int on_start_map(void *ctx)
{
    return push(ctx, AG_JSON_OBJECT);
}

static int on_key(void *ctx, const unsigned char *s, size_t len)
{
    ag_jsondoc *d = ctx;
    d->pending_key = add_text(d, s, len);
    return d->pending_key != NONE;
}

static int on_end(void *ctx)
{
    ag_jsondoc *d = ctx;
    d->nodes[d->stack[--d->depth]].u.last = 0; /* closed: the union holds nothing */
    return 1;
}

static int on_start_array(void *ctx)
{
    return push(ctx, AG_JSON_ARRAY);
}

static const yajl_callbacks callbacks = {
    .yajl_null = on_null,
    .yajl_boolean = on_bool,
    .yajl_number = on_number,
    .yajl_string = on_string,
    .yajl_start_map = on_start_map,
    .yajl_map_key = on_key,
    .yajl_end_map = on_end,
    .yajl_start_array = on_start_array,
    .yajl_end_array = on_end,
};

void ag_jsondoc_free(ag_jsondoc *d)
{
    if (!d)
        return;
    free(d->nodes);
    free(d->text);
    free(d->stack);
    free(d);
}

ag_status ag_jsondoc_parse(const char *data, size_t len, ag_jsondoc **out, ag_error *err)
{
    *out = NULL;
    ag_jsondoc *d = calloc(1, sizeof *d);
    if (!d)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    d->root = d->pending_key = NONE;
    /* about one node per 12 bytes of coordinates */
    if (AG_ARRAY_RESERVE(d->nodes, d->cap, len / 12 + 16) != AG_OK) {
        ag_jsondoc_free(d);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    yajl_handle h = yajl_alloc(&callbacks, NULL, d);
    if (!h) {
        ag_jsondoc_free(d);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    yajl_status ys = yajl_parse(h, (const unsigned char *)data, len);
    if (ys == yajl_status_ok)
        ys = yajl_complete_parse(h);
    ag_status st = AG_OK;
    if (d->nomem) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    } else if (ys != yajl_status_ok || d->root == NONE) {
        size_t at = yajl_get_bytes_consumed(h);
        if (at > len)
            at = len;
        long line = 1, col = 1;
        for (size_t i = 0; i < at; i++) {
            if (data[i] == '\n') {
                line++;
                col = 1;
            } else {
                col++;
            }
        }
        unsigned char *msg = yajl_get_error(h, 0, (const unsigned char *)data, len);
        const char *m = msg ? (const char *)msg : "not JSON";
        /* yajl's message reads "parse error: ...": keep what follows */
        const char *colon = strstr(m, ": ");
        st = ag_error_set(err, AG_ERR_PARSE, line, "%s (line %ld, column %ld)",
                          colon ? colon + 2 : m, line, col);
        if (msg)
            yajl_free_error(h, msg);
        /* trailing newlines in yajl's text */
        if (err) {
            size_t n = strlen(err->text);
            while (n && (err->text[n - 1] == '\n' || err->text[n - 1] == ' '))
                err->text[--n] = '\0';
        }
    }
    yajl_free(h);
    if (st != AG_OK) {
        ag_jsondoc_free(d);
        return st;
    }
    *out = d;
    return AG_OK;
}

uint32_t ag_jsondoc_root(const ag_jsondoc *d)
{
    return d->root;
}

ag_json_type ag_jsondoc_type(const ag_jsondoc *d, uint32_t n)
{
    return n == NONE ? AG_JSON_NULL : (ag_json_type)d->nodes[n].type;
}

uint32_t ag_jsondoc_first(const ag_jsondoc *d, uint32_t n)
{
    return n == NONE ? NONE : d->nodes[n].first;
}

uint32_t ag_jsondoc_next(const ag_jsondoc *d, uint32_t n)
{
    return n == NONE ? NONE : d->nodes[n].next;
}

size_t ag_jsondoc_size(const ag_jsondoc *d, uint32_t n)
{
    if (n == NONE || (d->nodes[n].type != AG_JSON_ARRAY && d->nodes[n].type != AG_JSON_OBJECT))
        return 0;
    return d->nodes[n].count;
}

uint32_t ag_jsondoc_get(const ag_jsondoc *d, uint32_t obj, const char *key)
{
    if (obj == NONE || d->nodes[obj].type != AG_JSON_OBJECT)
        return NONE;
    for (uint32_t c = d->nodes[obj].first; c != NONE; c = d->nodes[c].next)
        if (d->nodes[c].key != NONE && strcmp(d->text + d->nodes[c].key, key) == 0)
            return c;
    return NONE;
}

uint32_t ag_jsondoc_at(const ag_jsondoc *d, uint32_t arr, size_t i)
{
    if (arr == NONE || d->nodes[arr].type != AG_JSON_ARRAY)
        return NONE;
    uint32_t c = d->nodes[arr].first;
    while (c != NONE && i--)
        c = d->nodes[c].next;
    return c;
}

double ag_jsondoc_number(const ag_jsondoc *d, uint32_t n)
{
    if (n == NONE || d->nodes[n].type != AG_JSON_NUMBER)
        return 0;
    return d->nodes[n].is_int ? (double)d->nodes[n].u.ival : d->nodes[n].u.num;
}

const char *ag_jsondoc_string(const ag_jsondoc *d, uint32_t n)
{
    return n != NONE && d->nodes[n].type == AG_JSON_STRING ? d->text + d->nodes[n].u.str : NULL;
}

int ag_jsondoc_integer(const ag_jsondoc *d, uint32_t n, int64_t *value)
{
    if (n == NONE || d->nodes[n].type != AG_JSON_NUMBER || !d->nodes[n].is_int)
        return 0;
    *value = d->nodes[n].u.ival;
    return 1;
}
