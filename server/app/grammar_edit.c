#include "grammar_edit.h"

#include <jansson.h>
#include <stdlib.h>

#include "../core/edit/idmatch.h"
#include "../store/grammars.h"
#include "../store/states.h"
#include "cloud_pipeline.h"
#include "edit_session.h"
#include "store_ws.h"

/* The re-derived model given the ids of the model as it is (core/edit/idmatch.h): a node the
 * text left where it was, with its label, keeps its id. A model with no state to match (none
 * loads) keeps the numbering of its derivation. */
static ag_status keep_ids(const ag_store_env *env, int64_t model, ag_model_state *st,
                          ag_error *err)
{
    ag_edit_state *cur = NULL;
    ag_error e;
    ag_error_clear(&e);
    if (ag_edit_session_acquire(env->sessions, env->db, model, &cur, &e) != AG_OK)
        return AG_OK;
    ag_proceduralize_result *r = NULL;
    ag_edit_model *em = NULL;
    ag_status s = ag_idmatch_renumber(cur->em->proc, st->em->proc, NULL, &st->em->opt.patterns,
                                      &r, NULL, err);
    ag_edit_session_release(env->sessions, cur);
    if (s == AG_OK && !r) /* numbered as before */
        return AG_OK;
    if (s == AG_OK && (s = ag_edit_model_wrap(r, &st->em->opt, &em, err)) != AG_OK)
        ag_proceduralize_result_free(r);
    if (s == AG_OK) {
        ag_edit_model_free(st->em);
        st->em = em;
    }
    return s;
}

ag_status ag_grammar_edit_apply(const ag_store_env *env, int64_t model, int64_t base,
                                const char *author, const char *cid, const char *text,
                                size_t len, ag_task_budget *budget, int64_t *version,
                                ag_error *err, long *col)
{
    *version = 0;
    if (col)
        *col = 0;
    if (len > AG_GRAMMAR_TEXT_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "a grammar holds at most %zu bytes",
                            AG_GRAMMAR_TEXT_MAX);
    ag_grammar_row cur;
    ag_status s = ag_grammars_current(env->db, model, 0, &cur, err);
    if (s != AG_OK)
        return s;
    ag_grammars_row_clear(&cur);
    int cloud = 0; /* a point model's grammar names PLY terminals: app/store_ws_points.c */
    if ((s = ag_cloud_pipeline_is_cloud(env->db, model, &cloud, err)) != AG_OK)
        return s;
    if (cloud)
        return ag_store_ws_points_grammar_edit(env, model, base, author, cid, text, len, version,
                                               err, col);

    ag__store_ws_terminals ctx = {env->db, model};
    ag_model_state st;
    ag_work_limits limits = ag_work_limits_resolved(env->limits);
    ag_edit_budget eb = {.max_triangles = limits.max_triangles,
                         .max_components = limits.max_nodes,
                         .cancelled = budget ? ag_task_budget_exhausted : NULL,
                         .user = budget};
    if ((s = ag_model_state_from_text(text, len, ag__store_ws_terminal_lookup, &ctx, &eb, &st, err, col)) !=
        AG_OK)
        return ag_task_budget_explain(budget, s, "the grammar edit", err);
    if ((s = keep_ids(env, model, &st, err)) != AG_OK) {
        ag_model_state_clear(&st);
        return s;
    }
    const ag_grammar *g = st.em->proc->grammar;
    json_t *summary = json_pack(
        "{s:s, s:I, s:I, s:I, s:I, s:I, s:I}", "source", "edit", "rules", (json_int_t)g->nrules,
        "terminals", (json_int_t)g->nterminals, "grammar_bytes", (json_int_t)len, "triangles",
        (json_int_t)st.derived->ntris, "vertices", (json_int_t)st.derived->nverts, "components",
        (json_int_t)st.derived->ncomponents);
    char *summary_text = summary ? json_dumps(summary, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(summary);
    json_t *op = json_pack("{s:s, s:I}", "kind", "grammar", "bytes", (json_int_t)len);
    ag_seq_txn t;
    if (!summary_text || !op)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK && (s = ag_sequencer_begin(env->seq, env->db, model, base, NULL, NULL, &t, NULL,
                                              err)) == AG_OK) {
        /* the states before and after are kept: the author's undo restores the old text */
        s = ag_states_keep(t.db, model, t.version - 1, err);
        if (s == AG_OK)
            s = ag__store_ws_put_state(t.db, model, t.version, &st, summary_text, 1, err);
        int64_t v = t.version;
        if (s == AG_OK) {
            if ((s = ag_sequencer_commit(&t, author, cid, op, err)) == AG_OK) {
                *version = v;
                ag__store_ws_keep_model(env->sessions, model, v, &st);
            }
        } else {
            ag_sequencer_abort(&t);
        }
    }
    json_decref(op);
    free(summary_text);
    ag_model_state_clear(&st);
    return s;
}
