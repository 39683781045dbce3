/* A triangle mesh split into components, the geometry every archgram stage passes on.
 *
 * Conventions: metres, z up, right-handed, counter-clockwise front faces.
 * Components are the pickable units (an input group/object, or a connected piece);
 * each triangle belongs to exactly one component and each component to at most one
 * input group. */
#ifndef AG_MESH_H
#define AG_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "base/box.h"
#include "status.h"

typedef struct {
    size_t nverts;
    double *pos;               /* 3 * nverts */

    size_t ntris;
    uint32_t *tri;             /* 3 * ntris vertex indices */
    uint32_t *tri_component;   /* ntris: component of each triangle */

    size_t ngroups;
    char **group_names;        /* input group/object names, file order */

    size_t ncomponents;
    int32_t *component_group;  /* ncomponents: index into group_names, or -1 */

    /* capacities, private to mesh.c */
    size_t cap_verts, cap_tris, cap_groups, cap_components;
} ag_mesh;

ag_mesh *ag_mesh_create(void);
void ag_mesh_free(ag_mesh *m);

/* Makes room for at least nverts vertices and ntris triangles (an optional speed-up). */
ag_status ag_mesh_reserve(ag_mesh *m, size_t nverts, size_t ntris);

/* Append; return AG_ERR_NOMEM on allocation failure. Indices are checked by the caller. */
ag_status ag_mesh_add_vertex(ag_mesh *m, double x, double y, double z);
ag_status ag_mesh_add_triangle(ag_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t component);
/* Returns the new group's index through *index. */
ag_status ag_mesh_add_group(ag_mesh *m, const char *name, size_t *index);
/* Returns the new component's index through *index; group is an index or -1. */
ag_status ag_mesh_add_component(ag_mesh *m, int32_t group, size_t *index);

/* Axis-aligned bounds of all vertices that some triangle uses; an empty mesh gives
 * min = +inf, max = -inf. */
ag_box ag_mesh_bounds(const ag_mesh *m);

/* Per-component triangle counts; counts must hold ncomponents entries. */
void ag_mesh_component_triangle_counts(const ag_mesh *m, size_t *counts);

/* Replace the components by the connected pieces (triangles sharing a vertex index) of
 * each current component, keeping each piece's group. Used when a file has no groups,
 * and to split a group that holds loose parts. */
ag_status ag_mesh_split_connected(ag_mesh *m);

/* Remove components without triangles and renumber the rest (order kept). */
void ag_mesh_compact_components(ag_mesh *m);

/* Deep copy. */
ag_mesh *ag_mesh_clone(const ag_mesh *m);

/* Which part of two meshes differs, compared byte for byte (counts, vertices, triangles,
 * components, group names): "" when they are the same. */
const char *ag_mesh_difference(const ag_mesh *a, const ag_mesh *b);

#endif
