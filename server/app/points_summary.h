/* What a point model's saves describe, for both workspaces that keep point models (the
 * folder's summary.json and tree.json, app/points_folder_ws.h; the store's summary and tree
 * that GET …/tree serves, app/store_ws.h):
 *
 *   proceduralize   the input (file, bytes, points, offset, properties, normals), seconds per
 *                   stage, the segmentation's counts, the template matches, the completion per
 *                   consensus label, the saved model (tree, terminals, placements, rules,
 *                   patterns, bytes, spacing) and the fidelity of its derivation
 *   edit            the edit's report (equations, unknowns, instances per label, ...), the op,
 *                   load and edit milliseconds and the saved model
 *
 * Boxes are in the input's coordinates (the model keeps them local to its offset): those the
 * edit ops give. */
#ifndef AG_POINTS_SUMMARY_H
#define AG_POINTS_SUMMARY_H

#include <jansson.h>
#include <stddef.h>

#include "points_state.h"
#include "workspace.h"

/* Where the input came from: a file (path and size, the time reading it took) or, with file
 * NULL, the store's model. */
typedef struct {
    const char *file;
    size_t bytes;
    double read_s, write_s;
} ag_points_summary_input;

/* New references, NULL when out of memory. */
json_t *ag_points_summary_proc(const ag_points_state *st, const ag_points_outcome *o,
                               const ag_points_summary_input *in);
json_t *ag_points_summary_edit(const ag_points_state *st, const ag_edit_outcome *o);

/* The tree's node boxes moved by offset (a tree of app/model_tree.h, in place). */
void ag_points_summary_shift_tree(json_t *tree, const double offset[3]);

#endif
