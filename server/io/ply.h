/* PLY point clouds: the vertex element of ASCII, binary little-endian and binary
 * big-endian files, every scalar property kept in its own type.
 *
 * x, y, z become positions (any numeric type); nx, ny, nz (or normal_x, normal_y,
 * normal_z) become normals; every other scalar property is kept by name. List properties
 * of the vertex element and all other elements (faces, edges, ...) are skipped. A header
 * line `comment offset X Y Z` says the positions are relative to (X, Y, Z): it becomes the
 * cloud's offset, and the writer puts it there again. Without it, large coordinates are
 * moved to a local origin (ag_cloud_choose_origin).
 *
 * Every count is checked against the bytes that follow before anything is allocated, so a
 * header that lies gives a precise error and memory stays proportional to the input. */
#ifndef AG_PLY_H
#define AG_PLY_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "../core/points/cloud.h"
#include "../core/status.h"

ag_status ag_ply_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err);

/* Checks that data begins with a header this reader accepts (magic, format, elements,
 * properties, end_header alone on its line) whose elements' rows fit the bytes after it,
 * refusing it with AG_ERR_PARSE naming the line or element otherwise. A mesh read through
 * assimp is checked first: assimp 5.2 loops without end on a header it should refuse, and
 * spends seconds and gigabytes on a count of rows that the data cannot hold. */
ag_status ag_ply_check_header(const uint8_t *data, size_t len, ag_error *err);

/* ag_ply_check_header, then every row of every element read (none stored): the data must
 * hold every row the header declares, and each face (a `face` element's `vertex_indices` or
 * `vertex_index` list) must have corners, each a vertex of the file (one or two corners are
 * a point or a line, which the mesh reader drops). A mesh read through assimp is checked so
 * first: assimp aborts on a face of no corners and makes faces up from a file cut short.
 * AG_ERR_PARSE names the line (ASCII) or the face. */
ag_status ag_ply_check_mesh(const uint8_t *data, size_t len, ag_error *err);

/* Whether data is a PLY whose header declares a face element with at least one face (a
 * mesh rather than a point cloud). */
int ag_ply_has_faces(const uint8_t *data, size_t len);

/* The point count a PLY's header declares (its vertex element): 0 with *count, -1 when the
 * header does not parse or has no vertex element. */
int ag_ply_vertex_count(const uint8_t *data, size_t len, uint64_t *count);

typedef enum {
    AG_PLY_BINARY_LE = 0, /* the default */
    AG_PLY_BINARY_BE,
    AG_PLY_ASCII,
} ag_ply_encoding;

typedef struct {
    ag_ply_encoding encoding;
    /* Positions as absolute double x y z (offset added back) instead of float local
     * positions with a `comment offset X Y Z` header line. */
    int double_xyz;
} ag_ply_write_options;

/* Writes x y z, normals when present, then every property (int64/uint64 values as double:
 * PLY has no 64-bit integers). */
ag_status ag_ply_write(const ag_cloud *c, const ag_ply_write_options *opt, FILE *f, ag_error *err);
ag_status ag_ply_write_file(const ag_cloud *c, const ag_ply_write_options *opt, const char *path,
                            ag_error *err);

#endif
