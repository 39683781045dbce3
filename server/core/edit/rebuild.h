/* The proceduralization result of an edited split tree, without proceduralizing again.
 *
 * An edit that only moves, copies and removes what the model holds (a resize) knows its result
 * exactly: a tree in which every node that stays keeps its index (its id), copies are appended
 * and removed nodes are dead, each node naming the node of the input it copies (its source).
 * The result is made from that alone: every visible node places its source's component mapped
 * from the source's box to its own, in the order of the input's components (then the copies),
 * grouped by label name ("L<n>", as the grammar names them); components keep their source's
 * label, turn and variant (a terminal is placed scaled to its box, so a stretched copy is
 * still exactly its variant's terminal: labels survive an edit, as the paper's editing keeps
 * them as texture groups); the split chains are cut anew from the new boxes; rules are found
 * again (pattern-aware, rules.h), a pattern whose cells no longer repeat one rule on its grid is
 * dissolved into its cells and new repetitions become patterns (patterns.h); the grammar is
 * exported. Tolerances follow the model's size.
 *
 * ag_rebuild_finish makes a result from a mesh, the per-component classes and a complete tree
 * (rules included) as they were kept: what a store reloads. */
#ifndef AG_EDIT_REBUILD_H
#define AG_EDIT_REBUILD_H

#include <stdint.h>

#include "../proc/proceduralize.h"
#include "../status.h"

/* The edited tree t (taken) with per-node sources (taken, malloc'd, t->nnodes entries) over
 * input in, with patterns found by popt (NULL: defaults). When every node is its own source t
 * may be in->tree itself (a node's source is read before the node changes; in->tree is then
 * the result's, or freed). */
ag_status ag_rebuild(const ag_proceduralize_result *in, ag_splittree *t, int32_t *source,
                     const ag_patterns_options *popt, ag_proceduralize_result **out,
                     ag_error *err);

/* Only the mesh of the edited tree t (the components ag_rebuild would make; t's component
 * fields are not changed). */
ag_status ag_rebuild_mesh(const ag_proceduralize_result *in, const ag_splittree *t,
                          const int32_t *source, ag_mesh **out, ag_error *err);

/* The per-component classes of a kept model (what labeling found for it). */
typedef struct {
    size_t ncomponents, nlabels, nvariants;
    const int32_t *label, *variant; /* per component; -1 for a component without triangles */
    const uint8_t *rot, *vrot;      /* per component */
    const uint8_t *mirror;          /* per component (NULL: none mirrored) */
    const double *turn;             /* per component (NULL: 90 degrees times rot) */
    const int32_t *variant_label;   /* per variant */
    const double *variant_deviation; /* per variant (NULL: 0) */
    double diagonal, tol, exact, share; /* the labels' (absolute) tolerances */
    int exact_copies;
} ag_rebuild_classes;

/* A result from a kept model: mesh (taken) whose components the tree's visible nodes name
 * (tree taken: nodes, patterns, rules and rule counts as kept; its component map and adjacency
 * are made again), the classes copied. The grammar is exported again. */
ag_status ag_rebuild_finish(ag_mesh *mesh, ag_splittree *tree, const ag_rebuild_classes *classes,
                            ag_proceduralize_result **out, ag_error *err);

/* Numbers r's labels as its mesh's groups name them: a label whose components all lie in the
 * group "L<k>" becomes label k - 1 (a number claimed twice goes to the first label), the others
 * follow the largest number claimed, and the grammar is exported again with those names. An
 * edited or kept model's mesh names its labels so (grammar.h: terminals' label names);
 * proceduralizing it again numbers labels by first appearance instead, so a model's label
 * names would change under every edit. Unused numbers stay as labels without components. */
ag_status ag_rebuild_name_labels(ag_proceduralize_result *r, ag_error *err);

/* k for a mesh group named "L<k>" (k >= 1, a label's name), else 0 (for core/parts/graft). */
size_t ag__rebuild_label_number(const char *name);

#endif
