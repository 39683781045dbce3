/* Rebasing a live op made on an older version onto the model's current one, when nothing
 * that came since conflicts with it (schema/websocket.md, "Ops made on an older version").
 * Each kind says how it rebases in the op table (app/optable.h, ag_op_rebase):
 *
 *   AG_REBASE_NEVER         stale unless made on the current version
 *   AG_REBASE_ALWAYS        names no version's content (undo, redo: resolved against the log
 *                           when applied)
 *   AG_REBASE_UNLESS_SAME   everything but a later op of its own kind (a rename after a
 *                           rename, a note after a note: the sender sees the other first)
 *   AG_REBASE_OVER_CONTENT  ops that leave the geometry alone (rename, note), nothing else
 *   AG_REBASE_NODES         structural edits: ops that leave the geometry alone, and
 *                           geometry ops after which every node the op names is still there,
 *                           unchanged: each is found in the tree after each later geometry op
 *                           by its id (edits keep the ids of the nodes they leave alone), else
 *                           by its kind and box (within 1e-6 of the model's size), and the op
 *                           is rewritten with the ids it has now; a node an edit removed is a
 *                           conflict naming it removed
 *
 * A true conflict is AG_ERR_STALE naming the op that conflicts (its kind, version and author)
 * with the current version in err->element, like a plain stale op. */
#ifndef AG_REBASE_H
#define AG_REBASE_H

#include <jansson.h>
#include <stdint.h>

#include "optable.h"
#include "store_env.h"

/* rq was made on rq->base; the model is at `current` (> rq->base). On success *onto is
 * current and *op the op to apply there: NULL when rq->op applies unchanged, else a new
 * reference with the node ids rewritten (the caller decrefs it). */
ag_status ag_rebase_op(const ag_store_env *env, const ag_op_request *rq, const ag_op_kind *row,
                       int64_t current, int64_t *onto, json_t **op, ag_error *err);

/* For tests: the id at tree b of node id of tree a (served trees, app/model_tree.h), or -1
 * when it is not there unchanged (or is not found alone). */
int64_t ag_rebase_map_node(const json_t *tree_a, const json_t *tree_b, int64_t id);

#endif
