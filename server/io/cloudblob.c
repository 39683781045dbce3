#include "cloudblob.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h"

/* A step's thousandth: what the reader's arithmetic (integer * scale + offset - origin) may
 * move a LAS coordinate off its grid. */
#define GRID_TOLERANCE 1e-3

const char *ag_cloudblob_positions_name(ag_cloudblob_positions e)
{
    switch (e) {
    case AG_CLOUDBLOB_I32: return "i32";
    case AG_CLOUDBLOB_F32: return "f32";
    case AG_CLOUDBLOB_F64: return "f64";
    }
    return "?";
}

ag_cloudblob_positions ag_cloudblob_positions_from_name(const char *name)
{
    for (int e = AG_CLOUDBLOB_I32; name && e <= AG_CLOUDBLOB_F64; e++)
        if (strcmp(name, ag_cloudblob_positions_name((ag_cloudblob_positions)e)) == 0)
            return (ag_cloudblob_positions)e;
    return 0;
}

size_t ag_cloudblob_positions_size(ag_cloudblob_positions e)
{
    return e == AG_CLOUDBLOB_F64 ? 24 : 12;
}

static int on_grid(double v, double scale)
{
    double q = round(v / scale);
    return fabs(q) <= 2147483647.0 && fabs(q * scale - v) <= GRID_TOLERANCE * scale;
}

ag_cloudblob_positions ag_cloudblob_positions_choose(const ag_cloud *c)
{
    int grid = c->scale[0] > 0 && c->scale[1] > 0 && c->scale[2] > 0, f32 = 1;
    for (size_t i = 0; i < 3 * c->n && (grid || f32); i++) {
        double v = c->xyz[i];
        if (grid && !on_grid(v, c->scale[i % 3]))
            grid = 0;
        if (f32 && (double)(float)v != v)
            f32 = 0;
    }
    /* exact floats win over the grid: nothing at all moves */
    return f32 ? AG_CLOUDBLOB_F32 : grid ? AG_CLOUDBLOB_I32 : AG_CLOUDBLOB_F64;
}

static ag_status alloc_out(size_t count, size_t each, uint8_t **out, size_t *len, ag_error *err)
{
    *out = NULL;
    *len = 0;
    if (each && count > SIZE_MAX / each)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu values do not fit in memory", count);
    *len = count * each;
    if (!(*out = malloc(*len ? *len : 1)))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory encoding %zu points", count);
    return AG_OK;
}

ag_status ag_cloudblob_encode_positions(const ag_cloud *c, ag_cloudblob_positions e,
                                        size_t start, size_t count, uint8_t **out, size_t *len,
                                        ag_error *err)
{
    ag_status st = alloc_out(count, ag_cloudblob_positions_size(e), out, len, err);
    if (st != AG_OK)
        return st;
    const double *v = c->xyz + 3 * start;
    uint8_t *p = *out;
    for (size_t i = 0; i < 3 * count; i++) {
        switch (e) {
        case AG_CLOUDBLOB_I32:
            ag_bytes_put_u32le(p + 4 * i, (uint32_t)(int32_t)round(v[i] / c->scale[i % 3]));
            break;
        case AG_CLOUDBLOB_F32: ag_bytes_put_f32le(p + 4 * i, (float)v[i]); break;
        case AG_CLOUDBLOB_F64: ag_bytes_put_f64le(p + 8 * i, v[i]); break;
        }
    }
    return AG_OK;
}

ag_status ag_cloudblob_encode_normals(const ag_cloud *c, size_t start, size_t count,
                                      uint8_t **out, size_t *len, ag_error *err)
{
    if (!c->normals)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "the cloud has no normals");
    ag_status st = alloc_out(count, 12, out, len, err);
    for (size_t i = 0; st == AG_OK && i < 3 * count; i++)
        ag_bytes_put_f32le(*out + 4 * i, c->normals[3 * start + i]);
    return st;
}

ag_status ag_cloudblob_encode_property(const ag_cloud *c, size_t p, size_t start, size_t count,
                                       uint8_t **out, size_t *len, ag_error *err)
{
    size_t size = ag_scalar_size(c->props[p].type);
    ag_status st = alloc_out(count, size, out, len, err);
    const uint8_t *src = (const uint8_t *)c->props[p].values + start * size;
    for (size_t i = 0; st == AG_OK && i < count; i++)
        ag_bytes_store(*out + i * size, src + i * size, size, 0);
    return st;
}

static ag_status check_len(size_t len, size_t count, size_t each, const char *what,
                           ag_error *err)
{
    if (each && count > SIZE_MAX / each)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu %s do not fit in memory", count, what);
    if (len != count * each)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "a stored chunk of %s holds %zu bytes, not the %zu of %zu points",
                            what, len, count * each, count);
    return AG_OK;
}

ag_status ag_cloudblob_decode_positions(const uint8_t *data, size_t len,
                                        ag_cloudblob_positions e, ag_cloud *c, size_t start,
                                        size_t count, ag_error *err)
{
    if (!ag_cloudblob_positions_from_name(ag_cloudblob_positions_name(e)))
        return ag_error_set(err, AG_ERR_PARSE, 0, "unknown position encoding %d", (int)e);
    ag_status st = check_len(len, count, ag_cloudblob_positions_size(e), "positions", err);
    if (st != AG_OK)
        return st;
    double *v = c->xyz + 3 * start;
    for (size_t i = 0; i < 3 * count; i++) {
        switch (e) {
        case AG_CLOUDBLOB_I32:
            v[i] = (double)(int32_t)ag_bytes_u32le(data + 4 * i) * c->scale[i % 3];
            break;
        case AG_CLOUDBLOB_F32: v[i] = ag_bytes_f32le(data + 4 * i); break;
        case AG_CLOUDBLOB_F64: v[i] = ag_bytes_f64le(data + 8 * i); break;
        }
    }
    return AG_OK;
}

ag_status ag_cloudblob_decode_normals(const uint8_t *data, size_t len, ag_cloud *c, size_t start,
                                      size_t count, ag_error *err)
{
    ag_status st = check_len(len, count, 12, "normals", err);
    if (st == AG_OK && !c->normals)
        st = ag_error_set(err, AG_ERR_INTERNAL, 0, "the cloud has no room for normals");
    for (size_t i = 0; st == AG_OK && i < 3 * count; i++)
        c->normals[3 * start + i] = ag_bytes_f32le(data + 4 * i);
    return st;
}

ag_status ag_cloudblob_decode_property(const uint8_t *data, size_t len, ag_cloud *c, size_t p,
                                       size_t start, size_t count, ag_error *err)
{
    size_t size = ag_scalar_size(c->props[p].type);
    ag_status st = check_len(len, count, size, c->props[p].name, err);
    uint8_t *dst = (uint8_t *)c->props[p].values + start * size;
    for (size_t i = 0; st == AG_OK && i < count; i++)
        ag_bytes_load(dst + i * size, data + i * size, size, 0);
    return st;
}

unsigned ag_cloudblob_id_width(int64_t max_id)
{
    return max_id < INT8_MAX ? 1 : max_id < INT16_MAX ? 2 : 4;
}

ag_status ag_cloudblob_encode_ids(const int32_t *ids, size_t count, unsigned width,
                                  uint8_t **out, size_t *len, ag_error *err)
{
    if (width != 1 && width != 2 && width != 4)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "ids of %u bytes", width);
    ag_status st = alloc_out(count, width, out, len, err);
    for (size_t i = 0; st == AG_OK && i < count; i++) {
        int32_t v = ids[i];
        if ((width == 1 && (v < INT8_MIN || v > INT8_MAX)) ||
            (width == 2 && (v < INT16_MIN || v > INT16_MAX))) {
            st = ag_error_set(err, AG_ERR_INTERNAL, (long)i + 1, "id %d does not fit %u bytes",
                              v, width);
            break;
        }
        if (width == 1)
            (*out)[i] = (uint8_t)(int8_t)v;
        else if (width == 2)
            ag_bytes_put_u16le(*out + 2 * i, (uint16_t)(int16_t)v);
        else
            ag_bytes_put_u32le(*out + 4 * i, (uint32_t)v);
    }
    if (st != AG_OK) {
        free(*out);
        *out = NULL;
    }
    return st;
}

ag_status ag_cloudblob_decode_ids(const uint8_t *data, size_t len, unsigned width, int32_t *ids,
                                  size_t count, ag_error *err)
{
    if (width != 1 && width != 2 && width != 4)
        return ag_error_set(err, AG_ERR_PARSE, 0, "stored ids of %u bytes", width);
    ag_status st = check_len(len, count, width, "ids", err);
    for (size_t i = 0; st == AG_OK && i < count; i++)
        ids[i] = width == 1   ? (int8_t)data[i]
                 : width == 2 ? (int16_t)ag_bytes_u16le(data + 2 * i)
                              : (int32_t)ag_bytes_u32le(data + 4 * i);
    return st;
}

ag_status ag_cloudblob_encode_indices(const uint32_t *idx, size_t count, uint8_t **out,
                                      size_t *len, ag_error *err)
{
    ag_status st = alloc_out(count, 4, out, len, err);
    for (size_t i = 0; st == AG_OK && i < count; i++)
        ag_bytes_put_u32le(*out + 4 * i, idx[i]);
    return st;
}

ag_status ag_cloudblob_decode_indices(const uint8_t *data, size_t len, uint32_t *idx,
                                      size_t count, ag_error *err)
{
    ag_status st = check_len(len, count, 4, "indices", err);
    for (size_t i = 0; st == AG_OK && i < count; i++)
        idx[i] = ag_bytes_u32le(data + 4 * i);
    return st;
}
