/* PLY meshes come through assimp, which holds positions as 32-bit floats: a mesh in RD New
 * or UTM coordinates (hundreds of kilometres, often stored as double in the file) would lose
 * everything below a few centimetres, and a building's windows would no longer be copies of
 * each other. This puts the file's own values back: the vertex element read by the PLY
 * reader (doubles), used only when it is the same vertex list assimp produced (same count,
 * each position the float rounding of the file's). */
#ifndef AG_PLY_MESH_POSITIONS_H
#define AG_PLY_MESH_POSITIONS_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"

/* Replaces m's positions by data's (a PLY file assimp read into m without any axis change)
 * when the vertex lists agree; returns 1 when it did, 0 when m keeps assimp's positions. */
int ag_ply_mesh_restore_positions(ag_mesh *m, const uint8_t *data, size_t len);

#endif
