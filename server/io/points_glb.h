/* Binary glTF of a point cloud: one node with one mesh whose primitive draws POINTS (mode 0),
 * for viewers that show a budget of a cloud's points.
 *
 * POSITION is float32 relative to the centre of the points' bounds, the node's translation
 * is that centre (so geo-referenced clouds keep their precision), in glTF axes like every
 * GLB archgram writes (io/glb.h: x, z, -y of archgram's z-up model coordinates). COLOR_0,
 * when given, is RGBA of unsigned normalized bytes. Further per-point attributes are float32
 * SCALARs named by the caller (application-specific names start with "_", e.g. _SEGMENT,
 * _LABEL). The node's extras carry what the caller adds (the cloud's offset, how many points
 * it has, ...). No material: points are a viewer's to colour. No points: a valid GLB with an
 * empty scene. */
#ifndef AG_POINTS_GLB_H
#define AG_POINTS_GLB_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"

typedef struct {
    const char *name;    /* "_SEGMENT": "_" and capitals, as glTF asks */
    const float *values; /* n */
} ag_points_glb_attribute;

typedef struct {
    size_t n;
    const double *xyz;   /* 3n model coordinates, z up */
    const uint8_t *rgba; /* 4n, or NULL */
    const ag_points_glb_attribute *attributes;
    size_t nattributes;
    const json_t *extras; /* the node's extras (copied), or NULL */
} ag_points_glb;

/* *out is malloc'd. AG_ERR_TOO_LARGE past 4 GiB, AG_ERR_INVALID for an attribute name that
 * does not start with "_". */
ag_status ag_points_glb_write(const ag_points_glb *in, uint8_t **out, size_t *len,
                              ag_error *err);

#endif
