#include "usecase_compose.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/edit/idmatch.h"
#include "model_tree.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* The composed grammar (resolved, terminals with geometry) and the budget of what it may
 * derive. */
static ag_status compose_grammar(ag_workspace *ws, const ag_usecase_compose_params *p,
                                 ag_grammar **g, size_t *budget, ag_usecase_compose_result *out,
                                 const ag_edit_model **model, ag_error *err)
{
    memset(out, 0, sizeof *out);
    *g = NULL;
    if (p->op.mode < AG_COMPOSE_REPLACE || p->op.mode > AG_COMPOSE_FILL)
        return ag_error_set(err, AG_ERR_INVALID, 0, "mode: replace, insert or fill");
    if (p->op.scope != AG_COMPOSE_NODE && p->op.scope != AG_COMPOSE_RULE)
        return ag_error_set(err, AG_ERR_INVALID, 0, "scope: node or rule");
    double t0 = now_ms();
    ag_edit_model *em = NULL;
    const ag_edit_model *source = NULL;
    int64_t source_version = 0;
    ag_status s = ag_workspace_open_models(ws, NULL, &em, &source, &source_version, err);
    if (s == AG_OK)
        s = ag_model_tree_check_node(em, p->op.target, "target", err);
    const ag_part *part = NULL;
    if (s == AG_OK)
        s = ag_workspace_open_part(ws, p->part, &part, err);
    if (s != AG_OK)
        return s;
    out->load_ms = now_ms() - t0;
    out->part = part;
    if (model)
        *model = em;
    size_t own = 2 * em->proc->mesh->ntris;
    *budget = p->max_triangles                       ? p->max_triangles
              : own > AG_USECASE_COMPOSE_MAX_TRIANGLES ? own
                                                       : AG_USECASE_COMPOSE_MAX_TRIANGLES;
    t0 = now_ms();
    const ag_trace *trace = NULL;
    s = ag_workspace_model_trace(ws, &trace, err);
    if (s == AG_OK)
        s = ag_compose_traced(em->proc, trace, part, &p->op, g, &out->report, err);
    out->compose_ms = now_ms() - t0;
    return s;
}

/* A result past the budget, said as the composition's. */
static ag_status over_budget(ag_status s, size_t budget, ag_error *err)
{
    if (s == AG_ERR_TOO_LARGE)
        ag_error_set(err, s, 0,
                     "the composition makes more than %zu triangles (at most that in one op): "
                     "compose a larger part, or into a smaller target",
                     budget);
    return s;
}

typedef struct {
    const ag_edit_model *model;
    const ag_compose_op *op;
    ag_usecase_compose_result *out;
} graft_maker;

/* Per node of t: what the composition replaces (a replace's sites with their subtrees, what
 * lies below a fill's sites; an insert replaces nothing), which keeps no id. NULL when out of
 * memory. */
static uint8_t *composed_away(const ag_splittree *t, const ag_compose_op *op)
{
    uint8_t *site = calloc(t->nnodes + 1, 1), *away = calloc(t->nnodes + 1, 1);
    if (!site || !away) {
        free(site);
        free(away);
        return NULL;
    }
    int32_t rule = t->nodes[op->target].rule;
    for (size_t n = 0; n < t->nnodes; n++)
        site[n] = op->scope == AG_COMPOSE_RULE
                      ? t->nodes[n].kind == AG_NODE_COMPONENT && rule >= 0 &&
                            t->nodes[n].rule == rule
                      : n == (size_t)op->target;
    for (size_t n = 0; op->mode != AG_COMPOSE_INSERT && n < t->nnodes; n++) {
        if (t->nodes[n].kind == AG_NODE_DEAD)
            continue;
        /* below a site, or the site itself when it is replaced */
        int32_t x = op->mode == AG_COMPOSE_REPLACE ? (int32_t)n : t->nodes[n].parent;
        for (; x >= 0 && !away[n]; x = t->nodes[x].parent)
            away[n] = site[x];
    }
    free(site);
    return away;
}

/* The new state's edit model: the model's tree with the part grafted in; where the graft does
 * not apply, the derivation proceduralized and given the model's ids (core/edit/idmatch.h). */
static ag_status make_grafted(void *user, const ag_mesh *derived, ag_edit_model **em,
                              ag_error *err)
{
    graft_maker *gm = user;
    ag_proceduralize_result *r = NULL;
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_graft_compose(gm->model->proc, gm->op, derived, &gm->model->opt.patterns,
                                   &r, &gm->out->graft, &e);
    if (s == AG_OK) {
        if ((s = ag_edit_model_wrap(r, &gm->model->opt, em, err)) != AG_OK)
            ag_proceduralize_result_free(r);
        else
            gm->out->report.grafted = 1;
        return s;
    }
    if (s != AG_ERR_NOT_AVAILABLE) {
        if (err)
            *err = e;
        return s;
    }
    snprintf(gm->out->report.fallback, sizeof gm->out->report.fallback, "%.150s", e.text);
    ag_edit_model *fresh = NULL;
    if ((s = ag_model_state_reload(derived, &fresh, err)) != AG_OK)
        return s;
    const ag_splittree *t = gm->model->proc->tree;
    uint8_t *away = composed_away(t, gm->op);
    ag_idmatch_report ids = {0};
    s = away ? ag_idmatch_renumber(gm->model->proc, fresh->proc, away, &gm->model->opt.patterns,
                                   &r, &ids, err)
             : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    free(away);
    if (s == AG_OK && !r) { /* numbered as before */
        *em = fresh;
        fresh = NULL;
    } else if (s == AG_OK && (s = ag_edit_model_wrap(r, &gm->model->opt, em, err)) != AG_OK) {
        ag_proceduralize_result_free(r);
    }
    ag_edit_model_free(fresh);
    if (s == AG_OK)
        gm->out->graft = (ag_graft_report){.kept = ids.kept, .removed = ids.dead,
                                           .added = ids.appended};
    return s;
}

ag_status ag_usecase_compose_make(ag_workspace *ws, const ag_usecase_compose_params *p,
                                  ag_model_state *st, ag_usecase_compose_result *out,
                                  ag_error *err)
{
    memset(st, 0, sizeof *st);
    ag_grammar *g = NULL;
    size_t budget = 0;
    const ag_edit_model *em = NULL;
    ag_status s = compose_grammar(ws, p, &g, &budget, out, &em, err);
    if (s != AG_OK)
        return s;
    double t0 = now_ms();
    /* a workspace that keeps only the grammar reads it back proceduralized: its tree must be
     * numbered as that reload numbers it, so only one that keeps the tree takes the graft */
    int graft = !(ws->ops->state_flags & AG_MODEL_READ_BACK);
    graft_maker gm = {.model = em, .op = &p->op, .out = out};
    /* the maker takes the grammar's own derivation while its text is read back beside: the
     * state is checked (ag_model_state_checked) before it is kept */
    s = over_budget(ag_model_state_from_grammar_start(&g, budget, graft ? make_grafted : NULL,
                                                      &gm, st, err),
                    budget, err);
    ag_grammar_free(g);
    out->state_ms = now_ms() - t0;
    return s;
}

ag_status ag_usecase_compose_preview(ag_workspace *ws, const ag_usecase_compose_params *p,
                                     ag_mesh **mesh, ag_usecase_compose_result *out,
                                     ag_error *err)
{
    *mesh = NULL;
    ag_grammar *g = NULL;
    size_t budget = 0;
    ag_status s = compose_grammar(ws, p, &g, &budget, out, NULL, err);
    if (s != AG_OK)
        return s;
    double t0 = now_ms();
    ag_grammar_derive_options o = {.max_triangles = budget};
    s = over_budget(ag_grammar_derive(g, &o, mesh, err), budget, err);
    ag_grammar_free(g);
    out->state_ms = now_ms() - t0;
    return s;
}

ag_status ag_usecase_compose_run(ag_workspace *ws, const ag_usecase_compose_params *p,
                                 ag_usecase_compose_result *out, ag_error *err)
{
    ag_model_state st;
    ag_status s = ag_usecase_compose_make(ws, p, &st, out, err);
    if (s != AG_OK)
        return s;
    ag_compose_outcome o = {.op = &p->op,
                            .part = out->part,
                            .report = out->report,
                            .load_ms = out->load_ms,
                            .compose_ms = out->compose_ms,
                            .state_ms = out->state_ms,
                            .graft = out->graft};
    return ag_workspace_save_composed(ws, &st, &o, err);
}

json_t *ag_usecase_compose_report_json(const ag_compose_outcome *o)
{
    const ag_compose_report *r = &o->report;
    json_t *j = json_pack(
        "{s:{s:s,s:I,s:s},s:s,s:s,s:I,s:[I,I,I],s:i,s:[f,f,f],"
        "s:{s:I,s:I,s:I,s:I,s:I,s:I,s:I},s:{s:I,s:I,s:I,s:I},s:s}",
        "part", "name", o->part->name, "version", (json_int_t)o->part->version, "root",
        o->part->root, "root_rule", r->root, "target_rule", r->target_rule, "instances",
        (json_int_t)r->instances, "counts", (json_int_t)r->counts[0], (json_int_t)r->counts[1],
        (json_int_t)r->counts[2], "turn", 90 * r->turn, "fitted", r->fitted[0], r->fitted[1],
        r->fitted[2], "grammar", "rules_added", (json_int_t)r->rules_added, "rules_shared",
        (json_int_t)r->rules_shared, "terminals_added", (json_int_t)r->terminals_added,
        "terminals_shared", (json_int_t)r->terminals_shared, "renamed", (json_int_t)r->renamed,
        "cloned", (json_int_t)r->cloned, "expanded_cells", (json_int_t)r->expanded_cells, "fit",
        "elements", (json_int_t)r->fit.elements, "equations", (json_int_t)r->fit.equations,
        "rigid", (json_int_t)r->fit.rigid, "rigid_relaxed", (json_int_t)r->fit.rigid_relaxed,
        "message", r->message);
    /* how the new model was made: grafted, or (with the reason) proceduralized */
    if (j && (json_object_set_new(j, "state", json_string(r->grafted ? "grafted"
                                                                      : "proceduralized")) ||
              (r->fallback[0] && json_object_set_new(j, "fallback", json_string(r->fallback))))) {
        json_decref(j);
        j = NULL;
    }
    return j;
}
