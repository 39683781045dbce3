/* Structural edits of proceduralized models as ops (schema/edit_ops.md, schema/websocket.md),
 * and per-person undo/redo and restoring old versions:
 *
 *   resize, split, join, paste, remove   validated by io/edit_op_json.h, applied to the
 *       model's in-memory edit state (app/edit_session.h) off the op lock; the new mesh,
 *       grammar, terminals and split tree are stored with the version the op gets, and the op
 *       is logged with the edit's report ({"report": {equations, unknowns, solve_ms, ...}})
 *   {"kind":"undo"} / {"kind":"redo"}    become the op logged and broadcast:
 *       {"kind":"restore","version":V,"undoes":K} — back to the state before the person's
 *       latest edit K that is not undone — and {"kind":"restore","version":K,"redoes":K};
 *       refused (AG_ERR_CONFLICT, "undo-conflict: ...") when another person's op that changes
 *       geometry came after K (after the undo, for a redo), naming that op
 *   {"kind":"restore","version":V}       anyone: the state of version V as a new version
 *
 * A model without a grammar describing its mesh refuses structural edits with
 * AG_ERR_CONFLICT ("model N is not proceduralized: ..."). States are kept around every
 * structural edit and restore (store/states.h). */
#ifndef AG_EDIT_OPS_H
#define AG_EDIT_OPS_H

#include <jansson.h>
#include <stdint.h>

#include "../core/status.h"
#include "app.h"

/* Non-zero for resize, split, join, paste, remove, undo, redo and restore. */
int ag_edit_ops_handles(const char *kind);

/* The op's shape, without a model. Clients may not send "undoes"/"redoes". */
ag_status ag_edit_ops_validate(const json_t *op, ag_error *err);

/* The whole op, as ag_modelops_apply (same duplicate, stale and version semantics). */
ag_status ag_edit_ops_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                            const char *cid, const json_t *op, uint64_t origin, int64_t *version,
                            int *duplicate, ag_error *err);

/* A live drag: op is a resize made on version base; *boxes gets a new JSON array
 * [{"node": id, "box": [6]}] of the served tree's nodes whose box the solve moves, *solve_ms
 * the solve's time. Nothing is stored. AG_ERR_STALE (current version in err->element) when
 * base is not the model's version. */
ag_status ag_edit_ops_preview(ag_app *app, int64_t model, int64_t base, const json_t *op,
                              json_t **boxes, double *solve_ms, ag_error *err);

#endif
