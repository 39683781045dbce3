/* Wavefront OBJ ↔ ag_mesh.
 *
 * Reading: `v`, `f` (polygons fan-triangulated; v, v/vt, v//vn, v/vt/vn; negative
 * indices relative), `g` and `o` start a group (one component per group), `usemtl`,
 * `mtllib`, `vt`, `vn`, `s`, `l`, `p` and comments are accepted. Malformed input — a bad or
 * out-of-range index, NaN/inf coordinates, a truncated line, a face with fewer than three
 * vertices, counts past the limits — fails with AG_ERR_PARSE and the 1-based line in
 * err->element and a message naming the problem. A file with no triangle fails with
 * AG_ERR_EMPTY. Files without groups get one component per connected piece. */
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
} ag_obj_read_options;

ag_status ag_obj_read_buffer(const char *data, size_t len, const ag_obj_read_options *opt,
                             ag_mesh **out, ag_error *err);
ag_status ag_obj_read_file(const char *path, const ag_obj_read_options *opt, ag_mesh **out,
                           ag_error *err);

/* Writes z-up geometry back in the given up axis (AG_UP_DEFAULT = y), one `g` per
 * component named after its group (or `component_<i>`). */
ag_status ag_obj_write_file(const ag_mesh *m, ag_up_axis up, const char *path, ag_error *err);

#endif
