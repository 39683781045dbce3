/* Ops on a model: validated by their row of the op table (app/optable.h), sequenced (one
 * version per op, app/sequencer.h), logged and announced. The same path serves websocket ops,
 * REST PATCH and POST …/ops. */
#ifndef AG_MODELOPS_H
#define AG_MODELOPS_H

#include <jansson.h>
#include <stdint.h>

#include "optable.h"
#include "store_env.h"

/* Checks the shape of an op a client sends: its kind's validator; kinds the server makes
 * itself ("proceduralize", "grammar") are refused with a message naming the REST call that
 * makes them. */
ag_status ag_modelops_validate(const json_t *op, ag_error *err);

/* Applies a client's op if rq->base is the model's version — or, for a live op
 * (rq->rebase), onto the current version when nothing since its base conflicts with it
 * (app/rebase.h): *version gets the new version. A (author, cid) pair seen before on this
 * model is not applied again: *duplicate = 1 and *version is the version it got then.
 * AG_ERR_STALE carries the current version in err->element (and names the conflicting op
 * when a live op could not be rebased). */
ag_status ag_modelops_apply(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
                            int *duplicate, ag_error *err);

/* For the op validators: AG_ERR_INVALID naming the first member of op that is not in allowed
 * (NULL-terminated). */
ag_status ag_modelops_only_members(const json_t *op, const char *const *allowed, ag_error *err);

/* Checks a client-supplied identifier (cid, author): 1..100 printable ASCII characters. */
ag_status ag_modelops_check_token(const char *what, const char *value, ag_error *err);

/* The rows of rename and note (app/optable.c). */
ag_status ag__modelops_rename_validate(const json_t *op, ag_error *err);
ag_status ag__modelops_rename_effect(ag_db *db, int64_t model, const json_t *op, ag_error *err);
ag_status ag__modelops_note_validate(const json_t *op, ag_error *err);

#endif
