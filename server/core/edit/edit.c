#include "edit.h"

#include <assert.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "rebuild.h"
#include "resize.h"
#include "treeedit.h"

struct ag_edit_cache {
    ag_edit_resize_solver *solver;
};

int ag_edit_budget_cancelled(const ag_edit_budget *b)
{
    return b && b->cancelled && b->cancelled(b->user);
}

/* The re-proceduralization's stage callback: the edit's budget. */
static int budget_stage(void *user, ag_stage stage)
{
    (void)stage;
    return ag_edit_budget_cancelled(user);
}

/* A result past the budget's limits is refused before it is proceduralized (an operation
 * without an estimate of its own, or one whose estimate was below and the result not). */
static ag_status check_result(const ag_edit_budget *b, const ag_mesh *mesh, ag_error *err)
{
    if (!b)
        return AG_OK;
    if (b->max_triangles && mesh->ntris > b->max_triangles)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "the edit would make %zu triangles; this server takes at most %zu",
                            mesh->ntris, b->max_triangles);
    if (b->max_components && mesh->ncomponents > b->max_components)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "the edit would place %zu terminals; this server takes at most %zu",
                            mesh->ncomponents, b->max_components);
    if (ag_edit_budget_cancelled(b))
        return ag_error_set(err, AG_ERR_CANCELLED, 0, "the edit was stopped");
    return AG_OK;
}

void ag_edit_op_clear(ag_edit_op *op)
{
    if (!op)
        return;
    free(op->nodes);
    memset(op, 0, sizeof *op);
}

ag_status ag_edit_op_copy(ag_edit_op *dst, const ag_edit_op *src, ag_error *err)
{
    *dst = *src;
    dst->nodes = NULL;
    if (src->nnodes) {
        dst->nodes = malloc(src->nnodes * sizeof *dst->nodes);
        if (!dst->nodes) {
            dst->nnodes = 0;
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        memcpy(dst->nodes, src->nodes, src->nnodes * sizeof *dst->nodes);
    }
    return AG_OK;
}

void ag_edit_report_clear(ag_edit_report *rep)
{
    if (!rep)
        return;
    for (size_t i = 0; i < rep->nlabels; i++)
        free(rep->labels[i].name);
    free(rep->labels);
    memset(rep, 0, sizeof *rep);
}

static void free_labels(ag_edit_report *rep)
{
    for (size_t i = 0; i < rep->nlabels; i++)
        free(rep->labels[i].name);
    free(rep->labels);
    rep->labels = NULL;
    rep->nlabels = 0;
}

ag_status ag_edit_report_count_labels(ag_edit_report *rep, const ag_mesh *m, ag_error *err)
{
    free_labels(rep);
    size_t *tris = calloc(m->ncomponents + 1, sizeof *tris);
    size_t *count = calloc(m->ngroups + 1, sizeof *count);
    if (!tris || !count)
        goto nomem;
    ag_mesh_component_triangle_counts(m, tris);
    for (size_t c = 0; c < m->ncomponents; c++)
        if (tris[c] && m->component_group[c] >= 0)
            count[m->component_group[c]]++;
    rep->labels = calloc(m->ngroups + 1, sizeof *rep->labels);
    if (!rep->labels)
        goto nomem;
    for (size_t g = 0; g < m->ngroups; g++) {
        if (!count[g])
            continue;
        ag_edit_label_count *l = &rep->labels[rep->nlabels];
        if (!(l->name = strdup(m->group_names[g])))
            goto nomem;
        l->count = count[g];
        rep->nlabels++;
    }
    free(tris);
    free(count);
    return AG_OK;
nomem:
    free(tris);
    free(count);
    free_labels(rep);
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

/* Visible nodes per label of a model's tree, named as its grammar names them ("L<n>"). */
static ag_status count_tree_labels(ag_edit_report *rep, const ag_proceduralize_result *r,
                                   ag_error *err)
{
    free_labels(rep);
    const ag_splittree *t = r->tree;
    size_t nl = r->labels->nlabels;
    size_t *count = calloc(nl + 1, sizeof *count);
    if (!count)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && t->nodes[n].label >= 0 &&
            (size_t)t->nodes[n].label < nl)
            count[t->nodes[n].label]++;
    rep->labels = calloc(nl + 1, sizeof *rep->labels);
    if (!rep->labels) {
        free(count);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t l = 0; l < nl; l++) {
        if (!count[l])
            continue;
        char name[32];
        snprintf(name, sizeof name, "L%zu", l + 1);
        ag_edit_label_count *e = &rep->labels[rep->nlabels];
        if (!(e->name = strdup(name))) {
            free(count);
            free_labels(rep);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        e->count = count[l];
        rep->nlabels++;
    }
    free(count);
    return AG_OK;
}

ag_status ag_edit_check_node(const ag_proceduralize_result *in, int32_t node, const char *field,
                             ag_error *err)
{
    if (node < 0 || (size_t)node >= in->tree->nnodes)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "%s: no node %d (the tree has %zu)",
                            field, node, in->tree->nnodes);
    if (in->tree->nodes[node].kind == AG_NODE_DEAD)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "%s: node %d was removed", field, node);
    return AG_OK;
}

ag_status ag_edit_model_wrap(ag_proceduralize_result *r, const ag_proceduralize_options *opt,
                             ag_edit_model **out, ag_error *err)
{
    *out = NULL;
    ag_edit_model *m = calloc(1, sizeof *m);
    if (m)
        m->cache = calloc(1, sizeof *m->cache);
    if (!m || !m->cache) {
        free(m);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    m->proc = r;
    if (opt) {
        m->opt = *opt;
        m->opt.progress = NULL;
        m->opt.user = NULL;
        m->opt.verify = 0;
    }
    *out = m;
    return AG_OK;
}

ag_status ag_edit_model_create(const ag_mesh *mesh, const ag_proceduralize_options *opt,
                               ag_edit_model **out, ag_error *err)
{
    *out = NULL;
    /* an edited mesh's components are placed terminals (a join may make one of several
     * loose twins on purpose): segmentation must not split them again */
    ag_proceduralize_options o = {0};
    if (opt)
        o = *opt;
    o.segment.keep_groups = 1;
    ag_proceduralize_result *r;
    ag_status st = ag_proceduralize_run(mesh, &o, &r, err);
    if (!st && (st = ag_rebuild_name_labels(r, err)))
        ag_proceduralize_result_free(r);
    if (st)
        return st;
    if ((st = ag_edit_model_wrap(r, &o, out, err)))
        ag_proceduralize_result_free(r);
    return st;
}

ag_status ag_edit_model_from_grammar(const ag_grammar *g, const ag_proceduralize_options *opt,
                                     ag_edit_model **out, ag_error *err)
{
    *out = NULL;
    ag_mesh *d;
    ag_status st = ag_grammar_derive(g, NULL, &d, err);
    if (st)
        return st;
    st = ag_edit_model_create(d, opt, out, err);
    ag_mesh_free(d);
    return st;
}

void ag_edit_model_free(ag_edit_model *m)
{
    if (!m)
        return;
    if (m->cache)
        ag_edit_resize_solver_free(m->cache->solver);
    free(m->cache);
    ag_proceduralize_result_free(m->proc);
    free(m);
}

ag_status ag_edit_apply(ag_edit_model *m, const ag_edit_op *op, ag_edit_model **out,
                        ag_edit_report *rep, ag_error *err)
{
    return ag_edit_apply_ex(m, op, AG_EDIT_READ_BACK, out, rep, err);
}

/* The edited tree of op (resize.h, treeedit.h) over *base. */
static ag_status edited_tree(const ag_proceduralize_result *in, const ag_edit_op *op,
                             ag_treeedit_base *base, ag_splittree **tree, int32_t **source,
                             ag_edit_report *rep, ag_error *err)
{
    switch (op->kind) {
    case AG_EDIT_RESIZE:
        memset(base, 0, sizeof *base);
        base->view = *in;
        return ag_edit_resize_tree(in, op, tree, source, rep, err);
    case AG_EDIT_SPLIT:
        return ag_treeedit_split(in, op, base, tree, source, rep, err);
    case AG_EDIT_JOIN:
        return ag_treeedit_join(in, op, base, tree, source, rep, err);
    case AG_EDIT_REMOVE:
        return ag_treeedit_remove(in, op, base, tree, source, rep, err);
    case AG_EDIT_PASTE:
        return ag_treeedit_paste(in, op, base, tree, source, rep, err);
    default:
        return ag_error_set(err, AG_ERR_INVALID, 0, "kind: unknown edit kind %d", op->kind);
    }
}

/* What the edited tree places, against the budget, before anything is made of it. */
static ag_status check_tree(const ag_edit_budget *b, const ag_proceduralize_result *base,
                            const ag_splittree *t, const int32_t *source, ag_error *err)
{
    if (!b || (!b->max_triangles && !b->max_components))
        return AG_OK;
    const ag_labels *L = base->labels;
    size_t tris = 0, comps = 0;
    for (size_t v = 0; v < t->nnodes; v++) {
        if (t->nodes[v].kind != AG_NODE_COMPONENT)
            continue;
        int32_t c = base->tree->nodes[source[v]].component;
        if (c >= 0 && (size_t)c < L->ncomponents) {
            tris += L->tri_start[c + 1] - L->tri_start[c];
            comps++;
        }
    }
    if (b->max_triangles && tris > b->max_triangles)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "the edit would make %zu triangles; this server takes at most %zu",
                            tris, b->max_triangles);
    if (b->max_components && comps > b->max_components)
        return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, 0,
                            "the edit would place %zu terminals; this server takes at most %zu",
                            comps, b->max_components);
    return AG_OK;
}

/* An edit that knows its result: the edited tree rebuilt into the new model (rebuild.h), node
 * ids kept; read back through its grammar when asked. */
static ag_status apply_tree(ag_edit_model *m, const ag_edit_op *op, unsigned flags,
                            ag_edit_model **out, ag_edit_report *rep, ag_error *err)
{
    ag_splittree *tree = NULL;
    int32_t *source = NULL;
    ag_proceduralize_result *r = NULL;
    ag_treeedit_base base = {0};
    ag_status st = edited_tree(m->proc, op, &base, &tree, &source, rep, err);
    if (!st && op->kind != AG_EDIT_RESIZE) /* a resize counted its emission itself */
        st = check_tree(op->budget, &base.view, tree, source, err);
    if (st) {
        ag_splittree_free(tree);
        free(source);
    } else {
        st = ag_rebuild(&base.view, tree, source, &m->opt.patterns, &r, err);
    }
    ag_treeedit_base_free(&base);
    if (st)
        return st;
    if (ag_edit_budget_cancelled(op->budget)) {
        ag_proceduralize_result_free(r);
        return ag_error_set(err, AG_ERR_CANCELLED, 0, "the edit was stopped");
    }
    if (!r->mesh->ntris) {
        ag_proceduralize_result_free(r);
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the edit leaves no geometry");
    }
    if (flags & AG_EDIT_READ_BACK) {
        st = ag_edit_model_from_grammar(r->grammar, &m->opt, out, err);
        ag_proceduralize_result_free(r);
    } else if ((st = ag_edit_model_wrap(r, &m->opt, out, err))) {
        ag_proceduralize_result_free(r);
    }
    if (!st && (st = count_tree_labels(rep, (*out)->proc, err))) {
        ag_edit_model_free(*out);
        *out = NULL;
    }
    return st;
}

ag_status ag_edit_apply_ex(ag_edit_model *m, const ag_edit_op *op, unsigned flags,
                           ag_edit_model **out, ag_edit_report *rep, ag_error *err)
{
    assert(m && m->proc && op && out);
    *out = NULL;
    ag_edit_report local = {0};
    if (!rep)
        rep = &local;
    else
        ag_edit_report_clear(rep);
    ag_mesh *mesh = NULL;
    ag_status st;
    if (!(flags & AG_EDIT_MESH_PATH)) {
        st = apply_tree(m, op, flags, out, rep, err);
        ag_edit_report_clear(&local); /* the caller asked for no report */
        return st;
    }
    /* the mesh path: the operation's mesh proceduralized again */
    switch (op->kind) {
    case AG_EDIT_RESIZE:
        st = ag_edit_resize(m->proc, op, &mesh, rep, err);
        break;
    case AG_EDIT_SPLIT:
        st = ag_edit_split(m->proc, op, &mesh, rep, err);
        break;
    case AG_EDIT_JOIN:
        st = ag_edit_join(m->proc, op, &mesh, rep, err);
        break;
    case AG_EDIT_PASTE:
        st = ag_edit_paste(m->proc, op, &mesh, rep, err);
        break;
    case AG_EDIT_REMOVE:
        st = ag_edit_remove(m->proc, op, &mesh, rep, err);
        break;
    default:
        st = ag_error_set(err, AG_ERR_INVALID, 0, "kind: unknown edit kind %d", op->kind);
    }
    if (st)
        goto done;
    if (!mesh || !mesh->ntris) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0, "the edit leaves no geometry");
        goto done;
    }
    if ((st = check_result(op->budget, mesh, err)))
        goto done;
    /* proceduralize the result, then read it back through its grammar for stable ids; the
     * budget is asked between the stages */
    ag_proceduralize_options po = m->opt;
    if (op->budget && op->budget->cancelled) {
        po.progress = budget_stage;
        po.user = (void *)op->budget;
    }
    ag_edit_model *first = NULL;
    if ((st = ag_edit_model_create(mesh, &po, &first, err)))
        goto done;
    if (flags & AG_EDIT_READ_BACK) {
        st = ag_edit_model_from_grammar(first->proc->grammar, &po, out, err);
        ag_edit_model_free(first);
        if (st)
            goto done;
    } else {
        *out = first;
    }
    st = count_tree_labels(rep, (*out)->proc, err);
    if (st) {
        ag_edit_model_free(*out);
        *out = NULL;
    }
done:
    ag_mesh_free(mesh);
    ag_edit_report_clear(&local);
    return st;
}

ag_status ag_edit_preview(ag_edit_model *m, const ag_edit_op *op, ag_box **boxes,
                          ag_edit_report *rep, ag_error *err)
{
    *boxes = NULL;
    if (op->kind != AG_EDIT_RESIZE)
        return ag_error_set(err, AG_ERR_INVALID, 0, "kind: only a resize can be previewed");
    ag_status st = ag_edit_check_node(m->proc, op->node, "node", err);
    if (st)
        return st;
    double t0 = ag_clock_ms();
    if (!ag_edit_resize_solver_matches(m->cache->solver, op)) {
        ag_edit_resize_solver_free(m->cache->solver);
        m->cache->solver = NULL;
        if ((st = ag_edit_resize_solver_create(m->proc, op, &m->cache->solver, err)))
            return st;
    }
    ag_box *b = malloc((m->proc->tree->nnodes + 1) * sizeof *b);
    if (!b)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if ((st = ag_edit_resize_solver_solve(m->cache->solver, op, b, rep, err))) {
        free(b);
        return st;
    }
    if (rep) /* with the factorization when it was made for this call */
        rep->solve_ms = ag_clock_ms() - t0;
    *boxes = b;
    return AG_OK;
}
