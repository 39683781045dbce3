/* Segmentation of a mesh into components (the units that get labels).
 *
 * - A group/object is one component, except that a group holding loose parts is split into
 *   its connected pieces: always when it is the file's only group, otherwise when it has at
 *   least `split_min_pieces` pieces and pieces with an identical twin (same triangle count and
 *   box) carry at least half of its triangles (loose columns, tiles).
 * - Without groups, connected pieces are the components.
 * - A mesh that is one connected piece falls back to planar region growing.
 * Connectivity is by vertex position (welded within a tolerance), not by index, so files
 * that repeat vertices per polygon still connect. Triangle order is kept. */
#ifndef AG_SEGMENT_H
#define AG_SEGMENT_H

#include <stddef.h>

#include "../mesh.h"
#include "../status.h"

typedef struct {
    double weld;             /* relative to the model diagonal; 0 = 1e-9 */
    double planar_degrees;   /* normal tolerance of region growing; 0 = 1 degree */
    size_t split_min_pieces; /* 0 = 4 */
    int keep_groups;         /* non-zero: never split a group */
} ag_segment_options;

typedef struct {
    size_t groups_split;   /* groups replaced by their connected pieces */
    int planar_fallback;   /* the single piece was split into planar regions */
    size_t components;
} ag_segment_info;

/* Checks indices, finite coordinates and component numbers; AG_ERR_INVALID with the 1-based
 * triangle/vertex in err->element, AG_ERR_EMPTY for a mesh without triangles. */
ag_status ag_segment_validate(const ag_mesh *m, ag_error *err);

/* *out is a new mesh with the same vertices and triangles (same order) and new components. */
ag_status ag_segment_run(const ag_mesh *in, const ag_segment_options *opt, ag_mesh **out,
                         ag_segment_info *info, ag_error *err);

#endif
