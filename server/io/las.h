/* ASPRS LAS point clouds, versions 1.0-1.4, point data formats 0-10 (LAZ through laz.h).
 *
 * Integer coordinates are scaled and offset into absolute coordinates and then moved to
 * the cloud's local origin (ag_cloud_choose_origin); the LAS scale is kept as the cloud's
 * `scale`. Every field of the point format becomes a property named after the
 * specification: intensity, return_number, number_of_returns, scan_direction_flag,
 * edge_of_flight_line, classification, synthetic, key_point, withheld, overlap (6-10),
 * scanner_channel (6-10), scan_angle_rank (0-5, degrees) or scan_angle (6-10, 0.006
 * degree units), user_data, point_source_id, gps_time, red, green, blue, nir,
 * wavepacket_index, wavepacket_offset, wavepacket_size, wavepacket_location, wavepacket_xt,
 * wavepacket_yt, wavepacket_zt. Extra bytes described by the LASF_Spec extra-bytes record
 * become properties of their own type (extra bytes nx, ny, nz become normals); undescribed
 * extra bytes are skipped. Other VLRs and EVLRs are skipped. The header's point count and
 * record length are checked against the file size before anything is allocated (for LAZ: at
 * most one point per byte of file). */
#ifndef AG_LAS_H
#define AG_LAS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "../core/points/cloud.h"
#include "../core/status.h"

typedef struct {
    uint8_t version_major, version_minor;
    uint16_t header_size;
    uint32_t point_offset;   /* byte where the point records start */
    uint32_t nvlrs;
    uint8_t point_format;    /* 0-10, compression bits removed */
    int compressed;          /* LAZ: bit 7 or 6 of the point format byte */
    uint16_t record_length;
    uint64_t count;          /* points: the 64-bit count of LAS 1.4 when set, else legacy */
    double scale[3], offset[3], min[3], max[3];
} ag_las_header;

/* Bytes of a point record of format f (0-10) without extra bytes; 0 for others. */
size_t ag_las_record_size(int format);

/* Parses and checks the public header block. */
ag_status ag_las_read_header(const uint8_t *data, size_t len, ag_las_header *h, ag_error *err);

/* LAS, or LAZ (decoded by laz.c), into a cloud. */
ag_status ag_las_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err);

typedef struct {
    int point_format;  /* 0-10; -1 picks the smallest format that holds the cloud's fields */
    double scale[3];   /* 0: the cloud's scale where known, else 0.001 (millimetres) */
} ag_las_write_options;

/* Writes LAS 1.2 (formats 0-5) or 1.4 (6-10) with the cloud's offset as LAS offset. Fields
 * of the format come from the properties of the same name (0 when absent; 8-bit colour is
 * widened to 16 bits); every other property, and normals as nx ny nz, go into described
 * extra bytes. AG_ERR_INVALID when a coordinate does not fit the 32-bit integers at the
 * scale. */
ag_status ag_las_write(const ag_cloud *c, const ag_las_write_options *opt, FILE *f, ag_error *err);
ag_status ag_las_write_file(const ag_cloud *c, const ag_las_write_options *opt, const char *path,
                            ag_error *err);

/* ---- shared with laz.c --------------------------------------------------------------- */

/* Receives point record `index` (record_length bytes, LAS layout). */
typedef void (*ag__las_record_fn)(void *user, size_t index, const uint8_t *record);

typedef struct {
    const uint8_t *data; /* the VLR's payload */
    size_t len;
} ag__las_vlr;

#endif
