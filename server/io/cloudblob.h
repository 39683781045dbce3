/* The stored encoding of a point cloud's columns (the store keeps them in chunks of points,
 * store/pointclouds.h): positions in the smallest of three encodings that gives them back,
 * normals and properties in their own types, per-point ids (segment, label, piece) in the
 * smallest integer width that holds them. Every value is little-endian.
 *
 * Positions (local coordinates, absolute = position + the cloud's offset):
 *   i32   integers in units of the cloud's scale (LAS/LAZ input): chosen when every
 *         coordinate lies on its scale's grid (within a thousandth of a step, the rounding
 *         of the reader's double arithmetic) and the integers fit 32 bits; decoded as
 *         integer * scale, the grid point the file held
 *   f32   when every coordinate is exactly a float (float PLY input)
 *   f64   otherwise: the doubles as they are */
#ifndef AG_CLOUDBLOB_H
#define AG_CLOUDBLOB_H

#include <stddef.h>
#include <stdint.h>

#include "../core/points/cloud.h"
#include "../core/status.h"

typedef enum {
    AG_CLOUDBLOB_I32 = 1,
    AG_CLOUDBLOB_F32,
    AG_CLOUDBLOB_F64,
} ag_cloudblob_positions;

/* "i32", "f32", "f64"; from_name gives 0 for anything else. */
const char *ag_cloudblob_positions_name(ag_cloudblob_positions e);
ag_cloudblob_positions ag_cloudblob_positions_from_name(const char *name);
/* Bytes per point. */
size_t ag_cloudblob_positions_size(ag_cloudblob_positions e);

/* The smallest encoding that keeps c's positions (see above). */
ag_cloudblob_positions ag_cloudblob_positions_choose(const ag_cloud *c);

/* Points [start, start + count) of c: their positions in encoding e, their normals (c must
 * have them), the values of property p — each as malloc'd bytes. */
ag_status ag_cloudblob_encode_positions(const ag_cloud *c, ag_cloudblob_positions e,
                                        size_t start, size_t count, uint8_t **out, size_t *len,
                                        ag_error *err);
ag_status ag_cloudblob_encode_normals(const ag_cloud *c, size_t start, size_t count,
                                      uint8_t **out, size_t *len, ag_error *err);
ag_status ag_cloudblob_encode_property(const ag_cloud *c, size_t p, size_t start, size_t count,
                                       uint8_t **out, size_t *len, ag_error *err);

/* The reverse into c's arrays at point start (c already holds room for the points). The
 * byte count must be that of count points: AG_ERR_PARSE naming the column otherwise. */
ag_status ag_cloudblob_decode_positions(const uint8_t *data, size_t len,
                                        ag_cloudblob_positions e, ag_cloud *c, size_t start,
                                        size_t count, ag_error *err);
ag_status ag_cloudblob_decode_normals(const uint8_t *data, size_t len, ag_cloud *c, size_t start,
                                      size_t count, ag_error *err);
ag_status ag_cloudblob_decode_property(const uint8_t *data, size_t len, ag_cloud *c, size_t p,
                                       size_t start, size_t count, ag_error *err);

/* Per-point ids (>= -1): the width (1, 2 or 4 bytes) that holds ids up to max_id. */
unsigned ag_cloudblob_id_width(int64_t max_id);
ag_status ag_cloudblob_encode_ids(const int32_t *ids, size_t count, unsigned width,
                                  uint8_t **out, size_t *len, ag_error *err);
ag_status ag_cloudblob_decode_ids(const uint8_t *data, size_t len, unsigned width, int32_t *ids,
                                  size_t count, ag_error *err);

/* Point indices (uint32), e.g. a level-of-detail order. */
ag_status ag_cloudblob_encode_indices(const uint32_t *idx, size_t count, uint8_t **out,
                                      size_t *len, ag_error *err);
ag_status ag_cloudblob_decode_indices(const uint8_t *data, size_t len, uint32_t *idx,
                                      size_t count, ag_error *err);

#endif
