/* A compact, versioned binary encoding of ag_mesh for the store (little-endian:
 * magic "AGM1", counts, float64 positions, uint32 triangles and components, group names).
 * Decoding validates every count and index against the buffer, so a corrupt blob gives
 * AG_ERR_PARSE, never an out-of-bounds read. */
#ifndef AG_MESHBLOB_H
#define AG_MESHBLOB_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/status.h"

ag_status ag_meshblob_encode(const ag_mesh *m, uint8_t **out, size_t *len);
ag_status ag_meshblob_decode(const uint8_t *data, size_t len, ag_mesh **out, ag_error *err);

#endif
