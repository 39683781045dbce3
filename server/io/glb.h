/* Binary glTF 2.0 (GLB) output of an ag_mesh.
 *
 * One node with one mesh/primitive per component, so a picked primitive maps back to a
 * component: node.name = "component <i>", node.extras = {"component": i, "group": name|null}.
 * mesh.extras holds the same. glTF is y-up, archgram is z-up: positions are written as
 * (x, z, -y). Vertices are not shared: each triangle gets its own three vertices with its
 * flat normal, and no index buffer. Positions are stored relative to the centre of the
 * mesh bounds and every node's `translation` is that centre, so geo-referenced (UTM)
 * coordinates keep their precision in float32. Components without triangles get no node;
 * an empty mesh gives a valid GLB with an empty scene and no BIN chunk. One default
 * material (light grey, doubleSided). */
#ifndef AG_GLB_H
#define AG_GLB_H

#include <stddef.h>
#include <stdint.h>

#include <jansson.h>

#include "../core/mesh.h"
#include "../core/status.h"

/* *out is malloc'd; the caller frees it. */
ag_status ag_glb_write(const ag_mesh *m, uint8_t **out, size_t *len, ag_error *err);
/* Per-component additions to the extras, e.g. from a split tree: "label" when label is not
 * NULL, "node" when node >= 0. */
typedef struct {
    const char *label;
    int64_t node;
} ag_glb_component_meta;

/* Like ag_glb_write, with meta[c] added to component c's extras for c < nmeta (meta may be
 * NULL). */
ag_status ag_glb_write_meta(const ag_mesh *m, const ag_glb_component_meta *meta, size_t nmeta,
                            uint8_t **out, size_t *len, ag_error *err);
ag_status ag_glb_write_file(const ag_mesh *m, const char *path, ag_error *err);

/* The GLB container around a glTF document and its binary buffer (binlen may be 0: no BIN
 * chunk); *out is malloc'd. Shared by every GLB archgram writes (io/points_glb.h). */
ag_status ag_glb_frame(const json_t *root, const uint8_t *bin, size_t binlen, uint8_t **out,
                       size_t *len, ag_error *err);

/* z-up archgram → y-up glTF, a proper rotation (winding and handedness are kept): p as
 * (x, z, -y) minus centre (already in glTF axes). */
static inline void ag_glb_yup(const double *p, const double *centre, double *o)
{
    o[0] = p[0] - centre[0];
    o[1] = p[2] - centre[1];
    o[2] = -p[1] - centre[2];
}

#endif
