#include "model_kept.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <sodium.h>

#include "../core/base/array.h"
#include "../core/edit/rebuild.h"
#include "model_tree.h"

#define KEPT_FORMAT 4
#define KEPT_FORMAT_FULL_DEAD 3 /* dead nodes written whole; still read */
/* the most node ids a format 4 member may name (runs of dead nodes cost no data per id) */
#define KEPT_MAX_NODES ((size_t)1 << 24)
#define NODE_INTS 13
#define NODE_BYTES (4 * NODE_INTS + 8 * 9)
#define PATTERN_BYTES (4 * 7 + 8 * 12)
#define RULE_BYTES 8
#define COMPONENT_BYTES (4 * 5 + 8)
#define VARIANT_BYTES (4 + 8)

/* ---- writing ----------------------------------------------------------------------------- */

/* The kept data: little-endian int32 and IEEE doubles, packed, then base64 (libsodium). */
typedef struct {
    uint8_t *p;
    size_t n, cap;
    int fail;
} packer;

static void put_bytes(packer *k, const void *v, size_t n)
{
    if (k->fail || (k->n + n > k->cap &&
                    (k->fail = AG_ARRAY_RESERVE_MORE(k->p, k->cap, k->n, n) != AG_OK)))
        return;
    memcpy(k->p + k->n, v, n);
    k->n += n;
}

static void put_u32(packer *k, uint32_t v)
{
    uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    put_bytes(k, b, 4);
}

static void put_i32(packer *k, int32_t v)
{
    put_u32(k, (uint32_t)v);
}

static void put_f64(packer *k, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put_u32(k, (uint32_t)u);
    put_u32(k, (uint32_t)(u >> 32));
}

/* Standard base64 with padding, as sodium_bin2base64's VARIANT_ORIGINAL writes it (and
 * sodium_base642bin reads it back, as base64_decode does). Written here because libsodium's encoder is constant-time,
 * made for secrets, and takes a quarter of an edit's tree writing on a large building; the
 * libraries that have a plain one are not this layer's. out holds 4 * ceil(n / 3) + 1. */
static void base64_encode(char *out, const uint8_t *in, size_t n)
{
    static const char digit[64] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t i = 0;
    for (; i + 3 <= n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (uint32_t)in[i + 1] << 8 | in[i + 2];
        *out++ = digit[v >> 18];
        *out++ = digit[(v >> 12) & 63];
        *out++ = digit[(v >> 6) & 63];
        *out++ = digit[v & 63];
    }
    if (i < n) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0);
        *out++ = digit[v >> 18];
        *out++ = digit[(v >> 12) & 63];
        *out++ = i + 1 < n ? digit[(v >> 6) & 63] : '=';
        *out++ = '=';
    }
    *out = '\0';
}

/* The inverse of base64_encode, as strict as sodium_base642bin with VARIANT_ORIGINAL (every
 * character of the alphabet, the length a multiple of four, padding only at the end) and
 * written here for the encoder's reason: the constant-time decoder took an eighth of a large
 * model's reload. out holds 3 * (n / 4) bytes; 0 with *len set, or -1 for a bad text. */
static int base64_decode(uint8_t *out, const char *in, size_t n, size_t *len)
{
    static int8_t value[256];
    static int ready;
    if (!ready) { /* the table is the same for every caller: a race writes the same bytes */
        memset(value, -1, sizeof value);
        const char *digit = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        for (int i = 0; i < 64; i++)
            value[(uint8_t)digit[i]] = (int8_t)i;
        ready = 1;
    }
    if (n % 4)
        return -1;
    size_t pad = n && in[n - 1] == '=' ? (n > 1 && in[n - 2] == '=' ? 2 : 1) : 0;
    size_t o = 0;
    for (size_t i = 0; i < n; i += 4) {
        int last = i + 4 == n;
        int8_t a = value[(uint8_t)in[i]], b = value[(uint8_t)in[i + 1]];
        int8_t c = last && pad == 2 ? 0 : value[(uint8_t)in[i + 2]];
        int8_t d = last && pad ? 0 : value[(uint8_t)in[i + 3]];
        if ((a | b | c | d) < 0)
            return -1;
        uint32_t v = (uint32_t)a << 18 | (uint32_t)b << 12 | (uint32_t)c << 6 | (uint32_t)d;
        out[o++] = (uint8_t)(v >> 16);
        if (!last || pad < 2)
            out[o++] = (uint8_t)(v >> 8);
        if (!last || !pad)
            out[o++] = (uint8_t)v;
    }
    *len = o;
    return 0;
}

static char *kept_text(const ag_edit_model *em)
{
    const ag_splittree *t = em->proc->tree;
    const ag_labels *L = em->proc->labels;
    packer k = {0};
    /* all of it at once: grown piece by piece, a large tree's data is copied many times */
    size_t total = t->nnodes * NODE_BYTES + t->npatterns * PATTERN_BYTES +
                   t->nrules * RULE_BYTES + L->ncomponents * COMPONENT_BYTES +
                   L->nvariants * VARIANT_BYTES;
    k.fail = AG_ARRAY_RESERVE_MORE(k.p, k.cap, k.n, total ? total : 1) != AG_OK;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_DEAD) {
            /* a dead node only holds its id: a run of them is its kind and its length */
            size_t run = 1;
            while (n + run < t->nnodes && t->nodes[n + run].kind == AG_NODE_DEAD)
                run++;
            put_i32(&k, AG_NODE_DEAD);
            put_u32(&k, (uint32_t)run);
            n += run - 1;
            continue;
        }
        const int32_t ints[NODE_INTS] = {x->kind,      x->parent,    x->first_child, x->last_child,
                                         x->next_sibling, x->component, x->label,    x->variant,
                                         x->rot,       x->octant,    x->rule_rot,    x->rule,
                                         /* only a pattern node's names a pattern (dead
                                          * ones may keep an index of a dropped one) */
                                         x->kind == AG_NODE_PATTERN ? x->pattern : -1};
        for (int q = 0; q < NODE_INTS; q++)
            put_i32(&k, ints[q]);
        for (int a = 0; a < 3; a++)
            put_f64(&k, x->box.min[a]);
        for (int a = 0; a < 3; a++)
            put_f64(&k, x->box.max[a]);
        for (int a = 0; a < 3; a++)
            put_f64(&k, x->pivot[a]);
    }
    for (size_t i = 0; i < t->npatterns; i++) {
        const ag_pattern *p = &t->patterns[i];
        put_i32(&k, p->rule);
        put_i32(&k, p->rot);
        put_i32(&k, p->nvec);
        for (int a = 0; a < 3; a++)
            put_u32(&k, p->counts[a]);
        for (int a = 0; a < 3; a++)
            put_f64(&k, p->step[a]);
        for (int v = 0; v < 3; v++)
            for (int a = 0; a < 3; a++)
                put_f64(&k, p->vec[v][a]);
        put_i32(&k, p->node);
    }
    for (size_t r = 0; r < t->nrules; r++) {
        put_u32(&k, t->rule_count[r]);
        put_i32(&k, t->rule_rep[r]);
    }
    for (size_t c = 0; c < L->ncomponents; c++) {
        put_i32(&k, L->label[c]);
        put_i32(&k, L->variant[c]);
        put_i32(&k, L->rot[c]);
        put_i32(&k, L->vrot[c]);
        put_i32(&k, L->mirror ? L->mirror[c] : 0);
        put_f64(&k, L->turn ? L->turn[c] : L->rot[c] * 1.5707963267948966);
    }
    for (size_t v = 0; v < L->nvariants; v++) {
        put_i32(&k, L->variant_label[v]);
        put_f64(&k, L->variant_deviation ? L->variant_deviation[v] : 0);
    }
    /* printed directly: jansson would copy and scan the data string character by character */
    char *out = NULL;
    if (!k.fail) {
        size_t blen = sodium_base64_ENCODED_LEN(k.n, sodium_base64_VARIANT_ORIGINAL);
        char head[640];
        int hn = snprintf(head, sizeof head,
                          "{\"format\":%d,\"tol\":%.17g,\"eps\":%.17g,\"ncomponents\":%zu,"
                          "\"nnodes\":%zu,\"npatterns\":%zu,\"nrules\":%zu,\"nlabels\":%zu,"
                          "\"nvariants\":%zu,\"diagonal\":%.17g,\"label_tol\":%.17g,"
                          "\"exact\":%.17g,\"share\":%.17g,\"exact_copies\":%d,\"data\":\"",
                          KEPT_FORMAT, t->tol, t->eps, L->ncomponents, t->nnodes, t->npatterns,
                          t->nrules, L->nlabels, L->nvariants, L->diagonal, L->tol, L->exact,
                          L->share, L->exact_copies ? 1 : 0);
        if (hn > 0 && (size_t)hn < sizeof head && (out = malloc((size_t)hn + blen + 4))) {
            memcpy(out, head, (size_t)hn);
            base64_encode(out + hn, k.p ? k.p : (const uint8_t *)"", k.n);
            strcat(out + hn, "\"}");
        }
    }
    free(k.p);
    return out;
}

char *ag_model_kept_join(const char *served, const ag_edit_model *em)
{
    char *kept = served ? kept_text(em) : NULL;
    char *out = NULL;
    size_t n = served ? strlen(served) : 0;
    if (kept && n >= 2 && served[n - 1] == '}') {
        size_t kn = strlen(kept);
        if ((out = malloc(n + kn + 16))) {
            memcpy(out, served, n - 1);
            size_t at = n - 1;
            int empty = served[0] == '{' && at == 1; /* "{}": the kept member alone */
            memcpy(out + at, ",\"kept\":" + empty, 8 - (size_t)empty);
            at += 8 - (size_t)empty;
            memcpy(out + at, kept, kn);
            at += kn;
            out[at++] = '}';
            out[at] = '\0';
        }
    }
    free(kept);
    return out;
}

char *ag_model_kept_tree_text(const ag_edit_model *em)
{
    /* the served part keeps its own (shorter) printing; the kept member is exact */
    char *served = ag_model_tree_served_text(em);
    char *out = ag_model_kept_join(served, em);
    free(served);
    return out;
}

char *ag_model_kept_bare_text(const ag_edit_model *em)
{
    return ag_model_kept_join("{}", em);
}

#define BARE_START "{\"kept\":{\"format\":"

int ag_model_kept_serves(const char *tree_text)
{
    while (*tree_text == ' ')
        tree_text++;
    return strncmp(tree_text, BARE_START, strlen(BARE_START)) != 0;
}

#define KEPT_MEMBER ",\"kept\":{\"format\":"

char *ag_model_kept_served_text(const char *tree_text)
{
    /* the kept member is written last and holds only numbers: its start is the last match */
    size_t n = strlen(tree_text);
    const char *at = NULL;
    for (const char *p = strstr(tree_text, KEPT_MEMBER); p; p = strstr(p + 1, KEPT_MEMBER))
        at = p;
    size_t keep = at && n && tree_text[n - 1] == '}' ? (size_t)(at - tree_text) : n;
    char *out = malloc(keep + 2);
    if (!out)
        return NULL;
    memcpy(out, tree_text, keep);
    if (keep < n)
        out[keep++] = '}';
    out[keep] = '\0';
    return out;
}

/* ---- reading ----------------------------------------------------------------------------- */

typedef struct {
    ag_error *err;
    ag_status st;
    const uint8_t *p; /* the decoded data */
    size_t n, at;
} reader;

static int bad(reader *R, const char *what)
{
    if (!R->st)
        R->st = ag_error_set(R->err, AG_ERR_PARSE, 0, "the kept model: %s", what);
    return 0;
}

static uint32_t get_u32(reader *R)
{
    const uint8_t *b = R->p + R->at;
    R->at += 4;
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static int32_t get_i32(reader *R)
{
    return (int32_t)get_u32(R);
}

static double get_f64(reader *R)
{
    uint64_t lo = get_u32(R), hi = get_u32(R);
    uint64_t u = lo | hi << 32;
    double v;
    memcpy(&v, &u, 8);
    return v;
}

/* An int32 in [lo, hi]. */
static int in_range(reader *R, int32_t v, int64_t lo, int64_t hi, const char *what)
{
    return v >= lo && v <= hi ? 1 : bad(R, what);
}

static int finite3(reader *R, const double *v, const char *what)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(v[a]))
            return bad(R, what);
    return 1;
}

/* A dead node as it is read: its id and nothing else (no links, classes or box). */
static void dead_node(ag_tnode *x)
{
    memset(x, 0, sizeof *x);
    x->kind = AG_NODE_DEAD;
    x->parent = x->first_child = x->last_child = x->next_sibling = -1;
    x->component = x->label = x->variant = x->rule = x->pattern = -1;
}

static int read_node(reader *R, const ag_splittree *t, size_t nlabels, size_t nvariants,
                     ag_tnode *x)
{
    int64_t n = (int64_t)t->nnodes;
    const int64_t lo[NODE_INTS] = {AG_NODE_ROOT, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, -1, -1};
    const int64_t hi[NODE_INTS] = {AG_NODE_DEAD,          n - 1, n - 1, n - 1, n - 1,
                                   (int64_t)t->ncomponents - 1, (int64_t)nlabels - 1,
                                   (int64_t)nvariants - 1, 3,     8,     3,
                                   (int64_t)t->nrules - 1,      (int64_t)t->npatterns - 1};
    static const char *const field[NODE_INTS] = {
        "kind", "parent", "first child", "last child", "next sibling", "component", "label",
        "variant", "rot", "octant", "rule rot", "rule", "pattern"};
    int32_t v[NODE_INTS];
    for (int k = 0; k < NODE_INTS; k++)
        if ((v[k] = get_i32(R)) < lo[k] || v[k] > hi[k]) {
            if (!R->st)
                R->st = ag_error_set(R->err, AG_ERR_PARSE, 0,
                                     "the kept model: a node's %s (%d) is out of range",
                                     field[k], (int)v[k]);
            return 0;
        }
    memset(x, 0, sizeof *x);
    x->kind = (uint8_t)v[0];
    x->parent = v[1];
    x->first_child = v[2];
    x->last_child = v[3];
    x->next_sibling = v[4];
    x->component = v[5];
    x->label = v[6];
    x->variant = v[7];
    x->rot = (uint8_t)v[8];
    x->octant = (uint8_t)v[9];
    x->rule_rot = (uint8_t)v[10];
    x->rule = v[11];
    x->pattern = v[12];
    for (int a = 0; a < 3; a++)
        x->box.min[a] = get_f64(R);
    for (int a = 0; a < 3; a++)
        x->box.max[a] = get_f64(R);
    for (int a = 0; a < 3; a++)
        x->pivot[a] = get_f64(R);
    if (!finite3(R, x->box.min, "a node's box") || !finite3(R, x->box.max, "a node's box") ||
        !finite3(R, x->pivot, "a node's pivot"))
        return 0;
    for (int a = 0; a < 3; a++)
        if (x->box.max[a] < x->box.min[a])
            return bad(R, "a node's box is inverted");
    if (x->kind == AG_NODE_DEAD) /* format 3 wrote a dead node whole: it keeps only its id */
        dead_node(x);
    return 1;
}

/* The nodes of format 4: a live node's record as format 3's, a run of dead ones their kind
 * and count. The records are not of one length, so each is checked against the data left
 * (rest: the bytes the sections after the nodes take). */
static int read_nodes_compact(reader *R, ag_splittree *t, size_t nlabels, size_t nvariants,
                              size_t rest)
{
    size_t n = 0;
    while (n < t->nnodes) {
        if (R->n - R->at < rest + 8)
            return bad(R, "the data ends inside the nodes");
        size_t at = R->at;
        if (get_i32(R) == AG_NODE_DEAD) {
            uint32_t run = get_u32(R);
            if (!run || run > t->nnodes - n)
                return bad(R, "a run of dead nodes is empty or passes the last node");
            for (uint32_t i = 0; i < run; i++)
                dead_node(&t->nodes[n++]);
            continue;
        }
        R->at = at;
        if (R->n - R->at < rest + NODE_BYTES)
            return bad(R, "the data ends inside the nodes");
        if (!read_node(R, t, nlabels, nvariants, &t->nodes[n++]))
            return 0;
    }
    if (R->n - R->at != rest)
        return bad(R, "the data's length does not match its counts");
    return 1;
}

static int read_pattern(reader *R, const ag_splittree *t, ag_pattern *p)
{
    memset(p, 0, sizeof *p);
    int32_t rule = get_i32(R), rot = get_i32(R), nvec = get_i32(R);
    if (!in_range(R, rule, -1, (int64_t)t->nrules - 1, "a pattern's rule") ||
        !in_range(R, rot, 0, 3, "a pattern's turn") ||
        !in_range(R, nvec, 0, 3, "a pattern's lattice"))
        return 0;
    p->rule = rule;
    p->rot = (uint8_t)rot;
    p->nvec = (uint8_t)nvec;
    for (int a = 0; a < 3; a++)
        p->counts[a] = get_u32(R);
    for (int a = 0; a < 3; a++)
        p->step[a] = get_f64(R);
    for (int v = 0; v < 3; v++)
        for (int a = 0; a < 3; a++)
            p->vec[v][a] = get_f64(R);
    if (!finite3(R, p->step, "a pattern's step") || !finite3(R, p->vec[0], "a pattern's vectors") ||
        !finite3(R, p->vec[1], "a pattern's vectors") ||
        !finite3(R, p->vec[2], "a pattern's vectors"))
        return 0;
    int32_t node = get_i32(R); /* -1: a pattern dissolved */
    if (!in_range(R, node, -1, (int64_t)t->nnodes - 1, "a pattern's node"))
        return 0;
    p->node = node;
    return 1;
}

static int check_links(reader *R, const ag_splittree *t)
{
    if (!t->nnodes || t->nodes[0].kind != AG_NODE_ROOT || t->nodes[0].parent != -1)
        return bad(R, "node 0 is not the root");
    uint8_t *seen = calloc(t->nnodes, 1), *named = calloc(t->ncomponents + 1, 1);
    int32_t *stack = malloc(t->nnodes * sizeof *stack);
    if (!seen || !named || !stack) {
        free(seen);
        free(named);
        free(stack);
        if (!R->st)
            R->st = ag_error_set(R->err, AG_ERR_NOMEM, 0, "out of memory");
        return 0;
    }
    int ok = 1;
    size_t top = 0;
    stack[top++] = 0;
    seen[0] = 1;
    while (top && ok) {
        int32_t p = stack[--top];
        int32_t last = -1;
        for (int32_t c = t->nodes[p].first_child; c >= 0 && ok; c = t->nodes[c].next_sibling) {
            if (seen[c] || t->nodes[c].parent != p || t->nodes[c].kind == AG_NODE_ROOT ||
                t->nodes[c].kind == AG_NODE_DEAD)
                ok = bad(R, "the nodes' links do not make a tree");
            else {
                seen[c] = 1;
                stack[top++] = c;
                last = c;
            }
        }
        if (ok && last != t->nodes[p].last_child)
            ok = bad(R, "a node's last child is not the end of its list");
    }
    for (size_t n = 0; ok && n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (!seen[n] && x->kind != AG_NODE_DEAD) /* dead nodes keep their old links */
            ok = bad(R, "a node outside the tree is not dead");
        else if (x->kind == AG_NODE_COMPONENT && x->component >= 0 && named[x->component]++)
            ok = bad(R, "two nodes hold one component");
        else if (x->kind == AG_NODE_PATTERN &&
                 (x->pattern < 0 || t->patterns[x->pattern].node != (int32_t)n))
            ok = bad(R, "a pattern node and its pattern disagree");
    }
    free(seen);
    free(named);
    free(stack);
    return ok;
}


/* A count of the kept member, at most `most`. */
static int get_count(reader *R, const json_t *k, const char *key, size_t most, size_t *out)
{
    const json_t *v = json_object_get(k, key);
    if (!json_is_integer(v) || json_integer_value(v) < 0 ||
        (uint64_t)json_integer_value(v) > most)
        return bad(R, key);
    *out = (size_t)json_integer_value(v);
    return 1;
}

static int get_real(reader *R, const json_t *k, const char *key, double *out)
{
    const json_t *v = json_object_get(k, key);
    if (!json_is_number(v) || !isfinite(json_number_value(v)))
        return bad(R, key);
    *out = json_number_value(v);
    return 1;
}

/* What a kept member holds: the split tree and the classes labeling gave the components. */
typedef struct {
    ag_splittree *t;
    ag_rebuild_classes classes;
} kept_parts;

static void kept_parts_free(kept_parts *kp)
{
    ag_splittree_free(kp->t);
    free((void *)kp->classes.label);
    free((void *)kp->classes.variant);
    free((void *)kp->classes.rot);
    free((void *)kp->classes.vrot);
    free((void *)kp->classes.variant_label);
    free((void *)kp->classes.mirror);
    free((void *)kp->classes.turn);
    free((void *)kp->classes.variant_deviation);
    memset(kp, 0, sizeof *kp);
}

/* The kept member of tree_text read and checked; ncomponents, when not SIZE_MAX, is the
 * number of components of the mesh it must fit. */
static ag_status read_kept(const char *tree_text, size_t ncomponents, kept_parts *out,
                           ag_error *err)
{
    memset(out, 0, sizeof *out);
    json_error_t je;
    json_t *doc = json_loads(tree_text, 0, &je);
    if (!doc)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the stored tree is not JSON: %s", je.text);
    const json_t *k = json_object_get(doc, "kept");
    if (!json_is_object(k)) {
        json_decref(doc);
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "the stored tree keeps no model");
    }
    reader R = {.err = err};
    ag_rebuild_classes classes = {0};
    int32_t *label = NULL, *variant = NULL, *vlabel = NULL;
    uint8_t *rot = NULL, *vrot = NULL, *data = NULL;
    ag_splittree *t = NULL;
    size_t format = 0, ncomp = 0, nnodes = 0, npat = 0, nrules = 0, nl = 0, nv = 0;
    size_t exact_copies = 0;
    uint8_t *mirror = NULL;
    double *turn = NULL, *deviation = NULL;
    double tol = 0, eps = 0;
    const json_t *d = json_object_get(k, "data");
    const char *b64 = json_string_value(d);
    size_t blen = b64 ? strlen(b64) : 0;
    /* every count is bounded by the data's length, so nothing larger than it is allocated */
    int ok = get_count(&R, k, "format", KEPT_FORMAT, &format) &&
             (format == KEPT_FORMAT || format == KEPT_FORMAT_FULL_DEAD ||
              bad(&R, "an unknown format")) &&
             (b64 || bad(&R, "no data")) && get_count(&R, k, "ncomponents", blen, &ncomp) &&
             /* runs of dead nodes take a few bytes for many ids: a cap instead of the length */
             get_count(&R, k, "nnodes", format == KEPT_FORMAT ? KEPT_MAX_NODES : blen, &nnodes) &&
             get_count(&R, k, "npatterns", blen, &npat) &&
             get_count(&R, k, "nrules", blen, &nrules) && get_count(&R, k, "nlabels", INT32_MAX, &nl) &&
             get_count(&R, k, "nvariants", blen, &nv) && get_real(&R, k, "tol", &tol) &&
             get_real(&R, k, "eps", &eps) && get_real(&R, k, "diagonal", &classes.diagonal) &&
             get_real(&R, k, "label_tol", &classes.tol) && get_real(&R, k, "exact", &classes.exact) &&
             get_real(&R, k, "share", &classes.share) &&
             get_count(&R, k, "exact_copies", 1, &exact_copies);
    if (ok && ncomponents != SIZE_MAX && ncomp != ncomponents)
        ok = bad(&R, "it names another number of components than the mesh has");
    if (ok && !(data = malloc(blen + 1)))
        R.st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory"), ok = 0;
    size_t dlen = 0;
    if (ok && base64_decode(data, b64, blen, &dlen))
        ok = bad(&R, "the data is not base64");
    size_t rest = npat * PATTERN_BYTES + nrules * RULE_BYTES + ncomp * COMPONENT_BYTES +
                  nv * VARIANT_BYTES; /* after the nodes */
    if (ok && (format == KEPT_FORMAT ? dlen < rest : dlen != nnodes * NODE_BYTES + rest))
        ok = bad(&R, "the data's length does not match its counts");
    if (ok && !nnodes)
        ok = bad(&R, "no nodes");
    R.p = data;
    R.n = dlen;
    if (ok) {
        t = calloc(1, sizeof *t);
        label = malloc((ncomp + 1) * sizeof *label);
        variant = malloc((ncomp + 1) * sizeof *variant);
        rot = malloc(ncomp + 1);
        vrot = malloc(ncomp + 1);
        vlabel = malloc((nv + 1) * sizeof *vlabel);
        mirror = malloc(ncomp + 1);
        turn = malloc((ncomp + 1) * sizeof *turn);
        deviation = malloc((nv + 1) * sizeof *deviation);
        if (t) {
            t->nnodes = t->cap = nnodes;
            t->npatterns = t->cap_patterns = npat;
            t->nrules = nrules;
            t->ncomponents = ncomp;
            t->tol = tol;
            t->eps = eps;
            t->nodes = malloc((nnodes + 1) * sizeof *t->nodes);
            t->patterns = malloc((npat + 1) * sizeof *t->patterns);
            t->rule_count = malloc((nrules + 1) * sizeof *t->rule_count);
            t->rule_rep = malloc((nrules + 1) * sizeof *t->rule_rep);
        }
        if (!t || !label || !variant || !rot || !vrot || !vlabel || !mirror || !turn ||
            !deviation || !t->nodes || !t->patterns ||
            !t->rule_count || !t->rule_rep)
            R.st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory"), ok = 0;
    }
    if (ok && format == KEPT_FORMAT)
        ok = read_nodes_compact(&R, t, nl, nv, rest);
    for (size_t n = 0; ok && format == KEPT_FORMAT_FULL_DEAD && n < nnodes; n++)
        ok = read_node(&R, t, nl, nv, &t->nodes[n]);
    for (size_t i = 0; ok && i < npat; i++)
        ok = read_pattern(&R, t, &t->patterns[i]);
    for (size_t r = 0; ok && r < nrules; r++) {
        t->rule_count[r] = get_u32(&R);
        t->rule_rep[r] = get_i32(&R);
        ok = in_range(&R, t->rule_rep[r], -1, (int64_t)nnodes - 1, "a rule's representative");
    }
    for (size_t c = 0; ok && c < ncomp; c++) {
        int32_t l = get_i32(&R), v = get_i32(&R), r = get_i32(&R), w = get_i32(&R);
        int32_t mi = get_i32(&R);
        turn[c] = get_f64(&R);
        ok = in_range(&R, l, -1, (int64_t)nl - 1, "a component's label") &&
             in_range(&R, v, -1, (int64_t)nv - 1, "a component's variant") &&
             in_range(&R, r, 0, 3, "a component's turn") &&
             in_range(&R, w, 0, 3, "a component's variant turn") &&
             in_range(&R, mi, 0, 1, "a component's mirror flag") &&
             (isfinite(turn[c]) || bad(&R, "a component's turn angle"));
        mirror[c] = (uint8_t)mi;
        label[c] = l;
        variant[c] = v;
        rot[c] = (uint8_t)r;
        vrot[c] = (uint8_t)w;
    }
    for (size_t v = 0; ok && v < nv; v++) {
        ok = in_range(&R, vlabel[v] = get_i32(&R), -1, (int64_t)nl - 1, "a variant's label");
        deviation[v] = get_f64(&R);
        ok = ok && (isfinite(deviation[v]) || bad(&R, "a variant's deviation"));
    }
    if (ok)
        ok = check_links(&R, t);
    json_decref(doc);
    free(data);
    ag_status st = R.st;
    classes.ncomponents = ncomp;
    classes.nlabels = nl;
    classes.nvariants = nv;
    classes.label = label;
    classes.variant = variant;
    classes.rot = rot;
    classes.vrot = vrot;
    classes.variant_label = vlabel;
    classes.mirror = mirror;
    classes.turn = turn;
    classes.variant_deviation = deviation;
    classes.exact_copies = (int)exact_copies;
    out->t = t;
    out->classes = classes;
    if (st)
        kept_parts_free(out);
    return st;
}

ag_status ag_model_kept_reload(const ag_mesh *mesh, const char *tree_text, ag_edit_model **em,
                               ag_error *err)
{
    *em = NULL;
    kept_parts kp;
    ag_status st = read_kept(tree_text, mesh->ncomponents, &kp, err);
    if (st)
        return st;
    ag_mesh *m = ag_mesh_clone(mesh);
    ag_proceduralize_result *r = NULL;
    if (!m)
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    else {
        st = ag_rebuild_finish(m, kp.t, &kp.classes, &r, err); /* takes m and the tree */
        kp.t = NULL;
    }
    ag_proceduralize_options opt = {.segment.keep_groups = 1}; /* as ag_edit_model_create */
    if (!st && (st = ag_edit_model_wrap(r, &opt, em, err)))
        ag_proceduralize_result_free(r);
    kept_parts_free(&kp);
    return st;
}

ag_status ag_model_kept_tree(const char *tree_text, ag_splittree **tree, ag_error *err)
{
    *tree = NULL;
    kept_parts kp;
    ag_status st = read_kept(tree_text, SIZE_MAX, &kp, err);
    if (st)
        return st;
    *tree = kp.t;
    kp.t = NULL;
    kept_parts_free(&kp);
    return AG_OK;
}
