/* Edits of a point model (§5): the structural edits of core/edit (edit.h) run on the model's
 * proxy, and their output read back as placements (pointmodel.h).
 *
 * - resize: the attachment equations and their sparse least squares (core/edit/resize*), with
 *   the point-cloud split ratio 1.5 (AG_POINTS_SPLIT_RATIO: a node stretched past it, or a
 *   pattern's cells, double; squeezed under its inverse, they join), the node's density kept
 *   when it is derived (stretch compensation, resample.h) and the seams between placements that
 *   now overlap thinned;
 * - paste (insert or replace x fill or derive, also from another point model: its terminals
 *   come along), the copied node turned by quarter turns to face the way the paste node faces;
 * - split, remove; join keeps its placements (a joined node is a union of placements).
 * An op names nodes of the model's tree (pm->em->proc->tree), as ops on meshes do. The result
 * is a new model, built (its nodes numbered afresh: ag_pointedit_keep_ids gives the state
 * read back from it the ids of every node the op did not remove, moved or resized ones too); a
 * caller that keeps only the grammar reads it back through its grammar text
 * (app/points_state.h) so that its node ids are the ones a reload gives. */
#ifndef AG_POINTEDIT_H
#define AG_POINTEDIT_H

#include "../edit/edit.h"
#include "../status.h"
#include "pointmodel.h"

/* Applies op to pm (unchanged); source: a paste's source model (NULL: pm itself). rep (may be
 * NULL) gets the solve figures and the placements per terminal of the new model ("L<n>"). */
ag_status ag_pointedit_apply(const ag_pointmodel *pm, const ag_edit_op *op,
                             const ag_pointmodel *source, ag_pointmodel **out,
                             ag_edit_report *rep, ag_error *err);

/* made (built) numbered as `before` numbers the nodes made keeps (core/edit/idmatch.h): the
 * build numbers every node afresh. op (may be NULL; in before's coordinates, as
 * ag_pointedit_apply was given it, with the paste's source model `source`, NULL: before): the
 * edit that made it. A node op did not remove keeps its id, also when op moved or resized it:
 * made's nodes are matched against the tree op makes of before's on the tree (core/edit/edit.h:
 * kept nodes at their ids with their new boxes, a resize's rule-mates moved with its node,
 * copies appended, removed nodes dead), each new node of made given an id after all of those.
 * Only the proxy's tree is renumbered: made's grammar is the matched one then, so take the
 * grammar text from made before. */
ag_status ag_pointedit_keep_ids(ag_pointmodel *made, const ag_pointmodel *before,
                                const ag_edit_op *op, const ag_pointmodel *source,
                                ag_error *err);

/* The model ag_pointedit_keep_ids numbers lists its components in the order of their ids, not
 * of pm's placements, so a tree kept from it (app/model_kept.h) does not fit the proxy a
 * reload of pm's grammar builds. kept: an edit model read from such a tree over that proxy;
 * pm's placements are put in kept's component order (placement k the one whose box, terminal
 * and turn kept's component k has) and *mesh is the proxy in that order, over which the tree
 * reads as it was kept. AG_ERR_PARSE when a component of kept has no placement of pm. */
ag_status ag_pointedit_kept_order(ag_pointmodel *pm, const ag_edit_model *kept, ag_mesh **mesh,
                                  ag_error *err);

/* pm, whose edit model was made from a kept tree over its proxy (app/model_kept.h), with the
 * proxy's groups named after its labels ("L<label + 1>") as the model ag_pointedit_keep_ids
 * made and kept names them: the next edit matches nodes by those names. */
ag_status ag_pointedit_name_groups(ag_pointmodel *pm, ag_error *err);

/* A deep copy of a model's terminals and placements (not built). */
ag_status ag_pointedit_copy(const ag_pointmodel *pm, ag_pointmodel **out, ag_error *err);

#endif
