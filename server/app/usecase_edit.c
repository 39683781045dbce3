#include "usecase_edit.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "model_tree.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* The op's node ids: the target is the edited model's, the selection a paste copies is the
 * source's (the edited model's own when it copies from itself). */
static ag_status check_nodes(const ag_edit_op *op, const ag_edit_model *em,
                             const ag_edit_model *source, int64_t source_model, ag_error *err)
{
    ag_status s = AG_OK;
    int paste = op->kind == AG_EDIT_PASTE;
    if (op->kind != AG_EDIT_JOIN && op->kind != AG_EDIT_REMOVE)
        s = ag_model_tree_check_node(em, op->node, paste ? "target" : "node", err);
    for (size_t i = 0; s == AG_OK && i < op->nnodes; i++) {
        char field[64];
        if (paste && source_model)
            snprintf(field, sizeof field, "source[%zu] (of model %lld)", i, (long long)source_model);
        else
            snprintf(field, sizeof field, "%s[%zu]", paste ? "source" : "nodes", i);
        s = ag_model_tree_check_node(paste && source ? source : em, op->nodes[i], field, err);
    }
    return s;
}

ag_status ag_usecase_edit_run(ag_workspace *ws, const ag_usecase_edit_params *p,
                              ag_usecase_edit_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    double t0 = now_ms();
    ag_edit_model *em = NULL, *made = NULL;
    const ag_edit_model *source = NULL;
    int64_t source_version = 0;
    ag_edit_op op = *p->op;
    ag_model_state st = {0};
    ag_status s = ag_workspace_open_models(ws, p->from, &em, &source, &source_version, err);
    if (s != AG_OK)
        return s;
    out->load_ms = now_ms() - t0;
    t0 = now_ms();
    int64_t source_model = p->from && source ? p->from->model : 0;
    if ((s = check_nodes(&op, em, source, source_model, err)) != AG_OK)
        return s;
    op.source = source ? source->proc : NULL;
    if ((s = ag_edit_apply_ex(em, &op, 0, &made, &out->report, err)) != AG_OK ||
        (s = ag_model_state_start(&made, ws->ops->state_flags, &st, err)) != AG_OK)
        goto done;
    /* instances per label as the saved model names its labels */
    if ((s = ag_edit_report_count_labels(&out->report, st.em->proc->mesh, err)) != AG_OK)
        goto done;
    out->edit_ms = now_ms() - t0;
    ag_edit_outcome o = {.op = p->op,
                         .from = p->from,
                         .report = out->report,
                         .load_ms = out->load_ms,
                         .edit_ms = out->edit_ms,
                         .source_version = source_version};
    s = ag_workspace_save(ws, &st, NULL, &o, err);
done:
    ag_model_state_clear(&st);
    ag_edit_model_free(made);
    if (s != AG_OK)
        ag_edit_report_clear(&out->report);
    return s;
}
