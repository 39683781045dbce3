#include "usecase_points.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/clock.h"
#include "../core/points/pointedit.h"
#include "model_tree.h"
#include "points_state.h"

/* Where each stage starts on the 0..1 progress scale; verify from 0.85. */
static const double stage_start[AG_PCLOUD_STAGES] = {0.02, 0.45, 0.55, 0.6, 0.75, 0.8};

static int on_stage(void *user, ag_pcloud_stage stage, double fraction)
{
    double next = stage + 1 < AG_PCLOUD_STAGES ? stage_start[stage + 1] : 0.85;
    return ag_workspace_progress(user, stage_start[stage] + fraction * (next - stage_start[stage]),
                                 ag_proceduralize_cloud_stage_name(stage));
}

ag_status ag_usecase_points_proceduralize_run(ag_workspace *ws,
                                              const ag_usecase_points_proceduralize_params *p,
                                              ag_usecase_points_proceduralize_result *out,
                                              ag_error *err)
{
    memset(out, 0, sizeof *out);
    double t_all = ag_clock_seconds();
    ag_cloud *cloud = NULL, *derived = NULL;
    ag_proceduralize_cloud_result *r = NULL;
    ag_points_state st = {0};
    /* the cloud with every property (the terminals keep them); a segmentation the workspace
     * has is not used: the pipeline segments with its repetition stages together */
    ag_cloud_state cs;
    ag_status s = ag_workspace_input_cloud(ws, 1, 0, &cs, err);
    cloud = cs.cloud;
    cs.cloud = NULL;
    ag_cloud_state_clear(&cs);
    if (s != AG_OK) {
        ag_cloud_free(cloud);
        return s;
    }
    ag_proceduralize_cloud_options o = p ? p->options : (ag_proceduralize_cloud_options){0};
    o.progress = on_stage;
    o.user = ws;
    ag_box *boxes = NULL;
    if (p && p->boxes_in_input && (o.ntemplates || o.nrois)) {
        /* the boxes in the cloud's local frame */
        if (!(boxes = malloc((o.ntemplates + o.nrois) * sizeof *boxes))) {
            ag_cloud_free(cloud);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        for (size_t k = 0; k < o.ntemplates + o.nrois; k++) {
            boxes[k] = k < o.ntemplates ? o.templates[k] : o.rois[k - o.ntemplates];
            for (int a = 0; a < 3; a++) {
                boxes[k].min[a] -= cloud->offset[a];
                boxes[k].max[a] -= cloud->offset[a];
            }
        }
        o.templates = o.ntemplates ? boxes : NULL;
        o.rois = o.nrois ? boxes + o.ntemplates : NULL;
    }
    out->points = cloud->n;
    if ((s = ag_proceduralize_cloud_run(cloud, &o, &r, err)) != AG_OK)
        goto done;
    if (ag_workspace_progress(ws, 0.85, "verify")) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    /* the state read back from its text and terminals, derived and compared with the input */
    double t0 = ag_clock_seconds();
    ag_points_outcome oc = {.input = cloud, .proc = r};
    if ((s = ag_points_state_make(r->model, &st, err)) != AG_OK ||
        (s = ag_pointmodel_derive(st.pm, 0, &derived, NULL, err)) != AG_OK ||
        (s = ag_pointmodel_compare(cloud, derived, 2 * r->model->spacing, &oc.fidelity, err)) !=
            AG_OK)
        goto done;
    oc.derived_points = derived->n;
    oc.verify_s = ag_clock_seconds() - t0;
    if (ag_workspace_progress(ws, 0.95, "verify")) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    const ag_segment_cloud_result *sg = r->seg;
    out->segments = ag_segment_cloud_in_use(sg);
    out->planes = sg->nplanes;
    out->clusters = sg->nclusters;
    out->elements = sg->nelements;
    out->labels = sg->nlabels;
    out->terminals = st.pm->nterminals;
    out->placements = st.pm->nplacements;
    out->rules = st.pm->em->proc->grammar->nrules;
    out->patterns = st.pm->em->proc->tree->npatterns;
    out->derived_points = derived->n;
    out->grammar_bytes = st.text_len;
    out->terminal_bytes = st.terms.bytes;
    out->fidelity = oc.fidelity;
    oc.total_s = ag_clock_seconds() - t_all - oc.verify_s;
    s = ag_workspace_save_points(ws, &st, &oc, NULL, err);
    out->total_s = ag_clock_seconds() - t_all - oc.verify_s;
done:
    ag_points_state_clear(&st);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(cloud);
    ag_cloud_free(derived);
    free(boxes);
    return s;
}

/* The op's node ids: the target is the edited model's, a paste's selection the source's. */
static ag_status check_nodes(const ag_edit_op *op, const ag_pointmodel *pm,
                             const ag_pointmodel *source, ag_error *err)
{
    ag_status s = AG_OK;
    int paste = op->kind == AG_EDIT_PASTE;
    if (op->kind != AG_EDIT_JOIN && op->kind != AG_EDIT_REMOVE)
        s = ag_model_tree_check_node(pm->em, op->node, paste ? "target" : "node", err);
    for (size_t i = 0; s == AG_OK && i < op->nnodes; i++) {
        char field[64];
        snprintf(field, sizeof field, "%s[%zu]", paste ? "source" : "nodes", i);
        s = ag_model_tree_check_node(paste && source ? source->em : pm->em, op->nodes[i], field,
                                     err);
    }
    return s;
}

ag_edit_op ag_usecase_points_local_op(const ag_pointmodel *pm, const ag_edit_op *in)
{
    ag_edit_op op = *in;
    for (int a = 0; a < 3; a++) {
        op.box.min[a] -= pm->offset[a];
        op.box.max[a] -= pm->offset[a];
        op.region.min[a] -= pm->offset[a];
        op.region.max[a] -= pm->offset[a];
    }
    if (op.kind == AG_EDIT_SPLIT && op.axis >= 0 && op.axis < 3)
        op.at -= pm->offset[op.axis];
    return op;
}

ag_status ag_usecase_points_edit_run(ag_workspace *ws, const ag_usecase_points_edit_params *p,
                                     ag_usecase_points_edit_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    double t0 = ag_clock_ms();
    ag_pointmodel *pm = NULL, *made = NULL;
    const ag_pointmodel *source = NULL;
    ag_points_state st = {0};
    ag_status s = ag_workspace_open_point_models(ws, p->from, &pm, &source, err);
    if (s != AG_OK)
        return s;
    out->load_ms = ag_clock_ms() - t0;
    t0 = ag_clock_ms();
    if ((s = check_nodes(p->op, pm, source, err)) != AG_OK)
        return s;
    ag_edit_op op = ag_usecase_points_local_op(pm, p->op);
    if ((s = ag_pointedit_apply(pm, &op, source, &made, &out->report, err)) != AG_OK ||
        (s = ag_points_state_make(made, &st, err)) != AG_OK)
        goto done;
    out->placements = st.pm->nplacements;
    out->edit_ms = ag_clock_ms() - t0;
    ag_edit_outcome o = {.op = p->op,
                         .from = p->from,
                         .report = out->report,
                         .load_ms = out->load_ms,
                         .edit_ms = out->edit_ms};
    s = ag_workspace_save_points(ws, &st, NULL, &o, err);
done:
    ag_points_state_clear(&st);
    ag_pointmodel_free(made);
    if (s != AG_OK)
        ag_edit_report_clear(&out->report);
    return s;
}
