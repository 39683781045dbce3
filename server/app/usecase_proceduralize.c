#include "usecase_proceduralize.h"

#include <string.h>
#include <time.h>

#include "../core/base/tolerance.h"

/* Where each stage starts on the 0..1 progress scale. */
static const double stage_start[AG_STAGE_COUNT] = {0.02, 0.2, 0.4, 0.5, 0.6, 0.7, 0.8};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int on_stage(void *user, ag_stage stage)
{
    return ag_workspace_progress(user, stage_start[stage], ag_proceduralize_stage_name(stage));
}

typedef struct {
    const ag_mesh *input;
    double tol;
    ag_fidelity *out;
} fidelity_check;

static ag_status check_fidelity(void *user, const ag_mesh *derived, ag_error *err)
{
    fidelity_check *c = user;
    return ag_grammar_fidelity(c->input, derived, c->tol, c->out, err);
}

ag_status ag_usecase_proceduralize_run(ag_workspace *ws, const ag_usecase_proceduralize_params *p,
                                       ag_usecase_proceduralize_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    double t_all = now();
    ag_mesh *mesh = NULL;
    ag_proceduralize_result *r = NULL;
    ag_edit_model *made = NULL;
    ag_model_state st = {0};
    ag_status s = ag_workspace_input_mesh(ws, &mesh, err);
    if (s != AG_OK)
        return s;
    if (p && p->max_triangles && mesh->ntris > p->max_triangles) {
        s = ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                         "the mesh has %zu triangles; this server proceduralizes at most %zu",
                         mesh->ntris, p->max_triangles);
        ag_mesh_free(mesh);
        return s;
    }
    ag_proceduralize_options po = {.progress = on_stage, .user = ws};
    if (p) {
        po.segment = p->segment;
        po.label = p->label;
    }
    if ((s = ag_proceduralize_run(mesh, &po, &r, err)) != AG_OK)
        goto done;
    ag_proc_outcome o = {.input = mesh, .proc = r};
    memcpy(o.seconds, r->seconds, sizeof o.seconds);
    if ((s = ag_edit_model_wrap(r, NULL, &made, err)) != AG_OK) {
        ag_proceduralize_result_free(r);
        goto done;
    }
    if (ag_workspace_progress(ws, stage_start[AG_STAGE_VERIFY],
                              ag_proceduralize_stage_name(AG_STAGE_VERIFY))) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    /* verify: the grammar printed, read back with its terminals as they will be kept,
     * derived, proceduralized anew (the saved tree) and, meanwhile, compared with the input */
    double t0 = now();
    fidelity_check fc = {.input = r->mesh, .tol = AG_PROC_VERIFY_FACTOR * r->labels->tol,
                         .out = &o.fidelity};
    if ((s = ag_model_state_make_beside(&made, AG_MODEL_READ_BACK, check_fidelity, &fc, &st,
                                        err)) != AG_OK)
        goto done;
    o.seconds[AG_STAGE_VERIFY] = now() - t0;
    if (o.fidelity.unmatched && !(p && p->save_unfaithful)) {
        s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                         "the grammar does not reproduce %zu of the %zu input triangles; the "
                         "model was left as it was",
                         o.fidelity.unmatched, o.fidelity.input_triangles);
        goto done;
    }
    if (ag_workspace_progress(ws, 0.95, ag_proceduralize_stage_name(AG_STAGE_VERIFY))) {
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    out->triangles = mesh->ntris;
    out->components = r->mesh->ncomponents;
    out->labels = r->labels->nlabels;
    out->variants = r->labels->nvariants;
    out->rules = r->grammar->nrules;
    out->patterns = r->tree->npatterns;
    out->terminals = r->grammar->nterminals;
    out->grammar_bytes = st.text_len;
    out->terminal_bytes = st.terms.bytes;
    out->fidelity = o.fidelity;
    out->label_tolerance = r->labels->tol;
    out->units = r->labels->units;
    o.total_s = now() - t_all - o.seconds[AG_STAGE_VERIFY];
    s = ag_workspace_save(ws, &st, &o, NULL, err);
    out->total_s = now() - t_all - o.seconds[AG_STAGE_VERIFY];
done:
    ag_model_state_clear(&st);
    ag_edit_model_free(made); /* frees r */
    ag_mesh_free(mesh);
    return s;
}
