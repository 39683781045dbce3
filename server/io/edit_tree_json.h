/* The split tree of a model being edited as JSON, so that a person (or a pipeline) can pick
 * the node ids that edit ops name: {"root":0,"nodes":[{"id","parent","kind","box",
 * "children", and for visible nodes "label" ("L<n>", as the grammar's terminals),
 * "component", "rule"; for patterns "counts"}],"stats":{"nodes","visible","invisible",
 * "depth","patterns","rules"}}. Ids are indices into the tree; removed nodes are left out.
 * Boxes are world [minx, miny, minz, maxx, maxy, maxz]. */
#ifndef AG_EDIT_TREE_JSON_H
#define AG_EDIT_TREE_JSON_H

#include <jansson.h>

#include "../core/proc/proceduralize.h"

/* New reference, or NULL when out of memory. */
json_t *ag_edit_tree_json(const ag_proceduralize_result *r);
/* The "stats" object alone. */
json_t *ag_edit_tree_json_stats(const ag_proceduralize_result *r);

#endif
