/* Wavefront OBJ ↔ ag_mesh.
 *
 * Reading: `v x y z [w | r g b]` (extras ignored), `f` (polygons fan-triangulated from
 * their first vertex; v, v/vt, v//vn, v/vt/vn; negative indices relative to the vertices
 * defined so far), `g` and `o` start a group, `usemtl`, `mtllib` (materials
 * are not read: the library is never opened, whoever the caller), `vt`, `vn`, `s`, `l`, `p`, `#` comments, CRLF, blank lines, trailing blanks and `\` line continuations are
 * accepted; other statement keywords are ignored.
 *
 * Groups and components: one component per group, in the order of the groups' first faces.
 * Of consecutive g/o lines with no face between them the last wins; a group that never
 * gets a face does not exist; a group named again later continues the same group (and
 * component); a bare `g` is the group "default"; the name is the rest of the line.
 * Faces before any g/o form a group-less component (group -1). A file with no group at
 * all, or whose only group holds every face (a lone `o`, which segments nothing), gets one
 * component per connected piece (ag_mesh_split_connected), keeping that group. In files with
 * several groups, a group made of loose pieces stays one component: the proceduralization
 * stage decides.
 *
 * Degenerate faces: a triangle of the fan that repeats a vertex index is dropped silently;
 * geometrically flat (zero-area) triangles are kept for later stages to judge.
 *
 * Errors: malformed input — a zero, unparsable or out-of-range index (including one
 * that refers to a vertex defined further down: OBJ requires definition first), a
 * NaN/inf/unparsable coordinate, a truncated `v` line, a face with fewer than three
 * vertices, counts past max_vertices/max_triangles, a NUL byte or other binary data —
 * fails with AG_ERR_PARSE, the 1-based line in err->element and err->text like
 * "line 12: face index 57 out of range (file has 40 vertices so far)". A file without
 * any triangle fails with AG_ERR_EMPTY. On failure *out is NULL.
 *
 * Axes: the mesh is always z-up; a y-up file (the default) maps (x, y, z) → (x, -z, y). */
#ifndef AG_OBJ_H
#define AG_OBJ_H

#include <stddef.h>

#include "../core/mesh.h"
#include "../core/status.h"

typedef enum {
    AG_UP_DEFAULT = 0, /* OBJ's convention: y up */
    AG_UP_Y = 1,
    AG_UP_Z = 2,
} ag_up_axis;

typedef struct {
    ag_up_axis up;          /* the file's up axis; the mesh comes out z-up */
    size_t max_vertices;    /* 0 = 100 million */
    size_t max_triangles;   /* 0 = 200 million */
    /* Called now and then with the fraction read; return non-zero to cancel
     * (the reader then returns AG_ERR_CANCELLED). May be NULL. */
    int (*progress)(void *user, double fraction);
    void *user;
    /* Files of at least this many bytes are read in two parts at once when the program has
     * threads (core/base/parallel.h): the later half beside the first, merged after it, or
     * read again after it in turn when only that can tell (an error in it, an index it
     * cannot resolve alone), so the mesh and every message are a read in turn's.
     * 0 = 1 MiB. */
    size_t split_bytes;
} ag_obj_read_options;

ag_status ag_obj_read_buffer(const char *data, size_t len, const ag_obj_read_options *opt,
                             ag_mesh **out, ag_error *err);
ag_status ag_obj_read_file(const char *path, const ag_obj_read_options *opt, ag_mesh **out,
                           ag_error *err);

/* Writes z-up geometry back in the given up axis (AG_UP_DEFAULT = y): every vertex (the
 * shortest decimal that reads back to the same double, io/numtext.h: reading it back is
 * exact), then per component a `g` line named after its
 * group (or `component_<i>`) and its triangles, 1-based. A mesh without groups is written
 * without g lines, and a group-less component 0 before the first g line, so that reading
 * the file back reproduces the components; components sharing one group merge. */
ag_status ag_obj_write_file(const ag_mesh *m, ag_up_axis up, const char *path, ag_error *err);

#endif
