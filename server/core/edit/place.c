#include "place.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/hash.h"
#include "../base/tolerance.h"

void ag_place_identity(ag_place_map *m)
{
    memset(m, 0, sizeof *m);
    for (int i = 0; i < 3; i++)
        m->M[i][i] = 1;
}

void ag_place_boxes(ag_place_map *m, const ag_box *from, const ag_box *to, int k)
{
    k &= 3;
    double S[3], cf[3], ct[3];
    ag_box_extents(from, S);
    ag_box_centre(from, cf);
    ag_box_centre(to, ct);
    double Sr[3] = {S[0], S[1], S[2]};
    if (k & 1) {
        Sr[0] = S[1];
        Sr[1] = S[0];
    }
    double s[3];
    for (int a = 0; a < 3; a++)
        s[a] = Sr[a] > 0 ? ag_box_extent(to, a) / Sr[a] : 1.0;
    double c = k == 0 ? 1 : k == 2 ? -1 : 0, sn = k == 1 ? 1 : k == 3 ? -1 : 0;
    double R[3][3] = {{c, -sn, 0}, {sn, c, 0}, {0, 0, 1}};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m->M[i][j] = s[i] * R[i][j];
    for (int i = 0; i < 3; i++)
        m->t[i] = ct[i] - (m->M[i][0] * cf[0] + m->M[i][1] * cf[1] + m->M[i][2] * cf[2]);
}

void ag_place_apply(const ag_place_map *m, const double p[3], double q[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = m->M[i][0] * p[0] + m->M[i][1] * p[1] + m->M[i][2] * p[2] + m->t[i];
    memcpy(q, r, sizeof r);
}

ag_box ag_place_apply_box(const ag_place_map *m, const ag_box *b)
{
    ag_box o = ag_box_empty();
    for (int i = 0; i < 8; i++) {
        double p[3] = {i & 1 ? b->max[0] : b->min[0], i & 2 ? b->max[1] : b->min[1],
                       i & 4 ? b->max[2] : b->min[2]};
        ag_place_apply(m, p, p);
        ag_box_extend_point(&o, p);
    }
    return o;
}

ag_status ag_place_check_node(const ag_proceduralize_result *r, int32_t node, const char *what,
                              ag_error *err)
{
    const ag_splittree *t = r ? r->tree : NULL;
    if (!t)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s: the model has no split tree", what);
    if (node < 0 || (size_t)node >= t->nnodes)
        return ag_error_set(err, AG_ERR_NOT_FOUND, node,
                            "%s: node %d is not in the split tree (nodes 0..%zu)", what,
                            (int)node, t->nnodes - 1);
    if (t->nodes[node].kind == AG_NODE_DEAD)
        return ag_error_set(err, AG_ERR_NOT_FOUND, node,
                            "%s: node %d was removed from the split tree", what, (int)node);
    return AG_OK;
}

ag_status ag_place_check_selection(const ag_proceduralize_result *in, const ag_edit_op *op,
                                   const char *verb, const char *need, const char *done,
                                   ag_error *err)
{
    if (op->nnodes == 0 || !op->nodes)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s needs %s (nodes is empty)", verb, need);
    char what[48];
    for (size_t i = 0; i < op->nnodes; i++) {
        snprintf(what, sizeof what, "%s nodes[%zu]", verb, i);
        ag_status st = ag_place_check_node(in, op->nodes[i], what, err);
        if (st)
            return st;
        if (op->nodes[i] == AG_EDIT_ROOT)
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s nodes[%zu]: the root cannot be %s",
                                verb, i, done);
    }
    return AG_OK;
}

ag_status ag_place_check_split(const ag_proceduralize_result *in, const ag_edit_op *op,
                               size_t *ncomponents, ag_error *err)
{
    *ncomponents = 0;
    ag_status st = ag_place_check_node(in, op->node, "split node", err);
    if (st)
        return st;
    if (op->axis < 0 || op->axis > 2)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "split axis must be 0, 1 or 2 (x, y or z), not %d", op->axis);
    const ag_splittree *t = in->tree;
    const ag_box B = t->nodes[op->node].box;
    int a = op->axis;
    /* both halves must keep a size the tree can tell from a face coincidence (a tree without
     * one: as if its diagonal were 1 m) */
    double eps = t->eps > 0 ? AG_EDIT_SPLIT_MARGIN * t->eps : AG_EDIT_COINCIDENT;
    if (!isfinite(op->at) || op->at <= B.min[a] + eps || op->at >= B.max[a] - eps)
        return ag_error_set(err, AG_ERR_INVALID, op->node,
                            "split plane %c = %g is not inside node %d's box (%g .. %g)",
                            "xyz"[a], op->at, (int)op->node, B.min[a], B.max[a]);
    uint8_t *mark = calloc(t->ncomponents + 1, 1);
    if (!mark)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    *ncomponents = ag_place_mark_subtree(t, op->node, mark);
    free(mark);
    if (*ncomponents == 0)
        return ag_error_set(err, AG_ERR_INVALID, op->node, "node %d has no geometry to split",
                            (int)op->node);
    return AG_OK;
}

size_t ag_place_mark_subtree(const ag_splittree *t, int32_t node, uint8_t *mark)
{
    /* iterative preorder walk over first_child / next_sibling, bounded by the subtree root */
    assert(node >= 0 && (size_t)node < t->nnodes); /* callers check the node first */
    size_t n = 0;
    int32_t v = node;
    while (v >= 0) {
        const ag_tnode *x = &t->nodes[v];
        if (x->kind == AG_NODE_COMPONENT && x->component >= 0 && !mark[x->component]) {
            mark[x->component] = 1;
            n++;
        }
        if (x->first_child >= 0) {
            v = x->first_child;
            continue;
        }
        while (v != node && t->nodes[v].next_sibling < 0)
            v = t->nodes[v].parent;
        if (v == node)
            break;
        v = t->nodes[v].next_sibling;
    }
    return n;
}

int ag_place_facing(const ag_box *b, const ag_box *ref)
{
    /* the thinner horizontal axis is the facing axis */
    int a = ag_box_extent(b, 0) < ag_box_extent(b, 1) ? 0 : 1;
    double off = ag_box_centre_axis(b, a) - ag_box_centre_axis(ref, a);
    double size = ag_box_extent(ref, a);
    if (fabs(off) <= AG_EDIT_COINCIDENT * (size > 0 ? size : 1.0))
        return a == 0 ? 2 : 3;
    if (a == 0)
        return off > 0 ? 0 : 2;
    return off > 0 ? 1 : 3;
}

int ag_place_fill_grid(const ag_box *B, const double S[3], int facing, unsigned counts[3],
                       double step[3], ag_box *cell0)
{
    double D[3];
    for (int a = 0; a < 3; a++) {
        D[a] = B->max[a] - B->min[a];
        counts[a] = 1;
        step[a] = 0;
    }
    *cell0 = *B;
    int ax[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (D[ax[j]] > D[ax[i]]) {
                int x = ax[i];
                ax[i] = ax[j];
                ax[j] = x;
            }
    for (int i = 0; i < 2; i++) {
        int a = ax[i];
        double r = S[a] > 0 ? D[a] / S[a] : 1.0;
        if (!(r < 1e7))
            return -1;
        counts[a] = r < 1.5 ? 1u : (unsigned)lround(r);
        step[a] = D[a] / counts[a];
        cell0->max[a] = cell0->min[a] + step[a];
    }
    int a = ax[2];
    double size = fmin(S[a], D[a]);
    int facing_axis = facing & 1;
    if (a == facing_axis && facing < 2) {
        cell0->min[a] = B->max[a] - size; /* faces +x / +y */
    } else if (a == facing_axis) {
        cell0->max[a] = B->min[a] + size; /* faces -x / -y */
    } else {
        double c = 0.5 * (B->min[a] + B->max[a]);
        cell0->min[a] = c - 0.5 * size;
        cell0->max[a] = c + 0.5 * size;
    }
    step[a] = 0;
    return 0;
}

void ag_place_label_name(const ag_proceduralize_result *r, uint32_t c, const char *prefix,
                         char *buf, size_t cap)
{
    int32_t l = c < r->labels->ncomponents ? r->labels->label[c] : -1;
    if (l >= 0)
        snprintf(buf, cap, "%sL%d", prefix ? prefix : "", (int)l + 1);
    else
        snprintf(buf, cap, "%sC%u", prefix ? prefix : "", c + 1);
}

/* ---- builder ------------------------------------------------------------------------------ */

struct ag_place_builder {
    ag_mesh *m;
    size_t comp;      /* current component */
    int has_comp;
    int32_t *gslot;   /* open addressing: group index or -1 */
    size_t gcap;
    uint32_t *vmap;   /* scratch: source vertex → new vertex, UINT32_MAX when unset */
    size_t vcap;
};

ag_place_builder *ag_place_builder_create(void)
{
    ag_place_builder *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    b->m = ag_mesh_create();
    if (!b->m) {
        free(b);
        return NULL;
    }
    return b;
}

void ag_place_builder_free(ag_place_builder *b)
{
    if (!b)
        return;
    ag_mesh_free(b->m);
    free(b->gslot);
    free(b->vmap);
    free(b);
}

static ag_status group_index(ag_place_builder *b, const char *name, int32_t *out)
{
    if (2 * (b->m->ngroups + 1) > b->gcap) {
        size_t nc;
        if (ag_array_hash_size(b->m->ngroups + 1, &nc))
            return AG_ERR_TOO_LARGE;
        int32_t *ns = malloc(nc * sizeof *ns);
        if (!ns)
            return AG_ERR_NOMEM;
        for (size_t i = 0; i < nc; i++)
            ns[i] = -1;
        for (size_t g = 0; g < b->m->ngroups; g++) {
            size_t i = ag_hash_text(b->m->group_names[g]) & (nc - 1);
            while (ns[i] >= 0)
                i = (i + 1) & (nc - 1);
            ns[i] = (int32_t)g;
        }
        free(b->gslot);
        b->gslot = ns;
        b->gcap = nc;
    }
    size_t i = ag_hash_text(name) & (b->gcap - 1);
    while (b->gslot[i] >= 0) {
        if (!strcmp(b->m->group_names[b->gslot[i]], name)) {
            *out = b->gslot[i];
            return AG_OK;
        }
        i = (i + 1) & (b->gcap - 1);
    }
    size_t g;
    ag_status st = ag_mesh_add_group(b->m, name, &g);
    if (st)
        return st;
    b->gslot[i] = (int32_t)g;
    *out = (int32_t)g;
    return AG_OK;
}

ag_status ag_place_begin(ag_place_builder *b, const char *group)
{
    int32_t g;
    ag_status st = group_index(b, group, &g);
    if (!st)
        st = ag_mesh_add_component(b->m, g, &b->comp);
    if (!st)
        b->has_comp = 1;
    return st;
}

ag_status ag_place_add(ag_place_builder *b, const ag_proceduralize_result *r, uint32_t c,
                       const ag_place_map *m)
{
    const ag_mesh *src = r->mesh;
    const ag_labels *L = r->labels;
    if (!b->has_comp || c >= L->ncomponents)
        return AG_ERR_INTERNAL;
    if (src->nverts > b->vcap) {
        size_t old = b->vcap;
        ag_status st = AG_ARRAY_RESERVE_EXACT(b->vmap, b->vcap, src->nverts);
        if (st)
            return st;
        for (size_t i = old; i < b->vcap; i++)
            b->vmap[i] = UINT32_MAX;
    }
    ag_status st = AG_OK;
    uint32_t s0 = L->tri_start[c], s1 = L->tri_start[c + 1];
    for (uint32_t s = s0; s < s1 && !st; s++) {
        const uint32_t *tr = src->tri + 3 * (size_t)L->tris[s];
        uint32_t v[3];
        for (int k = 0; k < 3 && !st; k++) {
            uint32_t *slot = &b->vmap[tr[k]];
            if (*slot == UINT32_MAX) {
                double p[3];
                memcpy(p, src->pos + 3 * (size_t)tr[k], sizeof p);
                if (m)
                    ag_place_apply(m, p, p);
                *slot = (uint32_t)b->m->nverts;
                st = ag_mesh_add_vertex(b->m, p[0], p[1], p[2]);
            }
            v[k] = *slot;
        }
        if (!st)
            st = ag_mesh_add_triangle(b->m, v[0], v[1], v[2], (uint32_t)b->comp);
    }
    /* reset only what this component touched */
    for (uint32_t s = s0; s < s1; s++)
        for (int k = 0; k < 3; k++)
            b->vmap[src->tri[3 * (size_t)L->tris[s] + k]] = UINT32_MAX;
    return st;
}

ag_status ag_place_copy(ag_place_builder *b, const ag_proceduralize_result *r, uint32_t c,
                        const ag_place_map *m, const char *prefix)
{
    char name[64];
    ag_place_label_name(r, c, prefix, name, sizeof name);
    ag_status st = ag_place_begin(b, name);
    return st ? st : ag_place_add(b, r, c, m);
}

ag_status ag_place_copy_unmarked(ag_place_builder *b, const ag_proceduralize_result *r,
                                 const uint8_t *mark)
{
    const ag_splittree *t = r->tree;
    ag_status st = AG_OK;
    for (size_t c = 0; c < t->ncomponents && !st; c++)
        if (t->comp_node[c] >= 0 && !(mark && mark[c]))
            st = ag_place_copy(b, r, (uint32_t)c, NULL, NULL);
    return st;
}

size_t ag_place_triangles(const ag_place_builder *b)
{
    return b->m->ntris;
}

ag_status ag_place_finish(ag_place_builder *b, ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (b->m->ntris == 0) {
        ag_place_builder_free(b);
        return ag_error_set(err, AG_ERR_INVALID, 0, "the edit would leave no geometry");
    }
    *out = b->m;
    b->m = NULL;
    ag_place_builder_free(b);
    return AG_OK;
}

/* ---- paste plans -------------------------------------------------------------------------- */

#define PASTE_MAX_TRIANGLES 50000000.0

ag_status ag_place_paste_plan_make(const ag_proceduralize_result *in, const ag_edit_op *op,
                                   uint8_t *smark, ag_place_paste_plan *p, ag_error *err)
{
    memset(p, 0, sizeof *p);
    const ag_proceduralize_result *src = op->source ? op->source : in;
    int cross = src != in;
    if (op->nnodes == 0 || !op->nodes)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste needs a source selection (nodes is empty)");
    ag_status st = ag_place_check_node(in, op->node, "paste destination node", err);
    if (st)
        return st;
    char what[64];
    for (size_t i = 0; i < op->nnodes; i++) {
        snprintf(what, sizeof what, "paste source nodes[%zu]%s", i,
                 cross ? " (source model)" : "");
        if ((st = ag_place_check_node(src, op->nodes[i], what, err)))
            return st;
    }
    if (op->placement != AG_EDIT_INSERT && op->placement != AG_EDIT_REPLACE)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste placement must be insert (0) or replace (1), not %d",
                            op->placement);
    if (op->fit != AG_EDIT_FILL && op->fit != AG_EDIT_DERIVE)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "paste fit must be fill (0) or derive (1), not %d", op->fit);
    const ag_splittree *ts = src->tree, *td = in->tree;
    /* the joined source */
    ag_box Bs = ts->nodes[op->nodes[0]].box;
    size_t ns = 0, stris = 0;
    for (size_t i = 0; i < op->nnodes; i++) {
        ag_box_extend_box(&Bs, &ts->nodes[op->nodes[i]].box);
        ns += ag_place_mark_subtree(ts, op->nodes[i], smark);
    }
    if (ns == 0)
        return ag_error_set(err, AG_ERR_INVALID, op->nodes[0],
                            "the source selection has no geometry");
    for (size_t c = 0; c < ts->ncomponents; c++)
        if (smark[c])
            stris += src->labels->ntris[c];
    const ag_box Bd = td->nodes[op->node].box;
    int fs = ag_place_facing(&Bs, &ts->nodes[AG_EDIT_ROOT].box);
    int fd = ag_place_facing(&Bd, &td->nodes[AG_EDIT_ROOT].box);
    int k = (fd - fs) & 3;
    double S[3];
    ag_box_extents(&Bs, S);
    if (k & 1) {
        double x = S[0];
        S[0] = S[1];
        S[1] = x;
    }
    p->source_box = Bs;
    p->turns = k;
    p->ncomponents = ns;
    p->counts[0] = p->counts[1] = p->counts[2] = 1;
    p->cell0 = Bd;
    if (op->fit == AG_EDIT_FILL) {
        if (ag_place_fill_grid(&Bd, S, fd, p->counts, p->step, &p->cell0))
            return ag_error_set(err, AG_ERR_TOO_LARGE, op->node,
                                "the source is too small to fill node %d", (int)op->node);
        double total = (double)p->counts[0] * p->counts[1] * p->counts[2];
        double limit = op->budget && op->budget->max_triangles &&
                               (double)op->budget->max_triangles < PASTE_MAX_TRIANGLES
                           ? (double)op->budget->max_triangles
                           : PASTE_MAX_TRIANGLES;
        if (total * (double)stris > limit)
            return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, op->node,
                                "filling node %d needs %.0f copies of %zu triangles (limit %.0f "
                                "triangles)",
                                (int)op->node, total, stris, limit);
        if (op->budget && op->budget->max_components &&
            total * (double)op->nnodes > (double)op->budget->max_components)
            return ag_error_set(err, AG_ERR_RESULT_TOO_LARGE, op->node,
                                "filling node %d needs %.0f copies of %zu nodes (limit %zu "
                                "terminals)",
                                (int)op->node, total, op->nnodes, op->budget->max_components);
    }
    p->copies = (size_t)p->counts[0] * p->counts[1] * p->counts[2];
    return AG_OK;
}

ag_box ag_place_paste_cell(const ag_place_paste_plan *p, unsigned x, unsigned y, unsigned z)
{
    ag_box cell = p->cell0;
    unsigned ix[3] = {x, y, z};
    for (int a = 0; a < 3; a++) {
        cell.min[a] += ix[a] * p->step[a];
        cell.max[a] += ix[a] * p->step[a];
    }
    return cell;
}

void ag_place_paste_message(ag_edit_report *rep, const ag_place_paste_plan *p,
                            const ag_edit_op *op)
{
    snprintf(rep->message, sizeof rep->message,
             "pasted %zu cop%s (%u x %u x %u) of %zu components into node %d, turned by %d "
             "quarter turn%s",
             p->copies, p->copies == 1 ? "y" : "ies", p->counts[0], p->counts[1], p->counts[2],
             p->ncomponents, (int)op->node, p->turns, p->turns == 1 ? "" : "s");
}
