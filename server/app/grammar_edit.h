/* PUT /api/v1/models/{id}/grammar: a grammar text re-derives the model. The text, with the
 * terminals the model keeps, is parsed, derived and proceduralized (app/model_state.h); the
 * model's mesh, the text, the split tree (app/model_tree.h) and a summary are stored as a new
 * model version in one transaction and the op {"kind":"grammar","bytes":N} is logged. The
 * states before and after are kept (store/states.h), so the grammar edit is one undo step of
 * its author like a structural edit. The terminals stay as they were: a grammar may use any
 * of the model's stored terminals (by their path) and no other. The same text gives the same
 * mesh and tree. */
#ifndef AG_GRAMMAR_EDIT_H
#define AG_GRAMMAR_EDIT_H

#include <stddef.h>
#include <stdint.h>

#include "model_state.h"
#include "store_env.h"
#include "task_budget.h"

/* AG_ERR_NOT_FOUND when the model does not exist or was never proceduralized, parse errors as
 * ag_model_state_from_text (line in err->element, column in *col), AG_ERR_STALE when base is
 * not the current version, AG_ERR_TOO_LARGE beyond AG_GRAMMAR_TEXT_MAX. *version gets the new
 * version. */
/* budget (may be NULL): the edit stops when it runs out (AG_ERR_DEADLINE, AG_ERR_CANCELLED);
 * a derivation past env's limits is AG_ERR_RESULT_TOO_LARGE. */
ag_status ag_grammar_edit_apply(const ag_store_env *env, int64_t model, int64_t base,
                                const char *author, const char *cid, const char *text,
                                size_t len, ag_task_budget *budget, int64_t *version,
                                ag_error *err, long *col);

#endif
