#include "cloud.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const struct {
    const char *name;
    size_t size;
} scalar_info[AG_SCALAR_COUNT] = {
    [AG_SCALAR_INT8] = {"int8", 1},       [AG_SCALAR_UINT8] = {"uint8", 1},
    [AG_SCALAR_INT16] = {"int16", 2},     [AG_SCALAR_UINT16] = {"uint16", 2},
    [AG_SCALAR_INT32] = {"int32", 4},     [AG_SCALAR_UINT32] = {"uint32", 4},
    [AG_SCALAR_INT64] = {"int64", 8},     [AG_SCALAR_UINT64] = {"uint64", 8},
    [AG_SCALAR_FLOAT32] = {"float32", 4}, [AG_SCALAR_FLOAT64] = {"float64", 8},
};

size_t ag_scalar_size(ag_scalar_type t)
{
    return (unsigned)t < AG_SCALAR_COUNT ? scalar_info[t].size : 0;
}

const char *ag_scalar_name(ag_scalar_type t)
{
    return (unsigned)t < AG_SCALAR_COUNT ? scalar_info[t].name : "?";
}

int ag_scalar_is_float(ag_scalar_type t)
{
    return t == AG_SCALAR_FLOAT32 || t == AG_SCALAR_FLOAT64;
}

ag_cloud *ag_cloud_create(void)
{
    return calloc(1, sizeof(ag_cloud));
}

void ag_cloud_free(ag_cloud *c)
{
    if (!c)
        return;
    free(c->xyz);
    free(c->normals);
    for (size_t i = 0; i < c->nprops; i++)
        free(c->props[i].values);
    free(c);
}

/* n * each bytes, or 0 when that overflows (callers treat 0 for n > 0 as too large). */
static size_t checked_bytes(size_t n, size_t each)
{
    return each && n > SIZE_MAX / each ? 0 : n * each;
}

static int grow(void **p, size_t old_n, size_t new_n, size_t each)
{
    size_t bytes = checked_bytes(new_n, each);
    if (new_n && !bytes)
        return -1;
    void *q = realloc(*p, bytes ? bytes : 1);
    if (!q)
        return -1;
    if (new_n > old_n)
        memset((char *)q + old_n * each, 0, (new_n - old_n) * each);
    *p = q;
    return 0;
}

ag_status ag_cloud_reserve(ag_cloud *c, size_t n, ag_error *err)
{
    if (n <= c->cap)
        return AG_OK;
    if (!checked_bytes(n, 3 * sizeof(double)))
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points do not fit in memory", n);
    /* Each array grows to the new capacity; contents beyond c->n are zeroed. */
    if (grow((void **)&c->xyz, c->cap * 3, n * 3, sizeof(double)) ||
        (c->normals && grow((void **)&c->normals, c->cap * 3, n * 3, sizeof(float))))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for %zu points", n);
    for (size_t i = 0; i < c->nprops; i++)
        if (grow(&c->props[i].values, c->cap, n, ag_scalar_size(c->props[i].type)))
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for %zu points", n);
    c->cap = n;
    return AG_OK;
}

ag_status ag_cloud_resize(ag_cloud *c, size_t n, ag_error *err)
{
    if (n > c->cap) {
        /* amortised growth for appenders, exact size for readers that know n */
        size_t want = c->n && n < c->cap + c->cap / 2 ? c->cap + c->cap / 2 : n;
        if (want < n)
            want = n;
        ag_status st = ag_cloud_reserve(c, want, err);
        if (st != AG_OK)
            return st;
    } else if (n < c->n) {
        /* keep the invariant that everything past n is zero */
        memset(c->xyz + 3 * n, 0, (c->n - n) * 3 * sizeof(double));
        if (c->normals)
            memset(c->normals + 3 * n, 0, (c->n - n) * 3 * sizeof(float));
        for (size_t i = 0; i < c->nprops; i++) {
            size_t s = ag_scalar_size(c->props[i].type);
            memset((char *)c->props[i].values + n * s, 0, (c->n - n) * s);
        }
    }
    c->n = n;
    return AG_OK;
}

ag_status ag_cloud_add_normals(ag_cloud *c, ag_error *err)
{
    if (c->normals)
        return AG_OK;
    c->normals = calloc(c->cap ? c->cap * 3 : 1, sizeof(float));
    if (!c->normals)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for normals");
    return AG_OK;
}

ag_status ag_cloud_add_property(ag_cloud *c, const char *name, ag_scalar_type type,
                                size_t *index, ag_error *err)
{
    size_t len = name ? strlen(name) : 0;
    if (!len || len >= AG_CLOUD_NAME_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "property name '%.80s' is empty or too long",
                            name ? name : "");
    if ((unsigned)type >= AG_SCALAR_COUNT)
        return ag_error_set(err, AG_ERR_INVALID, 0, "property '%s' has no scalar type", name);
    if (ag_cloud_find(c, name))
        return ag_error_set(err, AG_ERR_INVALID, 0, "property '%s' appears twice", name);
    if (c->nprops >= AG_CLOUD_MAX_PROPERTIES)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "more than %d properties per point",
                            AG_CLOUD_MAX_PROPERTIES);
    void *values = calloc(c->cap ? c->cap : 1, ag_scalar_size(type));
    if (!values)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for property '%s'", name);
    ag_cloud_property *p = &c->props[c->nprops];
    memcpy(p->name, name, len + 1);
    p->type = type;
    p->values = values;
    if (index)
        *index = c->nprops;
    c->nprops++;
    return AG_OK;
}

ag_cloud_property *ag_cloud_find(const ag_cloud *c, const char *name)
{
    for (size_t i = 0; i < c->nprops; i++)
        if (!strcmp(c->props[i].name, name))
            return (ag_cloud_property *)&c->props[i];
    return NULL;
}

void ag_cloud_remove_property(ag_cloud *c, const char *name)
{
    ag_cloud_property *p = ag_cloud_find(c, name);
    if (!p)
        return;
    size_t i = (size_t)(p - c->props);
    free(p->values);
    memmove(&c->props[i], &c->props[i + 1], (c->nprops - i - 1) * sizeof c->props[0]);
    c->nprops--;
}

double ag_cloud_get(const ag_cloud_property *p, size_t i)
{
    switch (p->type) {
    case AG_SCALAR_INT8: return ((const int8_t *)p->values)[i];
    case AG_SCALAR_UINT8: return ((const uint8_t *)p->values)[i];
    case AG_SCALAR_INT16: return ((const int16_t *)p->values)[i];
    case AG_SCALAR_UINT16: return ((const uint16_t *)p->values)[i];
    case AG_SCALAR_INT32: return ((const int32_t *)p->values)[i];
    case AG_SCALAR_UINT32: return ((const uint32_t *)p->values)[i];
    case AG_SCALAR_INT64: return (double)((const int64_t *)p->values)[i];
    case AG_SCALAR_UINT64: return (double)((const uint64_t *)p->values)[i];
    case AG_SCALAR_FLOAT32: return ((const float *)p->values)[i];
    case AG_SCALAR_FLOAT64: return ((const double *)p->values)[i];
    default: return 0;
    }
}

static double clamp_round(double v, double lo, double hi)
{
    if (!(v == v))
        return 0;
    v = nearbyint(v);
    return v < lo ? lo : v > hi ? hi : v;
}

void ag_cloud_set(ag_cloud_property *p, size_t i, double v)
{
    switch (p->type) {
    case AG_SCALAR_INT8: ((int8_t *)p->values)[i] = (int8_t)clamp_round(v, INT8_MIN, INT8_MAX); break;
    case AG_SCALAR_UINT8: ((uint8_t *)p->values)[i] = (uint8_t)clamp_round(v, 0, UINT8_MAX); break;
    case AG_SCALAR_INT16: ((int16_t *)p->values)[i] = (int16_t)clamp_round(v, INT16_MIN, INT16_MAX); break;
    case AG_SCALAR_UINT16: ((uint16_t *)p->values)[i] = (uint16_t)clamp_round(v, 0, UINT16_MAX); break;
    case AG_SCALAR_INT32: ((int32_t *)p->values)[i] = (int32_t)clamp_round(v, INT32_MIN, INT32_MAX); break;
    case AG_SCALAR_UINT32: ((uint32_t *)p->values)[i] = (uint32_t)clamp_round(v, 0, UINT32_MAX); break;
    /* 2^63 is the first double past the int64 range */
    case AG_SCALAR_INT64: ((int64_t *)p->values)[i] = (int64_t)clamp_round(v, -9223372036854775808.0, 9223372036854774784.0); break;
    case AG_SCALAR_UINT64: ((uint64_t *)p->values)[i] = (uint64_t)clamp_round(v, 0, 18446744073709549568.0); break;
    case AG_SCALAR_FLOAT32: ((float *)p->values)[i] = (float)v; break;
    case AG_SCALAR_FLOAT64: ((double *)p->values)[i] = v; break;
    default: break;
    }
}

/* s (new) gets c's frame, n points, and c's normals and properties, uninitialized. */
static ag_status shape_like(const ag_cloud *c, size_t n, ag_cloud *s, ag_error *err)
{
    memcpy(s->offset, c->offset, sizeof s->offset);
    memcpy(s->scale, c->scale, sizeof s->scale);
    ag_status st = ag_cloud_resize(s, n, err);
    if (st == AG_OK && c->normals)
        st = ag_cloud_add_normals(s, err);
    for (size_t p = 0; st == AG_OK && p < c->nprops; p++)
        st = ag_cloud_add_property(s, c->props[p].name, c->props[p].type, NULL, err);
    return st;
}

ag_status ag_cloud_subset(const ag_cloud *c, const uint32_t *idx, size_t k, ag_cloud **out,
                          ag_error *err)
{
    *out = NULL;
    ag_cloud *s = ag_cloud_create();
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = shape_like(c, k, s, err);
    if (st != AG_OK) {
        ag_cloud_free(s);
        return st;
    }
    for (size_t i = 0; i < k; i++) {
        uint32_t j = idx[i];
        memcpy(s->xyz + 3 * i, c->xyz + 3 * (size_t)j, 3 * sizeof(double));
        if (c->normals)
            memcpy(s->normals + 3 * i, c->normals + 3 * (size_t)j, 3 * sizeof(float));
    }
    for (size_t p = 0; p < c->nprops; p++) {
        size_t sz = ag_scalar_size(c->props[p].type);
        const char *src = c->props[p].values;
        char *dst = s->props[p].values;
        for (size_t i = 0; i < k; i++)
            memcpy(dst + i * sz, src + (size_t)idx[i] * sz, sz);
    }
    *out = s;
    return AG_OK;
}

ag_status ag_cloud_clone(const ag_cloud *c, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_cloud *s = ag_cloud_create();
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = shape_like(c, c->n, s, err);
    if (st != AG_OK) {
        ag_cloud_free(s);
        return st;
    }
    memcpy(s->xyz, c->xyz, 3 * c->n * sizeof *s->xyz);
    if (c->normals)
        memcpy(s->normals, c->normals, 3 * c->n * sizeof *s->normals);
    for (size_t p = 0; p < c->nprops; p++)
        memcpy(s->props[p].values, c->props[p].values, c->n * ag_scalar_size(c->props[p].type));
    *out = s;
    return AG_OK;
}

void ag_cloud_bounds(const ag_cloud *c, double min[3], double max[3])
{
    ag_box b = ag_cloud_box(c);
    memcpy(min, b.min, sizeof b.min);
    memcpy(max, b.max, sizeof b.max);
}

ag_box ag_cloud_box(const ag_cloud *c)
{
    ag_box b = ag_box_empty();
    for (size_t i = 0; i < c->n; i++)
        ag_box_extend_point(&b, c->xyz + 3 * i);
    return b;
}

double ag_cloud_diagonal(const ag_cloud *c)
{
    if (c->n < 2)
        return 0;
    double min[3], max[3];
    ag_cloud_bounds(c, min, max);
    double dx = max[0] - min[0], dy = max[1] - min[1], dz = max[2] - min[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

void ag_cloud_rebase(ag_cloud *c, const double offset[3])
{
    double d[3] = {c->offset[0] - offset[0], c->offset[1] - offset[1], c->offset[2] - offset[2]};
    if (d[0] != 0 || d[1] != 0 || d[2] != 0)
        for (size_t i = 0; i < c->n; i++)
            for (int a = 0; a < 3; a++)
                c->xyz[3 * i + a] += d[a];
    memcpy(c->offset, offset, sizeof c->offset);
}

void ag_cloud_choose_origin(const double min[3], const double max[3], double origin[3])
{
    for (int a = 0; a < 3; a++) {
        double lo = min[a], hi = max[a];
        origin[a] = isfinite(lo) && isfinite(hi) && (fabs(lo) > 1e4 || fabs(hi) > 1e4)
                        ? floor(lo)
                        : 0;
    }
}

ag_status ag_cloud_check_finite(const ag_cloud *c, ag_error *err)
{
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "point %zu has a coordinate that is not a finite number", i + 1);
    }
    return AG_OK;
}
