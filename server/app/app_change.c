#include "app_change.h"

#include "auth.h"
#include "edit_ops.h"
#include "grammar_edit.h"
#include "modelops.h"
#include "store_env.h"

ag_status ag_app_change_op(ag_app *app, const ag_op_request *rq, int64_t *version,
                           int *duplicate, ag_error *err)
{
    *version = 0;
    *duplicate = 0;
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    return s != AG_OK ? s : ag_modelops_apply(&env, rq, version, duplicate, err);
}

ag_status ag_app_change_delete(ag_app *app, int64_t model, int64_t version, ag_error *err)
{
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    if (s == AG_OK && (s = ag_sequencer_delete(env.seq, env.db, model, version, err)) == AG_OK)
        ag_auth_forget(app); /* its id may come back for another model */
    return s;
}

ag_status ag_app_change_grammar(ag_app *app, int64_t model, int64_t base, const char *author,
                                const char *cid, const char *text, size_t len,
                                ag_task_budget *budget, int64_t *version, ag_error *err,
                                long *col)
{
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    return s != AG_OK ? s
                      : ag_grammar_edit_apply(&env, model, base, author, cid, text, len, budget,
                                              version, err, col);
}

size_t ag_app_change_grammar_max(void)
{
    return AG_GRAMMAR_TEXT_MAX;
}

ag_status ag_app_change_preview(ag_app *app, int64_t model, int64_t base, const json_t *op,
                                json_t **boxes, double *solve_ms, ag_error *err)
{
    *boxes = NULL;
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    return s != AG_OK ? s : ag_edit_ops_preview(&env, model, base, op, boxes, solve_ms, err);
}
