/* Layout (all little-endian). Encoding writes AGM2; decoding reads both.
 *
 * AGM1 (the first format; databases made before AGM2 hold it):
 *   "AGM1"
 *   u64 nverts, u64 ntris, u64 ngroups, u64 ncomponents
 *   f64 pos[3 * nverts]
 *   u32 tri[3 * ntris]
 *   u32 tri_component[ntris]
 *   i32 component_group[ncomponents]
 *   ngroups × (u32 byte length, bytes without NUL)
 *
 * AGM2 (the same mesh, a third of the bytes on a building: every version of an edited model
 * stores its mesh, and the store's writes are most of an edit's time):
 *   "AGM2"
 *   u64 nverts, u64 ntris, u64 ngroups, u64 ncomponents
 *   per vertex: a byte whose bit a says axis a repeats a recent value, then per axis either
 *     u16 slot (a repeat: the value last stored in that axis's slot) or f64 (a new value,
 *     stored in slot hash(value) of its axis); a building's coordinates repeat on every
 *     corner, so most are two bytes
 *   per triangle: varint zigzag(a - previous a), zigzag(b - a), zigzag(c - a)
 *   runs of triangles in one component: varint zigzag(component - previous), varint length
 *   per component: varint (group + 1)
 *   ngroups × (varint byte length, bytes without NUL)
 * Varints are LEB128 (7 bits a byte, low first). Nothing may follow. */
#include "meshblob.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char MAGIC1[4] = {'A', 'G', 'M', '1'};
static const char MAGIC2[4] = {'A', 'G', 'M', '2'};
#define HEADER 36
/* recent values kept per axis (AGM2): a slot is two bytes on the wire */
#define SLOTS 4096

static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

static uint8_t *put_varint(uint8_t *p, uint64_t v)
{
    while (v >= 0x80) {
        *p++ = (uint8_t)(v | 0x80);
        v >>= 7;
    }
    *p++ = (uint8_t)v;
    return p;
}

static uint64_t zigzag(int64_t v) { return ((uint64_t)v << 1) ^ (uint64_t)(v >> 63); }
static int64_t unzigzag(uint64_t u) { return (int64_t)(u >> 1) ^ -(int64_t)(u & 1); }

static uint32_t slot_of(uint64_t bits) { return (uint32_t)((bits * 0x9E3779B97F4A7C15ull) >> 52); }

/* The recent values of each axis, as encoder and decoder both keep them. */
typedef struct {
    uint64_t value[3][SLOTS];
    uint8_t set[3][SLOTS];
} recent;

ag_status ag_meshblob_encode(const ag_mesh *m, uint8_t **out, size_t *len)
{
    *out = NULL;
    *len = 0;
    /* The most each part can take (sizes of in-memory arrays cannot overflow when multiplied
     * back: they exist); the pages past what is written are never touched. */
    size_t n = HEADER + m->nverts * 25 + m->ntris * 30 + m->ncomponents * 5;
    for (size_t g = 0; g < m->ngroups; g++) {
        size_t l = strlen(m->group_names[g]);
        if (l > UINT32_MAX)
            return AG_ERR_TOO_LARGE;
        n += 10 + l;
    }
    uint8_t *b = malloc(n), *p = b;
    recent *r = calloc(1, sizeof *r);
    if (!b || !r) {
        free(b);
        free(r);
        return AG_ERR_NOMEM;
    }
    memcpy(p, MAGIC2, 4);
    put_u64(p + 4, m->nverts);
    put_u64(p + 12, m->ntris);
    put_u64(p + 20, m->ngroups);
    put_u64(p + 28, m->ncomponents);
    p += HEADER;
    for (size_t v = 0; v < m->nverts; v++) {
        uint8_t *flags = p++;
        *flags = 0;
        for (int a = 0; a < 3; a++) {
            uint64_t u;
            memcpy(&u, &m->pos[3 * v + (size_t)a], 8);
            uint32_t k = slot_of(u);
            if (r->set[a][k] && r->value[a][k] == u) {
                *flags |= (uint8_t)(1u << a);
                p[0] = (uint8_t)k;
                p[1] = (uint8_t)(k >> 8);
                p += 2;
            } else {
                r->value[a][k] = u;
                r->set[a][k] = 1;
                put_u64(p, u);
                p += 8;
            }
        }
    }
    int64_t prev = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        int64_t a = m->tri[3 * t], b1 = m->tri[3 * t + 1], c = m->tri[3 * t + 2];
        p = put_varint(p, zigzag(a - prev));
        p = put_varint(p, zigzag(b1 - a));
        p = put_varint(p, zigzag(c - a));
        prev = a;
    }
    prev = 0;
    for (size_t t = 0; t < m->ntris;) {
        size_t run = 1;
        while (t + run < m->ntris && m->tri_component[t + run] == m->tri_component[t])
            run++;
        p = put_varint(p, zigzag((int64_t)m->tri_component[t] - prev));
        p = put_varint(p, run);
        prev = m->tri_component[t];
        t += run;
    }
    for (size_t c = 0; c < m->ncomponents; c++)
        p = put_varint(p, (uint64_t)((int64_t)m->component_group[c] + 1));
    for (size_t g = 0; g < m->ngroups; g++) {
        size_t l = strlen(m->group_names[g]);
        p = put_varint(p, l);
        memcpy(p, m->group_names[g], l);
        p += l;
    }
    free(r);
    *len = (size_t)(p - b);
    uint8_t *fit = realloc(b, *len ? *len : 1); /* gives the unwritten pages back */
    *out = fit ? fit : b;
    return AG_OK;
}

/* Checks that count elements of size bytes fit in what remains at offset off. */
static int fits(size_t off, size_t len, uint64_t count, size_t size)
{
    if (off > len)
        return 0;
    return count <= (len - off) / size;
}

/* The mesh's components and group names once read, or an error; m is freed on failure. */
static ag_status nomem(ag_mesh *m, ag_error *err)
{
    ag_mesh_free(m);
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

static ag_status check_group(size_t c, int64_t g, uint64_t ng, ag_error *err)
{
    if (g < -1 || g >= (int64_t)ng)
        return ag_error_set(err, AG_ERR_PARSE, (long)(c + 1),
                            "mesh blob: component %zu has group %lld of %llu", c + 1,
                            (long long)g, (unsigned long long)ng);
    return AG_OK;
}

static ag_status check_name(const uint8_t *data, size_t len, size_t off, uint64_t l, size_t g,
                            ag_error *err)
{
    if (!fits(off, len, l, 1) || memchr(data + off, '\0', (size_t)l))
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: bad group name %zu", g + 1);
    return AG_OK;
}

static ag_status check_vertex_index(size_t t, uint32_t v, uint64_t nv, ag_error *err)
{
    if (v >= nv)
        return ag_error_set(err, AG_ERR_PARSE, (long)(t + 1),
                            "mesh blob: triangle %zu uses vertex %u of %llu", t + 1, v,
                            (unsigned long long)nv);
    return AG_OK;
}

static ag_status check_finite(size_t i, double v, ag_error *err)
{
    if (!isfinite(v))
        return ag_error_set(err, AG_ERR_PARSE, (long)(i / 3 + 1),
                            "mesh blob: vertex %zu is not finite", i / 3 + 1);
    return AG_OK;
}

static ag_status check_component(size_t t, uint64_t c, uint64_t nc, ag_error *err)
{
    if (c >= nc)
        return ag_error_set(err, AG_ERR_PARSE, (long)(t + 1),
                            "mesh blob: triangle %zu in component %llu of %llu", t + 1,
                            (unsigned long long)c, (unsigned long long)nc);
    return AG_OK;
}

static ag_status add_name(ag_mesh *m, const uint8_t *at, size_t l)
{
    char *name = strndup((const char *)at, l);
    if (!name)
        return AG_ERR_NOMEM;
    ag_status st = ag_mesh_add_group(m, name, NULL);
    free(name);
    return st;
}

static ag_status decode_v1(const uint8_t *data, size_t len, uint64_t nv, uint64_t nt,
                           uint64_t ng, uint64_t nc, ag_mesh *m, ag_error *err)
{
    size_t off = HEADER;
    /* Every section must fit in the rest of the buffer before anything is allocated. */
    if (!fits(off, len, nv, 24))
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated positions");
    size_t pos_off = off;
    off += (size_t)nv * 24;
    if (!fits(off, len, nt, 16))
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated triangles");
    size_t tri_off = off;
    off += (size_t)nt * 16;
    if (!fits(off, len, nc, 4))
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated components");
    size_t comp_off = off;
    off += (size_t)nc * 4;
    if (!fits(off, len, ng, 4)) /* each name has at least its length */
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated group names");
    if (ag_mesh_reserve(m, (size_t)nv, (size_t)nt) != AG_OK)
        return AG_ERR_NOMEM;
    ag_status st;
    for (size_t i = 0; i < 3 * (size_t)nv; i++) {
        uint64_t u = get_u64(data + pos_off + 8 * i);
        memcpy(&m->pos[i], &u, 8);
        if ((st = check_finite(i, m->pos[i], err)) != AG_OK)
            return st;
    }
    m->nverts = (size_t)nv;
    for (size_t i = 0; i < 3 * (size_t)nt; i++) {
        m->tri[i] = get_u32(data + tri_off + 4 * i);
        if ((st = check_vertex_index(i / 3, m->tri[i], nv, err)) != AG_OK)
            return st;
    }
    const uint8_t *tc = data + tri_off + 12 * (size_t)nt;
    for (size_t i = 0; i < (size_t)nt; i++) {
        m->tri_component[i] = get_u32(tc + 4 * i);
        if ((st = check_component(i, m->tri_component[i], nc, err)) != AG_OK)
            return st;
    }
    m->ntris = (size_t)nt;
    for (size_t i = 0; i < (size_t)nc; i++) {
        int32_t g = (int32_t)get_u32(data + comp_off + 4 * i);
        if ((st = check_group(i, g, ng, err)) != AG_OK)
            return st;
        if (ag_mesh_add_component(m, g, NULL) != AG_OK)
            return AG_ERR_NOMEM;
    }
    for (size_t g = 0; g < (size_t)ng; g++) {
        if (!fits(off, len, 1, 4))
            return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated group names");
        uint32_t l = get_u32(data + off);
        off += 4;
        if ((st = check_name(data, len, off, l, g, err)) != AG_OK)
            return st;
        if (add_name(m, data + off, l) != AG_OK)
            return AG_ERR_NOMEM;
        off += l;
    }
    if (off != len)
        return ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: %zu trailing bytes",
                            len - off);
    return AG_OK;
}

typedef struct {
    const uint8_t *p;
    size_t off, len;
} reader;

static int get_varint(reader *r, uint64_t *v)
{
    uint64_t x = 0;
    for (int shift = 0; shift < 64; shift += 7) {
        if (r->off >= r->len)
            return 0;
        uint8_t b = r->p[r->off++];
        x |= (uint64_t)(b & 0x7f) << shift;
        if (!(b & 0x80)) {
            *v = x;
            return 1;
        }
    }
    return 0; /* longer than any 64-bit value */
}

static ag_status truncated(const reader *r, const char *what, ag_error *err)
{
    return ag_error_set(err, AG_ERR_PARSE, (long)r->off, "mesh blob: truncated %s", what);
}

/* base + a signed step read from r, in [0, below): the step is bounded before it is added. */
static int get_step(reader *r, int64_t base, uint64_t below, int64_t *out)
{
    uint64_t u;
    if (!get_varint(r, &u))
        return 0;
    int64_t d = unzigzag(u);
    if (d > (int64_t)below || d < -(int64_t)below)
        *out = -1;
    else
        *out = base + d;
    return 1;
}

static ag_status decode_v2(const uint8_t *data, size_t len, uint64_t nv, uint64_t nt,
                           uint64_t ng, uint64_t nc, ag_mesh *m, ag_error *err)
{
    reader r = {.p = data, .off = HEADER, .len = len};
    /* the least each vertex (a flag, three slots) and triangle (three one-byte steps) takes,
     * before anything is allocated */
    if (!fits(r.off, len, nv, 7))
        return truncated(&r, "positions", err);
    if (!fits(r.off + (size_t)nv * 7, len, nt, 3))
        return truncated(&r, "triangles", err);
    if (ag_mesh_reserve(m, (size_t)nv, (size_t)nt) != AG_OK)
        return AG_ERR_NOMEM;
    recent *rc = calloc(1, sizeof *rc);
    if (!rc)
        return AG_ERR_NOMEM;
    ag_status st = AG_OK;
    for (size_t v = 0; st == AG_OK && v < (size_t)nv; v++) {
        if (r.off >= len) {
            st = truncated(&r, "positions", err);
            break;
        }
        uint8_t flags = data[r.off++];
        if (flags > 7) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)(v + 1),
                              "mesh blob: vertex %zu has bad flags %u", v + 1, flags);
            break;
        }
        for (int a = 0; st == AG_OK && a < 3; a++) {
            uint64_t u;
            if (flags & (1u << a)) {
                if (!fits(r.off, len, 1, 2)) {
                    st = truncated(&r, "positions", err);
                    break;
                }
                uint32_t k = data[r.off] | (uint32_t)data[r.off + 1] << 8;
                r.off += 2;
                if (k >= SLOTS || !rc->set[a][k]) {
                    st = ag_error_set(err, AG_ERR_PARSE, (long)(v + 1),
                                      "mesh blob: vertex %zu repeats a value never given", v + 1);
                    break;
                }
                u = rc->value[a][k];
            } else {
                if (!fits(r.off, len, 1, 8)) {
                    st = truncated(&r, "positions", err);
                    break;
                }
                u = get_u64(data + r.off);
                r.off += 8;
                uint32_t k = slot_of(u);
                rc->value[a][k] = u;
                rc->set[a][k] = 1;
            }
            size_t i = 3 * v + (size_t)a;
            memcpy(&m->pos[i], &u, 8);
            st = check_finite(i, m->pos[i], err);
        }
    }
    free(rc);
    if (st != AG_OK)
        return st;
    m->nverts = (size_t)nv;
    int64_t prev = 0;
    for (size_t t = 0; t < (size_t)nt; t++) {
        int64_t a, b, c;
        if (!get_step(&r, prev, nv, &a) || !get_step(&r, a < 0 ? 0 : a, nv, &b) ||
            !get_step(&r, a < 0 ? 0 : a, nv, &c))
            return truncated(&r, "triangles", err);
        const int64_t idx[3] = {a, b, c};
        for (int q = 0; q < 3; q++) {
            uint32_t vi = idx[q] < 0 || idx[q] > UINT32_MAX ? UINT32_MAX : (uint32_t)idx[q];
            if ((st = check_vertex_index(t, vi, nv, err)) != AG_OK)
                return st;
            m->tri[3 * t + (size_t)q] = vi;
        }
        prev = a;
    }
    prev = 0;
    for (size_t t = 0; t < (size_t)nt;) {
        int64_t c;
        uint64_t run;
        if (!get_step(&r, prev, nc, &c) || !get_varint(&r, &run))
            return truncated(&r, "components", err);
        if ((st = check_component(t, c < 0 ? UINT64_MAX : (uint64_t)c, nc, err)) != AG_OK)
            return st;
        if (run < 1 || run > (uint64_t)nt - t)
            return ag_error_set(err, AG_ERR_PARSE, (long)(t + 1),
                                "mesh blob: a run of %llu triangles from triangle %zu of %llu",
                                (unsigned long long)run, t + 1, (unsigned long long)nt);
        for (size_t k = 0; k < (size_t)run; k++)
            m->tri_component[t + k] = (uint32_t)c;
        t += (size_t)run;
        prev = c;
    }
    m->ntris = (size_t)nt;
    if (!fits(r.off, len, nc, 1))
        return truncated(&r, "components", err);
    for (size_t c = 0; c < (size_t)nc; c++) {
        uint64_t g1;
        if (!get_varint(&r, &g1))
            return truncated(&r, "components", err);
        int64_t g = g1 > (uint64_t)INT32_MAX + 1 ? INT64_MAX : (int64_t)g1 - 1;
        if ((st = check_group(c, g, ng, err)) != AG_OK)
            return st;
        if (ag_mesh_add_component(m, (int32_t)g, NULL) != AG_OK)
            return AG_ERR_NOMEM;
    }
    if (!fits(r.off, len, ng, 1)) /* each name has at least its length */
        return truncated(&r, "group names", err);
    for (size_t g = 0; g < (size_t)ng; g++) {
        uint64_t l;
        if (!get_varint(&r, &l))
            return truncated(&r, "group names", err);
        if ((st = check_name(data, len, r.off, l, g, err)) != AG_OK)
            return st;
        if (add_name(m, data + r.off, (size_t)l) != AG_OK)
            return AG_ERR_NOMEM;
        r.off += (size_t)l;
    }
    if (r.off != len)
        return ag_error_set(err, AG_ERR_PARSE, (long)r.off, "mesh blob: %zu trailing bytes",
                            len - r.off);
    return AG_OK;
}

ag_status ag_meshblob_decode(const uint8_t *data, size_t len, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    int version = len >= 4 && !memcmp(data, MAGIC1, 4)   ? 1
                  : len >= 4 && !memcmp(data, MAGIC2, 4) ? 2
                                                         : 0;
    if (!version)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: bad magic");
    if (len < HEADER)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: truncated header");
    uint64_t nv = get_u64(data + 4), nt = get_u64(data + 12), ng = get_u64(data + 20),
             nc = get_u64(data + 28);
    if (nv >= UINT32_MAX || nc >= UINT32_MAX || ng > INT32_MAX)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: counts out of range");
    ag_mesh *m = ag_mesh_create();
    if (!m)
        return nomem(NULL, err);
    ag_status st = version == 1 ? decode_v1(data, len, nv, nt, ng, nc, m, err)
                                : decode_v2(data, len, nv, nt, ng, nc, m, err);
    if (st == AG_ERR_NOMEM)
        return nomem(m, err);
    if (st != AG_OK) {
        ag_mesh_free(m);
        return st;
    }
    *out = m;
    return AG_OK;
}
