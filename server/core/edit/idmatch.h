/* Ids for a model that was proceduralized again.
 *
 * Where a change cannot be made on the split tree (a composition the graft does not pair, a
 * grammar text edit) the new model is its derivation proceduralized, and that numbers every
 * node afresh. ag_idmatch_renumber gives such a model the ids of the model it replaces: walking
 * down from the root, a node of the new tree takes the id of the node of the old tree that has
 * the same kind, the same label name (its component's group, as the grammar names labels) and
 * the same box within the models' tolerances, under the old node its own holder (the nearest
 * visible ancestor, or the root) matched; an intermediate split node follows the chain end it
 * leads to. A node nothing matched so (nested now in a node the change made, a joined one)
 * then takes the old node of the same kind and label name on the same box anywhere, the
 * nearest. Each of those steps weighs all its candidates at once, the more alike first: the
 * same terminal (triangle count and where its triangles lie in the box: a window and its
 * mirror image on one box are told apart), the nearer box, the larger overlap, held by the
 * match of the new node's holder, then the old id; so boxes that coincide are assigned the
 * same way whatever order either tree lists them in. Under the holder only nodes of the same
 * terminal match (which of two coincident boxes holds the other depends on that order).
 * Old nodes marked `changed` (what the change removed or replaced) are never
 * matched. New nodes nothing matched are appended after every old id, old nodes
 * nothing matched are dead, so an id never names another node than it did. The renumbered
 * tree is rebuilt from the new model (rebuild.h): the same components, labels and geometry,
 * rules and patterns found again on the same boxes, labels named as the kept nodes' old labels
 * were where that is one name per variant. */
#ifndef AG_EDIT_IDMATCH_H
#define AG_EDIT_IDMATCH_H

#include <stddef.h>
#include <stdint.h>

#include "../proc/proceduralize.h"
#include "../status.h"

typedef struct {
    size_t kept;     /* visible nodes of the new model that took an old id */
    size_t appended; /* visible nodes of the new model with a new id */
    size_t dead;     /* visible nodes of the old model no new node matched */
} ag_idmatch_report;

/* fresh renumbered after old into *out (fresh is not changed); *out = NULL when fresh already
 * numbers every node as old does (a text re-derived as it was: fresh is the result, exactly).
 * changed: per old node, non-zero for nodes that may not be matched (NULL: none). rep may be
 * NULL. */
ag_status ag_idmatch_renumber(const ag_proceduralize_result *old,
                              const ag_proceduralize_result *fresh, const uint8_t *changed,
                              const ag_patterns_options *popt, ag_proceduralize_result **out,
                              ag_idmatch_report *rep, ag_error *err);

#endif
