/* Structural edits of proceduralized models as ops (schema/edit_ops.md, schema/websocket.md),
 * per-person undo/redo and restoring old versions: the rows of these kinds in the op table
 * (app/optable.h).
 *
 *   resize, split, join, paste, remove   the edit use case (app/usecase_edit.h) on the store
 *       workspace (app/store_ws.h): node ids are the model's tree ids at the op's base; the
 *       new mesh, grammar, terminals and split tree are stored with the version the op gets,
 *       and the op is logged with the edit's report ({"report": {equations, unknowns,
 *       solve_ms, ...}})
 *   {"kind":"undo"} / {"kind":"redo"}    become the op logged and broadcast:
 *       {"kind":"restore","version":V,"undoes":K} — back to the state before the person's
 *       latest edit K that is not undone — and {"kind":"restore","version":K,"redoes":K};
 *       refused (AG_ERR_UNDO_CONFLICT) when another person's op that changes geometry came
 *       after K (after the undo, for a redo), naming that op
 *   {"kind":"restore","version":V}       anyone: the state of version V as a new version
 *
 * A model without a grammar describing its mesh refuses structural edits with
 * AG_ERR_NOT_PROCEDURALIZED ("model N is not proceduralized: ..."). States are kept around
 * every structural edit and restore (store/states.h). */
#ifndef AG_EDIT_OPS_H
#define AG_EDIT_OPS_H

#include <jansson.h>
#include <stdint.h>

#include "optable.h"
#include "store_env.h"

/* The op's shape, without a model: the five structural kinds; undo and redo (nothing but
 * "kind"); restore ("version" >= 1; clients may not send "undoes"/"redoes"). */
ag_status ag_edit_ops_validate(const json_t *op, ag_error *err);
ag_status ag_edit_ops_validate_history(const json_t *op, ag_error *err);
ag_status ag_edit_ops_validate_restore(const json_t *op, ag_error *err);

/* The whole op, as ag_modelops_apply (same duplicate, stale and version semantics). */
ag_status ag_edit_ops_run_edit(const ag_store_env *env, const ag_op_request *rq,
                               int64_t *version, int *duplicate, ag_error *err);
ag_status ag_edit_ops_run_restore(const ag_store_env *env, const ag_op_request *rq,
                                  int64_t *version, int *duplicate, ag_error *err);

/* A live drag: op is a resize made on version base; *boxes gets a new JSON array
 * [{"node": id, "box": [6]}] of the tree's nodes whose box the solve moves, *solve_ms the
 * solve's time. Nothing is stored. AG_ERR_STALE (current version in err->element) when base
 * is not the model's version. */
ag_status ag_edit_ops_preview(const ag_store_env *env, int64_t model, int64_t base,
                              const json_t *op, json_t **boxes, double *solve_ms, ag_error *err);

/* The nodes of tree t whose box the solve moved (solved: one box per node) as
 * [{"node","box"}], boxes moved by offset (a point model's local origin; zeros for a mesh); a
 * new reference, NULL when out of memory. */
json_t *ag__edit_ops_moved_boxes(const ag_splittree *t, const ag_box *solved,
                                 const double offset[3]);

#endif
