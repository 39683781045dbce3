/* A point cloud: n points with positions relative to a local origin, optional normals and
 * named per-point scalar properties kept in the type they were read with.
 *
 * Geo-referenced input (RD New, UTM) has coordinates of hundreds of kilometres; `offset`
 * holds the local origin so the positions stay small (absolute = xyz + offset) and float
 * output loses nothing. Writers put the offset back. Properties are whatever the input
 * had (intensity, classification, colour, return number, segment_index, ...) and travel
 * through the pipeline unchanged unless a stage owns them (`segment`, `label`).
 * Core: no I/O. */
#ifndef AG_CLOUD_H
#define AG_CLOUD_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"

typedef enum {
    AG_SCALAR_INT8,
    AG_SCALAR_UINT8,
    AG_SCALAR_INT16,
    AG_SCALAR_UINT16,
    AG_SCALAR_INT32,
    AG_SCALAR_UINT32,
    AG_SCALAR_INT64,
    AG_SCALAR_UINT64,
    AG_SCALAR_FLOAT32,
    AG_SCALAR_FLOAT64,
    AG_SCALAR_COUNT
} ag_scalar_type;

/* Bytes of one value. */
size_t ag_scalar_size(ag_scalar_type t);
/* "int8", "uint16", "float32", ... */
const char *ag_scalar_name(ag_scalar_type t);
int ag_scalar_is_float(ag_scalar_type t);

#define AG_CLOUD_NAME_MAX 64        /* bytes of a property name, with the terminating NUL */
#define AG_CLOUD_MAX_PROPERTIES 128 /* a file with more is refused with a precise error */

typedef struct {
    char name[AG_CLOUD_NAME_MAX];
    ag_scalar_type type;
    void *values; /* n values of `type` */
} ag_cloud_property;

typedef struct {
    size_t n;
    double *xyz;       /* 3n local coordinates; absolute = xyz + offset */
    double offset[3];  /* the local origin in the input's coordinate system */
    double scale[3];   /* coordinate resolution of the source (LAS scale), 0 = unknown */
    float *normals;    /* 3n unit normals, or NULL */
    size_t nprops;
    ag_cloud_property props[AG_CLOUD_MAX_PROPERTIES];
    size_t cap;        /* allocated points, private to cloud.c */
} ag_cloud;

ag_cloud *ag_cloud_create(void);
void ag_cloud_free(ag_cloud *c);

/* Sets the point count; new points (and their normals and property values) are zero.
 * Fails with AG_ERR_TOO_LARGE when the byte count would overflow, AG_ERR_NOMEM. */
ag_status ag_cloud_resize(ag_cloud *c, size_t n, ag_error *err);
/* Makes room for n points without changing c->n. */
ag_status ag_cloud_reserve(ag_cloud *c, size_t n, ag_error *err);

/* Allocates zeroed normals when there are none. */
ag_status ag_cloud_add_normals(ag_cloud *c, ag_error *err);

/* Adds a zero-filled property. AG_ERR_INVALID for a bad or duplicate name,
 * AG_ERR_TOO_LARGE past AG_CLOUD_MAX_PROPERTIES. *index (optional) receives its index;
 * c->props[index] stays where it is until the property is removed. */
ag_status ag_cloud_add_property(ag_cloud *c, const char *name, ag_scalar_type type,
                                size_t *index, ag_error *err);
/* The property called name, or NULL. */
ag_cloud_property *ag_cloud_find(const ag_cloud *c, const char *name);
/* Removes a property (no-op when absent); later properties move down by one. */
void ag_cloud_remove_property(ag_cloud *c, const char *name);

/* One value as a double / set from a double (rounded and clamped for integer types). */
double ag_cloud_get(const ag_cloud_property *p, size_t i);
void ag_cloud_set(ag_cloud_property *p, size_t i, double v);

/* A new cloud of the points idx[0..k) in that order, with every property, the normals, the
 * offset and the scale. */
ag_status ag_cloud_subset(const ag_cloud *c, const uint32_t *idx, size_t k, ag_cloud **out,
                          ag_error *err);

/* A deep copy (every property, the normals, the offset and the scale). */
ag_status ag_cloud_clone(const ag_cloud *c, ag_cloud **out, ag_error *err);

/* Local-coordinate bounds; an empty cloud gives min = +inf, max = -inf. */
void ag_cloud_bounds(const ag_cloud *c, double min[3], double max[3]);
/* The same as a box (the empty box for no points). */
ag_box ag_cloud_box(const ag_cloud *c);
/* Length of the bounds' diagonal (0 for fewer than two distinct points). */
double ag_cloud_diagonal(const ag_cloud *c);

/* Moves the local origin to `offset` (positions change, absolute coordinates do not). */
void ag_cloud_rebase(ag_cloud *c, const double offset[3]);
/* The local origin archgram uses for absolute bounds [min, max]: per axis 0 when the axis
 * stays within +-10 km (model coordinates are kept as they are), else min rounded down to
 * whole metres. */
void ag_cloud_choose_origin(const double min[3], const double max[3], double origin[3]);

/* AG_ERR_PARSE naming the first point (1-based, in the text) whose position is not finite. */
ag_status ag_cloud_check_finite(const ag_cloud *c, ag_error *err);

#endif
