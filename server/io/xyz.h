/* XYZ / TXT point clouds: one point per line, `x y z [nx ny nz] [r g b]`.
 *
 * Values are separated by spaces, tabs, commas or semicolons; blank lines and lines
 * starting with # or // are skipped. Every point line has the same number of values: 3,
 * 6 or 9. Six values are normals when every triple has unit length (within 10 %), else
 * colour. Colour is kept as uchar red/green/blue when every value is an integer 0-255,
 * else as float. Large coordinates are moved to a local origin like every reader's. */
#ifndef AG_XYZ_H
#define AG_XYZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "../core/points/cloud.h"
#include "../core/status.h"

ag_status ag_xyz_read_buffer(const uint8_t *data, size_t len, ag_cloud **out, ag_error *err);

/* Writes absolute x y z, then nx ny nz when there are normals, then red green blue when
 * the cloud has them. */
ag_status ag_xyz_write(const ag_cloud *c, FILE *f, ag_error *err);

#endif
