#include "pointedit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "../edit/idmatch.h"
#include "../proc/label.h"

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

/* Which terminal a group of an edited proxy names. A group is named after a label of the model
 * edited ("L<n>": label n - 1; "src_L<n>": the source's, whose terminal is copied over once;
 * "L<a>+L<b>+...": a join) and a label after the terminals (the variants) it holds: a build
 * names terminal t's label L<t+1>, but a model numbered as the one it was edited from
 * (ag_pointedit_keep_ids) has its labels named after that one's, so the label's terminals are
 * looked up in the model's own labels; of several, the one whose size fits the tetrahedron's
 * legs (a join moves nothing, a label named after an old one may hold two terminals). */
typedef struct {
    ag_pointmodel *made;
    const ag_pointmodel *self, *source;
    int32_t *source_copy; /* per source terminal: its copy in made, or -1 */
} lookup_ctx;

/* How well a terminal's size fits the legs of a placed tetrahedron (0: exactly). */
static double legs_off(const double S[3], const double legs[3])
{
    double off = 0;
    for (int a = 0; a < 3; a++) {
        double want = S[a] > AG_PROC_TINY ? S[a] : 1;
        off += fabs(legs[a] - want) / want;
    }
    return off;
}

/* The terminal in made that terminal t of from is: made's own for the edited model, a copy
 * of the source's made once; -1 when out of memory. */
static int32_t terminal_in_made(lookup_ctx *x, int src, size_t t, ag_error *err)
{
    if (!src)
        return (int32_t)t;
    if (x->source_copy[t] < 0) {
        size_t at;
        if (copy_terminal(x->made, &x->source->terminals[t], &at, err))
            return -1;
        x->source_copy[t] = (int32_t)at;
    }
    return x->source_copy[t];
}

/* Of the terminals one label name ("L<n>" or "src_L<n>", up to a '+' or the end) holds, the
 * one in made that fits legs best, if it fits better than *best_off; -1 when the name is not
 * a label of its model (or out of memory), else *best updated (or left). */
static int label_best(lookup_ctx *x, const char *name, const double legs[3], int32_t *best,
                      double *best_off, ag_error *err)
{
    int src = !strncmp(name, "src_", 4);
    const ag_pointmodel *from = src ? x->source : x->self;
    if (src)
        name += 4;
    char *end;
    long v = name[0] == 'L' ? strtol(name + 1, &end, 10) : 0;
    if (name[0] != 'L' || (*end && *end != '+') || v < 1)
        return -1;
    const ag_labels *L = from->em ? from->em->proc->labels : NULL;
    size_t found = 0;
    for (size_t t = 0; L && t < L->nvariants && t < from->nterminals; t++) {
        if (L->variant_label[t] != v - 1)
            continue;
        found++;
        double off = legs_off(from->terminals[t].size, legs);
        if (*best >= 0 && off >= *best_off)
            continue;
        int32_t m = terminal_in_made(x, src, t, err);
        if (m < 0)
            return -1;
        *best = m;
        *best_off = off;
    }
    if (found)
        return 0;
    /* a model without labels: a build's naming */
    if (L || (size_t)v > from->nterminals)
        return -1;
    int32_t m = terminal_in_made(x, src, (size_t)v - 1, err);
    if (m < 0)
        return -1;
    double off = legs_off(from->terminals[v - 1].size, legs);
    if (*best < 0 || off < *best_off) {
        *best = m;
        *best_off = off;
    }
    return 0;
}

static int32_t lookup_edit(void *user, const char *group, const double legs[3], ag_error *err)
{
    lookup_ctx *x = user;
    int32_t best = -1;
    double best_off = INFINITY;
    for (const char *p = group; p && *p;) {
        if (label_best(x, p, legs, &best, &best_off, err))
            return -1;
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
    int replaces = op->kind == AG_EDIT_REMOVE ||
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

/* The op as a point model runs it: the point-cloud split ratio and thin share unless it sets
 * its own, a paste's source the other model's proxy. */
static ag_edit_op point_op(const ag_edit_op *op, const ag_pointmodel *pm,
                           const ag_pointmodel *source)
{
    ag_edit_op o = *op;
    if (!o.split_ratio)
        o.split_ratio = AG_POINTS_SPLIT_RATIO;
    if (!o.thin_share)
        o.thin_share = AG_POINTS_THIN_SHARE;
    o.source = source && source != pm && source->em ? source->em->proc : NULL;
    return o;
}

/* r moved by d (its mesh and its nodes' boxes; pivots are relative to the parent's box). */
static void shift_result(ag_proceduralize_result *r, const double d[3])
{
    if (!d[0] && !d[1] && !d[2])
        return;
    for (size_t v = 0; v < r->mesh->nverts; v++)
        for (int a = 0; a < 3; a++)
            r->mesh->pos[3 * v + a] += d[a];
    for (size_t n = 0; n < r->tree->nnodes; n++)
        for (int a = 0; a < 3; a++) {
            r->tree->nodes[n].box.min[a] += d[a];
            r->tree->nodes[n].box.max[a] += d[a];
        }
}

/* What op makes of before on its tree (core/edit: the nodes it keeps at their ids with the
 * boxes it gives them, a resize's rule-mates moved with its node, copies appended, removed
 * nodes dead), in made's coordinates: where made's nodes are looked for. *out NULL when the
 * tree edit refuses what the proxy's edit made (then before's own boxes are matched). */
static ag_status expected_model(const ag_pointmodel *made, const ag_pointmodel *before,
                                const ag_edit_op *op, const ag_pointmodel *source,
                                ag_edit_model **out, ag_error *err)
{
    *out = NULL;
    ag_edit_op o = point_op(op, before, source);
    ag_error e;
    ag_error_clear(&e);
    ag_status st = ag_edit_apply_ex(before->em, &o, 0, out, NULL, &e);
    if (st == AG_ERR_NOMEM || st == AG_ERR_CANCELLED) {
        if (err)
            *err = e;
        return st;
    }
    if (st) {
        *out = NULL;
        return AG_OK;
    }
    double d[3];
    for (int a = 0; a < 3; a++)
        d[a] = before->offset[a] - made->offset[a];
    shift_result((*out)->proc, d);
    return AG_OK;
}

ag_status ag_pointedit_keep_ids(ag_pointmodel *made, const ag_pointmodel *before,
                                const ag_edit_op *op, const ag_pointmodel *source,
                                ag_error *err)
{
    if (!made->em || !before || !before->em)
        return AG_OK;
    ag_edit_model *expected = NULL;
    /* a join keeps its placements where they were (a point model has no joined terminal:
     * lookup_edit reads a joined group back as its members), so they are matched where
     * before had them, not at the union the tree edit gives the joined node */
    ag_status st = op && op->kind != AG_EDIT_JOIN
                       ? expected_model(made, before, op, source, &expected, err)
                       : AG_OK;
    if (st)
        return st;
    /* matched against where the op put every node; without that, against before's boxes,
     * with what the op removes or replaces kept out */
    uint8_t *changed = op && !expected ? replaced_by(before->em->proc->tree, op) : NULL;
    ag_proceduralize_result *r = NULL;
    st = ag_idmatch_renumber(expected ? expected->proc : before->em->proc, made->em->proc,
                             changed, &made->em->opt.patterns, &r, NULL, err);
    free(changed);
    ag_edit_model_free(expected);
    if (st || !r)
        return st;
    ag_edit_model *em = NULL;
    if ((st = ag_edit_model_wrap(r, &made->em->opt, &em, err)))
        return st;
    ag_edit_model_free(made->em);
    made->em = em;
    return AG_OK;
}

/* Placements by the lower x of their boxes, for the search of ag_pointedit_kept_order. */
typedef struct {
    double x;
    uint32_t i;
} by_x;

static int cmp_by_x(const void *pa, const void *pb)
{
    const by_x *a = pa, *b = pb;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    return (a->i > b->i) - (a->i < b->i);
}

/* Boxes this close are one placement's at least (or the tree's tolerances, when larger). */
#define KEPT_BOX_TOL 1e-6

ag_status ag_pointedit_kept_order(ag_pointmodel *pm, const ag_edit_model *kept, ag_mesh **mesh,
                                  ag_error *err)
{
    *mesh = NULL;
    const ag_splittree *t = kept->proc->tree;
    const ag_labels *L = kept->proc->labels;
    size_t n = pm->nplacements;
    double tol = fmax(KEPT_BOX_TOL, 2 * fmax(t->tol, t->eps));
    if (L->ncomponents != n || t->ncomponents != n)
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "the kept tree has %zu components, the model %zu placements",
                            L->ncomponents, n);
    by_x *xs = malloc((n + 1) * sizeof *xs);
    uint8_t *used = calloc(n + 1, 1);
    ag_pointmodel_placement *ordered = malloc((n + 1) * sizeof *ordered);
    ag_status st = xs && used && ordered ? AG_OK
                                         : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; !st && i < n; i++)
        xs[i] = (by_x){pm->placements[i].box.min[0], (uint32_t)i};
    if (!st)
        qsort(xs, n, sizeof *xs, cmp_by_x);
    for (size_t k = 0; !st && k < n; k++) {
        int32_t v = t->comp_node[k];
        if (v < 0 || (size_t)v >= t->nnodes) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)k,
                              "component %zu of the kept tree has no node", k);
            break;
        }
        const ag_box *b = &t->nodes[v].box;
        /* the first placement at or above b's lower x less the tolerance */
        size_t lo = 0, hi = n;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (xs[mid].x < b->min[0] - tol)
                lo = mid + 1;
            else
                hi = mid;
        }
        /* the nearest free placement of the component's terminal (the tree's box may differ
         * from the placement's by the tree's tolerance); the kept turn is the label's, not
         * always the placement's: it only breaks ties */
        int32_t found = -1;
        double best = INFINITY;
        for (size_t j = lo; j < n && xs[j].x <= b->min[0] + tol; j++) {
            const ag_pointmodel_placement *p = &pm->placements[xs[j].i];
            if (used[xs[j].i] || p->terminal != L->variant[k])
                continue;
            double d = 0;
            for (int a = 0; a < 3; a++)
                d = fmax(d, fmax(fabs(p->box.min[a] - b->min[a]), fabs(p->box.max[a] - b->max[a])));
            d += p->rot == L->rot[k] ? 0 : KEPT_BOX_TOL / 2;
            if (d <= tol && d < best) {
                best = d;
                found = (int32_t)xs[j].i;
            }
        }
        if (found < 0) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)v,
                              "node %d of the kept tree places no placement of the model", v);
            break;
        }
        used[found] = 1;
        ordered[k] = pm->placements[found];
    }
    if (!st) {
        memcpy(pm->placements, ordered, n * sizeof *ordered);
        st = ag_pointmodel_proxy_mesh(pm, mesh, err);
    }
    free(xs);
    free(used);
    free(ordered);
    return st;
}

ag_status ag_pointedit_name_groups(ag_pointmodel *pm, ag_error *err)
{
    if (pm->em && ag_labels_name_groups(pm->em->proc->mesh, pm->em->proc->labels) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
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
    ag_edit_op o = point_op(op, pm, source);
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
