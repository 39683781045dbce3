/* The architectural shell an extrusion produces: planar polygonal faces (possibly with
 * holes) over shared vertices, linked as half-edges so that closure and 2-manifoldness
 * can be checked, each face tagged with the plan edge and profile segment that made it.
 *
 * It is built from directed boundary segments: the sweep adds, for every face, the
 * pieces of its boundary in any order (counter-clockwise seen from outside), then
 * ag_shell_finish() welds coincident vertices, cancels zero-width slits and links
 * the pieces into loops and half-edges. */
#ifndef AG_EXTRUDE_SHELL_H
#define AG_EXTRUDE_SHELL_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"

typedef enum {
    AG_SHELL_FACE_SIDE = 0, /* swept by a plan edge along a profile segment */
    AG_SHELL_FACE_FLOOR = 1,
    AG_SHELL_FACE_CAP = 2,  /* flat top where the sweep was stopped */
} ag_shell_face_kind;

typedef struct {
    ag_shell_face_kind kind;
    int32_t loop, edge;     /* input plan loop and edge (-1 for floor/cap) */
    int32_t profile;        /* profile index, -1 for floor/cap */
    int32_t segment;        /* profile segment index (0-based), -1 for floor/cap */
    /* filled by ag_shell_finish: */
    uint32_t first_loop, nloops;
} ag_shell_face;

typedef struct {
    size_t nverts;
    double *pos; /* 3 * nverts */
    size_t nfaces;
    ag_shell_face *faces;
    /* loops: loop i holds idx[loop_start[i] .. loop_start[i+1]) */
    size_t nloops;
    uint32_t *loop_start;
    uint32_t *idx;
    /* half-edges (one per loop corner, same order as idx): he_next within the loop,
     * he_twin the opposite half-edge or UINT32_MAX, he_face the face */
    size_t nhalf;
    uint32_t *he_twin, *he_next, *he_face;
    size_t open_segments; /* boundary pieces that could not be linked into a loop */
    /* heights with two horizontal faces or more (see flats.h), how many of them were
     * rebuilt from their winding and how many were left as they were */
    size_t flat_levels, flat_rebuilt, flat_left;

    /* private build state */
    size_t cap_verts, cap_faces, nsegs, cap_segs;
    uint32_t *segs; /* 3 per segment: face, from, to */
} ag_shell;

ag_shell *ag_shell_create(void);
void ag_shell_free(ag_shell *s);
ag_status ag_shell_add_vertex(ag_shell *s, double x, double y, double z, uint32_t *id);
ag_status ag_shell_add_face(ag_shell *s, const ag_shell_face *f, uint32_t *id);
ag_status ag_shell_add_segment(ag_shell *s, uint32_t face, uint32_t from, uint32_t to);
/* Welds vertices closer than weld_tol, links segments into loops and half-edges. */
ag_status ag_shell_finish(ag_shell *s, double weld_tol);

typedef struct {
    int32_t face; /* -1 when the problem is not tied to one face */
    char reason[112];
} ag_shell_problem;

/* Checks that every half-edge has exactly one opposite half-edge (closed, edge-manifold),
 * that every face boundary closed into loops and that every face is planar (within
 * 1e-6 of its size). Writes up to max problems (one per
 * failing face) and returns how many faces fail in total: 0 = watertight 2-manifold. */
size_t ag_shell_check(const ag_shell *s, ag_shell_problem *out, size_t max);

/* Triangulates every face (ear clipping, holes bridged) into m as triangles of
 * `component`; vertices are appended. *ntris gets the number of triangles added.
 * Faces without area are skipped. */
ag_status ag_shell_to_mesh(const ag_shell *s, ag_mesh *m, uint32_t component, size_t *ntris);

/* Signed volume enclosed (positive for an outward-facing closed shell). */
double ag_shell_volume(const ag_shell *s);

#endif
