#include "pointedit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "../edit/idmatch.h"

static ag_status copy_terminal(ag_pointmodel *dst, const ag_pointmodel_terminal *t,
                               size_t *index, ag_error *err)
{
    if (AG_ARRAY_RESERVE(dst->terminals, dst->cap_terminals, dst->nterminals + 1))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_pointmodel_terminal *n = &dst->terminals[dst->nterminals];
    *n = *t;
    n->points = NULL;
    ag_status st = ag_cloud_clone(t->points, &n->points, err);
    if (st != AG_OK)
        return st;
    if (index)
        *index = dst->nterminals;
    dst->nterminals++;
    return AG_OK;
}

static ag_pointmodel *empty_like(const ag_pointmodel *pm)
{
    ag_pointmodel *n = ag_pointmodel_create();
    if (!n)
        return NULL;
    memcpy(n->offset, pm->offset, sizeof n->offset);
    memcpy(n->scale, pm->scale, sizeof n->scale);
    n->spacing = pm->spacing;
    n->tolerance = pm->tolerance;
    return n;
}

ag_status ag_pointedit_copy(const ag_pointmodel *pm, ag_pointmodel **out, ag_error *err)
{
    *out = NULL;
    ag_pointmodel *n = empty_like(pm);
    if (!n)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = AG_OK;
    for (size_t t = 0; t < pm->nterminals && !st; t++)
        st = copy_terminal(n, &pm->terminals[t], NULL, err);
    for (size_t i = 0; i < pm->nplacements && !st; i++)
        st = ag_pointmodel_add_placement(n, pm->placements[i].terminal, pm->placements[i].A,
                                         pm->placements[i].b, err);
    if (st) {
        ag_pointmodel_free(n);
        return st;
    }
    *out = n;
    return AG_OK;
}

/* Which terminal a group of an edited proxy names: "L<n>" the edited model's terminal n - 1,
 * "src_L<n>" the source's (copied over once), "L<a>+L<b>+..." (a join) the one of those whose
 * size fits the tetrahedron's legs. */
typedef struct {
    ag_pointmodel *made;
    const ag_pointmodel *self, *source;
    int32_t *source_copy; /* per source terminal: its copy in made, or -1 */
} lookup_ctx;

static int32_t terminal_named(lookup_ctx *x, const char *name, ag_error *err)
{
    int src = !strncmp(name, "src_", 4);
    const ag_pointmodel *from = src ? x->source : x->self;
    if (src)
        name += 4;
    char *end;
    long v = name[0] == 'L' ? strtol(name + 1, &end, 10) : 0;
    if (name[0] != 'L' || (*end && *end != '+') || v < 1 || (size_t)v > from->nterminals)
        return -1;
    if (!src)
        return (int32_t)(v - 1);
    if (x->source_copy[v - 1] < 0) {
        size_t t;
        if (copy_terminal(x->made, &from->terminals[v - 1], &t, err))
            return -1;
        x->source_copy[v - 1] = (int32_t)t;
    }
    return x->source_copy[v - 1];
}

static int32_t lookup_edit(void *user, const char *group, const double legs[3], ag_error *err)
{
    lookup_ctx *x = user;
    if (!strchr(group, '+'))
        return terminal_named(x, group, err);
    /* a join: the listed terminal whose size the legs fit best (a join moves nothing) */
    int32_t best = -1;
    double best_off = INFINITY;
    for (const char *p = group; p && *p;) {
        int32_t t = terminal_named(x, p, err);
        if (t < 0)
            return -1;
        const double *S = x->made->terminals[t].size;
        double off = 0;
        for (int a = 0; a < 3; a++) {
            double want = S[a] > AG_PROC_TINY ? S[a] : 1;
            off += fabs(legs[a] - want) / want;
        }
        if (off < best_off) {
            best_off = off;
            best = t;
        }
        p = strchr(p, '+');
        if (p)
            p++;
    }
    return best;
}

/* Per node of t: 1 for what op removes or replaces (the nodes it names and what they hold),
 * which no node of the result may take the id of; NULL when it names none (or out of memory:
 * then nothing is excluded, and the boxes alone decide). */
static uint8_t *replaced_by(const ag_splittree *t, const ag_edit_op *op)
{
    int replaces = op->kind == AG_EDIT_REMOVE || op->kind == AG_EDIT_JOIN ||
                   (op->kind == AG_EDIT_PASTE && op->placement == AG_EDIT_REPLACE);
    if (!replaces || !t->nnodes)
        return NULL;
    uint8_t *mark = calloc(t->nnodes, 1);
    if (!mark)
        return NULL;
    size_t named = op->kind == AG_EDIT_PASTE ? 1 : op->nnodes;
    for (size_t i = 0; i < named; i++) {
        int32_t n = op->kind == AG_EDIT_PASTE ? op->node : op->nodes[i];
        if (n > 0 && (size_t)n < t->nnodes)
            mark[n] = 1;
    }
    /* what a marked node holds: a parent comes before its children in no fixed order, so
     * walk up from every node */
    for (size_t n = 1; n < t->nnodes; n++)
        for (int32_t p = t->nodes[n].parent; p > 0 && !mark[n]; p = t->nodes[p].parent)
            if (mark[p])
                mark[n] = 1;
    return mark;
}

ag_status ag_pointedit_keep_ids(ag_pointmodel *made, const ag_pointmodel *before,
                                const ag_edit_op *op, ag_error *err)
{
    if (!made->em || !before || !before->em)
        return AG_OK;
    uint8_t *changed = op ? replaced_by(before->em->proc->tree, op) : NULL;
    ag_proceduralize_result *r = NULL;
    ag_status st = ag_idmatch_renumber(before->em->proc, made->em->proc, changed,
                                       &made->em->opt.patterns, &r, NULL, err);
    free(changed);
    if (st || !r)
        return st;
    ag_edit_model *em = NULL;
    if ((st = ag_edit_model_wrap(r, &made->em->opt, &em, err)))
        return st;
    ag_edit_model_free(made->em);
    made->em = em;
    return AG_OK;
}

ag_status ag_pointedit_apply(const ag_pointmodel *pm, const ag_edit_op *op,
                             const ag_pointmodel *source, ag_pointmodel **out,
                             ag_edit_report *rep, ag_error *err)
{
    *out = NULL;
    ag_edit_report local = {0};
    if (!rep)
        rep = &local;
    else
        ag_edit_report_clear(rep);
    if (!pm->em || (source && !source->em))
        return ag_error_set(err, AG_ERR_INVALID, 0, "the model is not built");
    ag_edit_op o = *op;
    if (!o.split_ratio)
        o.split_ratio = AG_POINTS_SPLIT_RATIO;
    if (!o.thin_share)
        o.thin_share = AG_POINTS_THIN_SHARE;
    o.source = source && source != pm ? source->em->proc : NULL;
    const ag_proceduralize_result *in = pm->em->proc;
    ag_mesh *mesh = NULL;
    ag_status st;
    switch (o.kind) {
    case AG_EDIT_RESIZE:
        st = ag_edit_resize(in, &o, &mesh, rep, err);
        break;
    case AG_EDIT_SPLIT:
        st = ag_edit_split(in, &o, &mesh, rep, err);
        break;
    case AG_EDIT_JOIN:
        st = ag_edit_join(in, &o, &mesh, rep, err);
        break;
    case AG_EDIT_PASTE:
        st = ag_edit_paste(in, &o, &mesh, rep, err);
        break;
    case AG_EDIT_REMOVE:
        st = ag_edit_remove(in, &o, &mesh, rep, err);
        break;
    default:
        st = ag_error_set(err, AG_ERR_INVALID, 0, "kind: unknown edit kind %d", o.kind);
    }
    ag_pointmodel *made = NULL;
    lookup_ctx x = {0};
    if (st)
        goto done;
    if (!mesh || !mesh->ntris) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0, "the edit leaves no points");
        goto done;
    }
    /* the new model: this model's terminals, then what a paste brings */
    if ((st = ag_pointedit_copy(pm, &made, err)))
        goto done;
    made->nplacements = 0;
    const ag_pointmodel *src = source ? source : pm;
    x = (lookup_ctx){made, pm, src, malloc((src->nterminals + 1) * sizeof(int32_t))};
    if (!x.source_copy) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t t = 0; t < src->nterminals; t++)
        x.source_copy[t] = -1;
    size_t joined = 0;
    if ((st = ag_pointmodel_read_proxy(made, mesh, lookup_edit, &x, &joined, err)) ||
        (st = ag_pointmodel_build(made, err)))
        goto done;
    /* placements per terminal, named as the new model names them */
    for (size_t i = 0; i < rep->nlabels; i++)
        free(rep->labels[i].name);
    free(rep->labels);
    rep->nlabels = 0;
    rep->labels = calloc(made->nterminals + 1, sizeof *rep->labels);
    if (!rep->labels) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t t = 0; t < made->nterminals; t++) {
        char name[32];
        snprintf(name, sizeof name, "L%zu", t + 1);
        rep->labels[t].name = strdup(name);
        if (!rep->labels[t].name) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        rep->nlabels = t + 1;
    }
    for (size_t i = 0; i < made->nplacements; i++)
        rep->labels[made->placements[i].terminal].count++;
    *out = made;
    made = NULL;
done:
    free(x.source_copy);
    ag_mesh_free(mesh);
    ag_pointmodel_free(made);
    ag_edit_report_clear(&local);
    return st;
}
