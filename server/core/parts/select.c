#include "select.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int live(const ag_splittree *t, int32_t n)
{
    return n >= 0 && (size_t)n < t->nnodes && t->nodes[n].kind != AG_NODE_DEAD;
}

static ag_status push(int32_t **v, size_t *n, size_t *cap, int32_t x)
{
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 16;
        int32_t *p = realloc(*v, c * sizeof *p);
        if (!p)
            return AG_ERR_NOMEM;
        *v = p;
        *cap = c;
    }
    (*v)[(*n)++] = x;
    return AG_OK;
}

static int box_inside(const ag_box *in, const ag_box *out)
{
    for (int a = 0; a < 3; a++)
        if (in->min[a] < out->min[a] || in->max[a] > out->max[a])
            return 0;
    return 1;
}

ag_status ag_select_box(const ag_splittree *t, const ag_box *window, int32_t **nodes, size_t *n,
                        ag_error *err)
{
    *nodes = NULL;
    *n = 0;
    size_t cap = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT && box_inside(&t->nodes[i].box, window) &&
            push(nodes, n, &cap, (int32_t)i)) {
            free(*nodes);
            *nodes = NULL;
            *n = 0;
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
    return AG_OK;
}

ag_status ag_select_rect(const ag_splittree *t, const double vp[16], const double rect[4],
                         int32_t **nodes, size_t *n, ag_error *err)
{
    *nodes = NULL;
    *n = 0;
    for (int i = 0; i < 16; i++)
        if (!isfinite(vp[i]))
            return ag_error_set(err, AG_ERR_INVALID, 0, "view-projection matrix: not finite");
    double x0 = fmin(rect[0], rect[2]), x1 = fmax(rect[0], rect[2]);
    double y0 = fmin(rect[1], rect[3]), y1 = fmax(rect[1], rect[3]);
    size_t cap = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        if (t->nodes[i].kind != AG_NODE_COMPONENT)
            continue;
        const ag_box *b = &t->nodes[i].box;
        int in = 1;
        for (int c = 0; c < 8 && in; c++) {
            double p[3] = {c & 1 ? b->max[0] : b->min[0], c & 2 ? b->max[1] : b->min[1],
                           c & 4 ? b->max[2] : b->min[2]};
            double q[4];
            for (int r = 0; r < 4; r++)
                q[r] = vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r];
            if (!(q[3] > 0)) {
                in = 0;
                break;
            }
            double x = q[0] / q[3], y = q[1] / q[3];
            in = x >= x0 && x <= x1 && y >= y0 && y <= y1;
        }
        if (in && push(nodes, n, &cap, (int32_t)i)) {
            free(*nodes);
            *nodes = NULL;
            *n = 0;
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
    }
    return AG_OK;
}

ag_status ag_select_pick(const ag_proceduralize_result *r, const double o[3], const double d[3],
                         int32_t *node, ag_error *err)
{
    *node = -1;
    const ag_mesh *m = r->mesh;
    double best = INFINITY;
    uint32_t hit = UINT32_MAX;
    for (size_t f = 0; f < m->ntris; f++) {
        /* Moller-Trumbore */
        const double *a = m->pos + 3 * m->tri[3 * f], *b = m->pos + 3 * m->tri[3 * f + 1],
                     *c = m->pos + 3 * m->tri[3 * f + 2];
        double e1[3], e2[3], pv[3], tv[3], qv[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = b[k] - a[k];
            e2[k] = c[k] - a[k];
            tv[k] = o[k] - a[k];
        }
        pv[0] = d[1] * e2[2] - d[2] * e2[1];
        pv[1] = d[2] * e2[0] - d[0] * e2[2];
        pv[2] = d[0] * e2[1] - d[1] * e2[0];
        double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
        if (fabs(det) < 1e-300)
            continue;
        double inv = 1 / det;
        double u = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) * inv;
        if (u < 0 || u > 1)
            continue;
        qv[0] = tv[1] * e1[2] - tv[2] * e1[1];
        qv[1] = tv[2] * e1[0] - tv[0] * e1[2];
        qv[2] = tv[0] * e1[1] - tv[1] * e1[0];
        double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) * inv;
        if (v < 0 || u + v > 1)
            continue;
        double s = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
        if (s > 0 && s < best) {
            best = s;
            hit = m->tri_component[f];
        }
    }
    if (hit == UINT32_MAX || hit >= r->tree->ncomponents || r->tree->comp_node[hit] < 0)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "the click hits no part of the model");
    *node = r->tree->comp_node[hit];
    return AG_OK;
}

int32_t ag_select_parent(const ag_splittree *t, int32_t node)
{
    if (!live(t, node))
        return -1;
    int32_t p = t->nodes[node].parent;
    while (p >= 0 && t->nodes[p].kind == AG_NODE_SPLIT)
        p = t->nodes[p].parent;
    return p;
}

size_t ag_select_children(const ag_splittree *t, int32_t node, int32_t *out, size_t cap)
{
    if (!live(t, node))
        return 0;
    size_t n = 0;
    for (int32_t c = t->nodes[node].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, c);
        if (e < 0 || t->nodes[e].kind == AG_NODE_DEAD)
            continue;
        if (n < cap)
            out[n] = e;
        n++;
    }
    return n;
}

int32_t ag_select_sibling(const ag_splittree *t, int32_t node, int dir)
{
    int32_t p = ag_select_parent(t, node);
    if (p < 0)
        return -1;
    int32_t prev = -1;
    int found = 0;
    for (int32_t c = t->nodes[p].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        int32_t e = ag_splittree_chain_end(t, c);
        if (e < 0 || t->nodes[e].kind == AG_NODE_DEAD)
            continue;
        if (found)
            return e; /* the next one */
        if (e == node) {
            if (dir < 0)
                return prev;
            found = 1;
        }
        prev = e;
    }
    return -1;
}

/* The path from the root to node (split nodes left out), root first; *len its length. */
static int32_t *path_of(const ag_splittree *t, int32_t node, size_t *len)
{
    size_t n = 0;
    for (int32_t v = node; v >= 0; v = ag_select_parent(t, v))
        n++;
    int32_t *p = malloc((n + 1) * sizeof *p);
    if (!p)
        return NULL;
    size_t i = n;
    for (int32_t v = node; v >= 0; v = ag_select_parent(t, v))
        p[--i] = v;
    *len = n;
    return p;
}

/* A node's label at the rule level: its rule, a pattern's rule marked as a pattern, the root;
 * a node without a rule is its own label. */
static int64_t rule_label(const ag_splittree *t, int32_t v)
{
    const ag_tnode *n = &t->nodes[v];
    if (n->kind == AG_NODE_ROOT)
        return 0;
    if (n->kind == AG_NODE_PATTERN && n->pattern >= 0 && (size_t)n->pattern < t->npatterns)
        return ((int64_t)2 << 32) | (uint32_t)t->patterns[n->pattern].rule;
    if (n->kind == AG_NODE_COMPONENT && n->rule >= 0)
        return ((int64_t)1 << 32) | (uint32_t)n->rule;
    return ((int64_t)3 << 32) | (uint32_t)v;
}

/* The stacks walked from the root: the deepest level at which every path has a label of the
 * level's intersection. Returns that level, or -1 when even the roots differ. */
static ag_status walk(const ag_splittree *t, const int32_t *sel, size_t nsel, int rule_level,
                      int32_t ***paths_out, size_t **lens_out, long *level, ag_error *err)
{
    if (!nsel || !sel)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the selection is empty");
    for (size_t i = 0; i < nsel; i++)
        if (!live(t, sel[i]))
            return ag_error_set(err, AG_ERR_NOT_FOUND, (long)i + 1,
                                "selection[%zu]: %d is not a node of the tree", i, (int)sel[i]);
    int32_t **paths = calloc(nsel, sizeof *paths);
    size_t *lens = calloc(nsel, sizeof *lens);
    if (!paths || !lens) {
        free(paths);
        free(lens);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t minlen = SIZE_MAX;
    for (size_t i = 0; i < nsel; i++) {
        if (!(paths[i] = path_of(t, sel[i], &lens[i]))) {
            for (size_t k = 0; k < i; k++)
                free(paths[k]);
            free(paths);
            free(lens);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        minlen = lens[i] < minlen ? lens[i] : minlen;
    }
    long last = -1;
    for (size_t d = 0; d < minlen; d++) {
        /* the level's set: labels every path shares (one label per node, so the intersection
         * is the first path's label when all agree, else empty) */
        int64_t l0 = rule_level ? rule_label(t, paths[0][d]) : paths[0][d];
        int same = 1;
        for (size_t i = 1; i < nsel && same; i++)
            same = (rule_level ? rule_label(t, paths[i][d]) : paths[i][d]) == l0;
        if (!same)
            break;
        last = (long)d;
    }
    *paths_out = paths;
    *lens_out = lens;
    *level = last;
    return AG_OK;
}

static void free_paths(int32_t **paths, size_t *lens, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(paths[i]);
    free(paths);
    free(lens);
}

ag_status ag_select_common_tree(const ag_splittree *t, const int32_t *sel, size_t nsel,
                                int32_t *ancestor, ag_error *err)
{
    int32_t **paths = NULL;
    size_t *lens = NULL;
    long level = -1;
    ag_status st = walk(t, sel, nsel, 0, &paths, &lens, &level, err);
    if (st)
        return st;
    *ancestor = level >= 0 ? paths[0][level] : 0;
    free_paths(paths, lens, nsel);
    return AG_OK;
}

ag_status ag_select_common_rule(const ag_splittree *t, const int32_t *sel, size_t nsel,
                                int32_t **nodes, size_t *n, ag_error *err)
{
    *nodes = NULL;
    *n = 0;
    int32_t **paths = NULL;
    size_t *lens = NULL;
    long level = -1;
    ag_status st = walk(t, sel, nsel, 1, &paths, &lens, &level, err);
    if (st)
        return st;
    size_t cap = 0;
    for (size_t i = 0; i < nsel && !st; i++) {
        int32_t v = level >= 0 ? paths[i][level] : 0;
        int dup = 0;
        for (size_t k = 0; k < *n && !dup; k++)
            dup = (*nodes)[k] == v;
        if (!dup && push(nodes, n, &cap, v))
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    free_paths(paths, lens, nsel);
    if (st) {
        free(*nodes);
        *nodes = NULL;
        *n = 0;
    }
    return st;
}
