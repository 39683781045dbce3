#include "usecase_save_part.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "../core/parts/select.h"
#include "model_tree.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* The node a selection saves: the one node, or the common ancestor of several. */
static ag_status saved_node(const ag_edit_model *em, const ag_usecase_save_part_params *p,
                            int32_t *node, ag_error *err)
{
    if (p->nnodes < 1 || p->nnodes > AG_USECASE_SAVE_PART_MAX_NODES)
        return ag_error_set(err, AG_ERR_INVALID, 0, "nodes: a selection of 1 to %d nodes",
                            AG_USECASE_SAVE_PART_MAX_NODES);
    ag_status s = AG_OK;
    for (size_t i = 0; s == AG_OK && i < p->nnodes; i++) {
        char field[48];
        if (p->nnodes == 1)
            snprintf(field, sizeof field, "node");
        else
            snprintf(field, sizeof field, "nodes[%zu]", i);
        s = ag_model_tree_check_node(em, p->nodes[i], field, err);
    }
    if (s != AG_OK)
        return s;
    if (p->nnodes == 1) {
        *node = p->nodes[0];
        return AG_OK;
    }
    return ag_select_common_tree(em->proc->tree, p->nodes, p->nnodes, node, err);
}

ag_status ag_usecase_save_part_run(ag_workspace *ws, const ag_usecase_save_part_params *p,
                                   ag_usecase_save_part_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_status s = ag_part_check_meta(p->meta, err);
    if (s != AG_OK)
        return s;
    double t0 = now_ms();
    ag_edit_model *em = NULL;
    const ag_edit_model *source = NULL;
    int64_t source_version = 0;
    if ((s = ag_workspace_open_models(ws, NULL, &em, &source, &source_version, err)) != AG_OK)
        return s;
    out->load_ms = now_ms() - t0;
    t0 = now_ms();
    int32_t node = -1;
    if ((s = saved_node(em, p, &node, err)) != AG_OK)
        return s;
    ag_part *part = NULL;
    const ag_trace *trace = NULL;
    if ((s = ag_workspace_model_trace(ws, &trace, err)) != AG_OK ||
        (s = ag_part_extract_traced(em->proc, trace, node, p->meta, &part, err)) != AG_OK)
        return s;
    out->save_ms = now_ms() - t0;
    out->node = node;
    out->nodes = part->nnodes;
    for (size_t i = 0; i < part->nnodes; i++)
        out->visible += part->nodes[i].kind == AG_NODE_COMPONENT;
    out->rules = part->grammar->nrules;
    out->terminals = part->grammar->nterminals;
    for (int a = 0; a < 3; a++)
        out->size[a] = part->box.max[a] - part->box.min[a];
    ag_part_outcome o = {.node = node, .load_ms = out->load_ms, .save_ms = out->save_ms};
    return ag_workspace_save_part(ws, part, &o, err);
}
