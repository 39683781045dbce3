/* The split tree of a model as JSON: the one numbering of its nodes.
 *
 * A node's id is its index in the split tree of the model's edit model (core/edit/edit.h:
 * the model's mesh proceduralized). The REST tree (GET /api/v1/models/{id}/tree), the CLI's
 * tree.json, the ids edit ops and previews name and the node each component of mesh.glb names
 * are all these indices, and a workspace keeps what it needs to rebuild the same edit model
 * (app/model_state.h), so the numbering survives a reload. Nodes that proceduralization
 * removed while it restructured the tree (cells moved under a pattern) keep their index: the
 * served tree lists them as {"id","kind":"dead"} and nothing more (after many edits most ids
 * are dead ones: listed whole they were most of the text), so nodes[i].id == i.
 *
 * A visible node's label is the group of its component in the model's mesh, which names
 * labels as the model's grammar does (app/model_state.h); rules are the edit model's grammar
 * rules (named as its grammar export names them).
 *
 * Served: {"root":0,"nodes":[{"id","parent","children","kind","box","visible","label","rule",
 * "terminal","component","pattern"}],"labels":[{"label","count","color"}],
 * "rules":[{"name","instances"}],"stats":{"nodes","visible","invisible","depth","components",
 * "patterns"}}, pattern = {"counts","step"} or {"counts","step":null,"vectors"}, and "rot"
 * when turned. The folder's tree.json (schema/edit_ops.md) is {"root":0,"nodes":[{"id",
 * "parent","kind","box","children", visible: "label","component","rule" (class index);
 * patterns: "counts"}],"stats":{...}} without the dead nodes. */
#ifndef AG_MODEL_TREE_H
#define AG_MODEL_TREE_H

#include <jansson.h>

#include "../core/edit/edit.h"
#include "../io/glb.h"

/* The numbering stored with a tree (store/grammars.h tree_numbering): trees stored with any
 * other value (read off the grammar's derivation, before this numbering) are rebuilt. */
#define AG_MODEL_TREE_NUMBERING 2

/* New references, NULL when out of memory. */
json_t *ag_model_tree_served(const ag_edit_model *em);
json_t *ag_model_tree_folder(const ag_edit_model *em);
/* The folder tree as json_dumps(ag_model_tree_folder(em), JSON_INDENT(1) |
 * JSON_REAL_PRECISION(15)) prints it, printed directly (fast on large trees); malloc'd, NULL
 * when out of memory. */
char *ag_model_tree_folder_text(const ag_edit_model *em);
/* The folder tree's "stats" alone. */
json_t *ag_model_tree_folder_stats(const ag_edit_model *em);

/* A node id an op names (field names it in the problem): AG_ERR_NOT_FOUND when it is not a
 * live node of em's tree. */
ag_status ag_model_tree_check_node(const ag_edit_model *em, int32_t id, const char *field,
                                   ag_error *err);

/* The served tree as compact text (malloc'd), or NULL when out of memory. */
char *ag_model_tree_served_text(const ag_edit_model *em);

/* Of t's nodes only what a served tree says of their kind and box: {"nodes":[{"id","kind",
 * "box"}]} (dead ones {"id","kind"}), numbered as the served tree; NULL when out of memory. */
json_t *ag_model_tree_boxes(const ag_splittree *t);

/* A stored tree (text) read for mesh.glb (ag_glb_write_meta): *meta has ncomponents entries
 * (label NULL / node -1 where the tree says nothing); the labels point into *labels, a
 * malloc'd block the caller frees after use. AG_ERR_PARSE for a tree that is not one. */
ag_status ag_model_tree_component_meta(const char *json, size_t ncomponents,
                                       ag_glb_component_meta **meta, char **labels,
                                       ag_error *err);

/* "#rrggbb" for a label name: "L<n>" spreads n over the hue circle, other names by a hash. */
void ag_model_tree_label_color(const char *label, char out[8]);

#endif
