/* The split tree of a grammar as JSON, as GET /api/v1/models/{id}/tree serves it.
 *
 * The tree is read off the grammar's derivation: the same walk, in the same order, as
 * ag_grammar_derive, so the n-th placed terminal is the n-th component of the derived mesh
 * and every visible node names its component. That makes the tree describe the derived mesh
 * exactly, whether the grammar came from a proceduralization or from an edit. Nodes:
 *   root       the axiom's box (node 0)
 *   split      a node made by split(...), a pattern cell, or a node a rule is applied to
 *   component  a placed terminal (visible), with its terminal, label and component index; a
 *              split node that gets a terminal becomes this node
 *   pattern    a subdivide/repeat application; its children are the cells
 * A rule applied to a node sets the node's "rule"; the rule's statements add its children.
 * Boxes are world coordinates (metres, z up) [minx, miny, minz, maxx, maxy, maxz].
 *
 * JSON: {"root":0,"nodes":[{"id","parent","children","kind","box","visible","label","rule",
 * "terminal","component","pattern"}],"labels":[{"label","count","color"}],
 * "rules":[{"name","instances"}],"stats":{"nodes","visible","invisible","depth","components",
 * "patterns"}}. Labels are the terminals' label names (or the terminal's name without one). */
#ifndef AG_SPLITTREE_JSON_H
#define AG_SPLITTREE_JSON_H

#include <stddef.h>
#include <stdint.h>

#include "../core/proc/grammar.h"
#include "../core/status.h"
#include "glb.h"

typedef struct {
    size_t max_nodes; /* 0 = 4 million; more is AG_ERR_TOO_LARGE */
} ag_splittree_json_options;

/* g must be resolved (ag_grammar_resolve, as the text parser does); geometry is not needed.
 * *json is malloc'd text; *ncomponents the number of placed terminals. */
ag_status ag_splittree_json_build(const ag_grammar *g, const ag_splittree_json_options *opt,
                                  char **json, size_t *ncomponents, ag_error *err);

/* The per-component label and node of a tree JSON text, for ag_glb_write_meta: *meta is a
 * malloc'd array of ncomponents entries (label NULL / node -1 where the tree says nothing);
 * the labels point into *labels, a malloc'd block the caller frees after use. */
ag_status ag_splittree_json_component_meta(const char *json, size_t ncomponents,
                                           ag_glb_component_meta **meta, char **labels,
                                           ag_error *err);

/* "#rrggbb" for a label name: "L<n>" spreads n over the hue circle, other names by a hash. */
void ag_splittree_json_label_color(const char *label, char out[8]);

#endif
