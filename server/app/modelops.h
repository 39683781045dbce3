/* Edits to a model as ops: validated, sequenced (one version per op), logged and published.
 * The same path serves websocket ops, REST PATCH and POST …/ops. */
#ifndef AG_MODELOPS_H
#define AG_MODELOPS_H

#include <jansson.h>
#include <stdint.h>

#include "app.h"

/* Checks an op's shape: {"kind": "rename", "name"} or {"kind": "note", "text"}; "plan" and
 * "profile" ops of extrusion models are checked by app/plan_edit.h, structural edits, "undo",
 * "redo" and "restore" by app/edit_ops.h (which also applies them). The kinds
 * the server makes itself ("proceduralize", "grammar") are refused with a message naming the
 * REST call that makes them. */
ag_status ag_modelops_validate(const json_t *op, ag_error *err);

/* Applies op to model if base is its current version: *version gets the new version.
 * A (author, cid) pair seen before on this model is not applied again: *duplicate = 1 and
 * *version is the version it got then. AG_ERR_STALE carries the current version in
 * err->element. origin is passed on to the published event (0 = none). */
ag_status ag_modelops_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                            const char *cid, const json_t *op, uint64_t origin,
                            int64_t *version, int *duplicate, ag_error *err);

/* Deletes a model at the given version (AG_ERR_STALE otherwise) and publishes its end. */
ag_status ag_modelops_delete(ag_app *app, int64_t model, int64_t version, ag_error *err);

/* For the op validators: AG_ERR_INVALID naming the first member of op that is not in allowed
 * (NULL-terminated). */
ag_status ag_modelops_only_members(const json_t *op, const char *const *allowed, ag_error *err);

/* Checks a client-supplied identifier (cid, author): 1..100 printable ASCII characters. */
ag_status ag_modelops_check_token(const char *what, const char *value, ag_error *err);

/* Server-made ops (a proceduralization, a grammar edit): changes the server computes, logged
 * and broadcast like any op. ag_modelops_server_begin takes the op lock, opens the
 * transaction and raises the version (AG_ERR_STALE with the current version in err->element
 * when base is not current, AG_ERR_NOT_FOUND without the model); the caller writes its
 * changes on t->db, then ag_modelops_server_commit logs the op, commits and publishes it, or
 * ag_modelops_server_abort rolls everything back. Both release the lock. */
typedef struct {
    ag_app *app; /* NULL when no server op is under way */
    ag_db *db;
    int64_t model;
    int64_t version; /* the version the change gets */
    uint64_t origin; /* the live session the op came from, set after begin (0 = none) */
} ag_modelops_txn;

ag_status ag_modelops_server_begin(ag_app *app, int64_t model, int64_t base, ag_modelops_txn *t,
                                   ag_error *err);
ag_status ag_modelops_server_commit(ag_modelops_txn *t, const char *author, const char *cid,
                                    const json_t *op, ag_error *err);
void ag_modelops_server_abort(ag_modelops_txn *t);

#endif
