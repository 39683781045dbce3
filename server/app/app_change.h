/* What the REST and live layers change: ops (every kind of the op table, app/optable.h),
 * deletions, grammar text edits and live drag previews, on the calling thread's connection. */
#ifndef AG_APP_CHANGE_H
#define AG_APP_CHANGE_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "optable.h"

/* A client's op (app/modelops.h): *version the new version, or with *duplicate the version
 * the same (author, cid) got before; AG_ERR_STALE with the current version in err->element. */
ag_status ag_app_change_op(ag_app *app, const ag_op_request *rq, int64_t *version,
                           int *duplicate, ag_error *err);
/* Deletes the model at version (AG_ERR_STALE otherwise) and announces its end. */
ag_status ag_app_change_delete(ag_app *app, int64_t model, int64_t version, ag_error *err);
/* PUT …/grammar (app/grammar_edit.h), under budget (may be NULL). */
ag_status ag_app_change_grammar(ag_app *app, int64_t model, int64_t base, const char *author,
                                const char *cid, const char *text, size_t len,
                                ag_task_budget *budget, int64_t *version, ag_error *err,
                                long *col);
/* Largest grammar text a PUT takes. */
size_t ag_app_change_grammar_max(void);
/* A live drag (app/edit_ops.h): the moved boxes, nothing stored. */
ag_status ag_app_change_preview(ag_app *app, int64_t model, int64_t base, const json_t *op,
                                json_t **boxes, double *solve_ms, ag_error *err);

#endif
