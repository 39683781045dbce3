/* Binary glTF 2.0 (GLB) output of an ag_mesh.
 *
 * One node with one mesh/primitive per component, so a picked primitive maps back to a
 * component: node.name = "component <i>", node.extras = {"component": i, "group": name|null}.
 * glTF is y-up, archgram is z-up: positions are written as (x, z, -y). Flat normals are
 * emitted (vertices are split per triangle only where needed is not attempted: every
 * primitive gets its own vertex copy so components stay independent). */
#ifndef AG_GLB_H
#define AG_GLB_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/status.h"

/* *out is malloc'd; the caller frees it. */
ag_status ag_glb_write(const ag_mesh *m, uint8_t **out, size_t *len, ag_error *err);
ag_status ag_glb_write_file(const ag_mesh *m, const char *path, ag_error *err);

#endif
