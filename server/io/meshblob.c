/* Layout (all little-endian):
 *   "AGM1"
 *   u64 nverts, u64 ntris, u64 ngroups, u64 ncomponents
 *   f64 pos[3 * nverts]
 *   u32 tri[3 * ntris]
 *   u32 tri_component[ntris]
 *   i32 component_group[ncomponents]
 *   ngroups × (u32 byte length, bytes without NUL)
 * Nothing may follow. */
#include "meshblob.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char MAGIC[4] = {'A', 'G', 'M', '1'};

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

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

ag_status ag_meshblob_encode(const ag_mesh *m, uint8_t **out, size_t *len)
{
    *out = NULL;
    *len = 0;
    /* Sizes of in-memory arrays cannot overflow when multiplied back: they exist. */
    size_t n = 4 + 32 + m->nverts * 24 + m->ntris * 16 + m->ncomponents * 4;
    for (size_t g = 0; g < m->ngroups; g++) {
        size_t l = strlen(m->group_names[g]);
        if (l > UINT32_MAX)
            return AG_ERR_TOO_LARGE;
        n += 4 + l;
    }
    uint8_t *b = malloc(n), *p = b;
    if (!b)
        return AG_ERR_NOMEM;
    memcpy(p, MAGIC, 4);
    p += 4;
    put_u64(p, m->nverts);
    put_u64(p + 8, m->ntris);
    put_u64(p + 16, m->ngroups);
    put_u64(p + 24, m->ncomponents);
    p += 32;
    for (size_t i = 0; i < 3 * m->nverts; i++, p += 8) {
        uint64_t u;
        memcpy(&u, &m->pos[i], 8);
        put_u64(p, u);
    }
    for (size_t i = 0; i < 3 * m->ntris; i++, p += 4)
        put_u32(p, m->tri[i]);
    for (size_t i = 0; i < m->ntris; i++, p += 4)
        put_u32(p, m->tri_component[i]);
    for (size_t i = 0; i < m->ncomponents; i++, p += 4)
        put_u32(p, (uint32_t)m->component_group[i]);
    for (size_t g = 0; g < m->ngroups; g++) {
        size_t l = strlen(m->group_names[g]);
        put_u32(p, (uint32_t)l);
        memcpy(p + 4, m->group_names[g], l);
        p += 4 + l;
    }
    *out = b;
    *len = n;
    return AG_OK;
}

/* Checks that count elements of size bytes fit in what remains at offset off. */
static int fits(size_t off, size_t len, uint64_t count, size_t size)
{
    if (off > len)
        return 0;
    return count <= (len - off) / size;
}

ag_status ag_meshblob_decode(const uint8_t *data, size_t len, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (len < 4 || memcmp(data, MAGIC, 4) != 0)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: bad magic");
    if (len < 36)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: truncated header");
    uint64_t nv = get_u64(data + 4), nt = get_u64(data + 12), ng = get_u64(data + 20),
             nc = get_u64(data + 28);
    size_t off = 36;
    if (nv >= UINT32_MAX || nc >= UINT32_MAX || ng > INT32_MAX)
        return ag_error_set(err, AG_ERR_PARSE, 0, "mesh blob: counts out of range");
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

    ag_mesh *m = ag_mesh_create();
    if (!m || ag_mesh_reserve(m, (size_t)nv, (size_t)nt) != AG_OK) {
        ag_mesh_free(m);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_status st = AG_OK;
    for (size_t i = 0; i < 3 * (size_t)nv; i++) {
        uint64_t u = get_u64(data + pos_off + 8 * i);
        memcpy(&m->pos[i], &u, 8);
        if (!isfinite(m->pos[i])) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)(i / 3 + 1),
                              "mesh blob: vertex %zu is not finite", i / 3 + 1);
            goto fail;
        }
    }
    m->nverts = (size_t)nv;
    for (size_t i = 0; i < 3 * (size_t)nt; i++) {
        m->tri[i] = get_u32(data + tri_off + 4 * i);
        if (m->tri[i] >= nv) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)(i / 3 + 1),
                              "mesh blob: triangle %zu uses vertex %u of %llu", i / 3 + 1,
                              m->tri[i], (unsigned long long)nv);
            goto fail;
        }
    }
    const uint8_t *tc = data + tri_off + 12 * (size_t)nt;
    for (size_t i = 0; i < (size_t)nt; i++) {
        m->tri_component[i] = get_u32(tc + 4 * i);
        if (m->tri_component[i] >= nc) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)(i + 1),
                              "mesh blob: triangle %zu in component %u of %llu", i + 1,
                              m->tri_component[i], (unsigned long long)nc);
            goto fail;
        }
    }
    m->ntris = (size_t)nt;
    for (size_t i = 0; i < (size_t)nc; i++) {
        int32_t g = (int32_t)get_u32(data + comp_off + 4 * i);
        if (g < -1 || (int64_t)g >= (int64_t)ng) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)(i + 1),
                              "mesh blob: component %zu has group %d of %llu", i + 1, g,
                              (unsigned long long)ng);
            goto fail;
        }
        if (ag_mesh_add_component(m, g, NULL) != AG_OK)
            goto nomem;
    }
    for (size_t g = 0; g < (size_t)ng; g++) {
        if (!fits(off, len, 1, 4)) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: truncated group names");
            goto fail;
        }
        uint32_t l = get_u32(data + off);
        off += 4;
        if (!fits(off, len, l, 1) || memchr(data + off, '\0', l)) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: bad group name %zu",
                              g + 1);
            goto fail;
        }
        char *name = strndup((const char *)data + off, l);
        if (!name)
            goto nomem;
        st = ag_mesh_add_group(m, name, NULL);
        free(name);
        if (st != AG_OK)
            goto nomem;
        off += l;
    }
    if (off != len) {
        st = ag_error_set(err, AG_ERR_PARSE, (long)off, "mesh blob: %zu trailing bytes",
                          len - off);
        goto fail;
    }
    *out = m;
    return AG_OK;
nomem:
    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
fail:
    ag_mesh_free(m);
    return st;
}
