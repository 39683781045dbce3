/* What rebuilds a model's edit model exactly, kept beside its mesh in the stored tree.
 *
 * An edit keeps the ids of the nodes it did not remove (core/edit/rebuild.h): its tree is not
 * the one proceduralizing its mesh again would give. So the store keeps, with the mesh, the
 * edit model's split tree (every node with its links, box, pivot and classes; patterns;
 * rules) and the classes labeling gave each component, and a reload makes the edit model from
 * those (ag_rebuild_finish) instead of proceduralizing the mesh: the numbering, the labels and
 * the rules survive the store round trip, undo, redo and restore.
 *
 * The stored tree text (app/model_tree.h, numbering AG_MODEL_TREE_NUMBERING) is the served
 * tree with one more member, "kept": {"format":4,"tol","eps","ncomponents","nnodes",
 * "npatterns","nrules","nlabels","nvariants","diagonal","label_tol","exact","share",
 * "exact_copies","data"}, data the
 * base64 of little-endian int32s and doubles: per node its kind, parent, first child, last
 * child, next sibling, component, label, variant, rot, octant, rule rot, rule and pattern,
 * then its box (min, max) and pivot, except that a run of dead nodes (which keep only their
 * ids, never reused) is written as the dead kind and the run's length; per pattern its rule, rot, lattice size, counts, step,
 * vectors and node; per rule its count and representative; per component its label,
 * variant, rot, variant rot, mirror flag and turn (radians); per variant its label and
 * deviation. Format 3, which wrote dead nodes whole, is still read. Binary, because the tree is written
 * with every edit: numbers exactly, a 200k-triangle building's in milliseconds. A kept member
 * that does not describe a tree over the mesh is refused (AG_ERR_PARSE naming what is wrong),
 * never trusted.
 *
 * An edit's or a composition's version is stored bare: {"kept":{...}} alone, without the
 * served tree. Printing the served tree is most of writing a large model's tree, and it is
 * asked for far less often than edits are made (and shared by every client when it is), so
 * the service makes it from the edit model when it is first asked for (app/edit_session.h,
 * ag_edit_session_served) and a rebase reads the boxes it compares from the kept member
 * (ag_model_kept_tree). ag_model_kept_serves tells the two kinds of stored text apart. */
#ifndef AG_MODEL_KEPT_H
#define AG_MODEL_KEPT_H

#include <jansson.h>

#include "../core/edit/edit.h"

/* The stored tree text of em (malloc'd): the served tree with the kept member; NULL when out
 * of memory. */
char *ag_model_kept_tree_text(const ag_edit_model *em);

/* The bare stored tree text of em (malloc'd): its kept member alone; NULL when out of
 * memory. */
char *ag_model_kept_bare_text(const ag_edit_model *em);

/* Whether a stored tree text holds the served tree (else it is bare: the kept member alone). */
int ag_model_kept_serves(const char *tree_text);

/* served (a served tree's text, an object: a point model's is in the input's coordinates)
 * with em's kept member added (malloc'd); NULL when out of memory. */
char *ag_model_kept_join(const char *served, const ag_edit_model *em);

/* The served tree of a stored tree text (malloc'd): the text without its kept member (all of
 * it when it keeps none); NULL when out of memory. */
char *ag_model_kept_served_text(const char *tree_text);

/* The edit model of a kept mesh from the kept member of its stored tree (tree_text):
 * AG_ERR_NOT_FOUND when the text has no kept member (a tree stored before it), AG_ERR_PARSE
 * when it is not one over this mesh. */
ag_status ag_model_kept_reload(const ag_mesh *mesh, const char *tree_text, ag_edit_model **em,
                               ag_error *err);

/* The split tree a stored tree text keeps (malloc'd; checked as a reload checks it, without a
 * mesh to fit): AG_ERR_NOT_FOUND when it keeps none, AG_ERR_PARSE when it is not valid. */
ag_status ag_model_kept_tree(const char *tree_text, ag_splittree **tree, ag_error *err);

#endif
