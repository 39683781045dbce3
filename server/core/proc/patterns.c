#include "patterns.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int32_t rule;
    uint8_t rot;
    int32_t node;
    int32_t slot; /* the child of the parent the node hangs from */
} inst;

static int cmp_inst(const void *a, const void *b)
{
    const inst *x = a, *y = b;
    if (x->rule != y->rule)
        return x->rule < y->rule ? -1 : 1;
    if (x->rot != y->rot)
        return x->rot < y->rot ? -1 : 1;
    return x->node < y->node ? -1 : x->node > y->node;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Per axis grid fit of the instances' min corners: counts, step, and each instance's index.
 * Returns 1 for a complete grid. */
static int grid_fit(const ag_splittree *t, const inst *g, size_t n, double tol, uint32_t counts[3],
                    double step[3], double origin[3], uint32_t *idx, double *tmp, uint8_t *seen)
{
    for (int a = 0; a < 3; a++) {
        for (size_t i = 0; i < n; i++)
            tmp[i] = t->nodes[g[i].node].box.min[a];
        qsort(tmp, n, sizeof *tmp, cmp_double);
        double lo = tmp[0], d = INFINITY;
        for (size_t i = 1; i < n; i++) {
            double gap = tmp[i] - tmp[i - 1];
            if (gap > tol && gap < d)
                d = gap;
        }
        origin[a] = lo;
        if (!isfinite(d)) {
            counts[a] = 1;
            step[a] = 0;
            for (size_t i = 0; i < n; i++)
                idx[3 * i + a] = 0;
            continue;
        }
        /* refine the step over the whole span so errors do not accumulate */
        double span = tmp[n - 1] - lo;
        double m = floor(span / d + 0.5);
        if (m < 1 || m > 1e6)
            return 0;
        d = span / m;
        counts[a] = (uint32_t)m + 1;
        step[a] = d;
        for (size_t i = 0; i < n; i++) {
            double x = (t->nodes[g[i].node].box.min[a] - lo) / d;
            double r = floor(x + 0.5);
            if (fabs(x - r) * d > tol)
                return 0;
            idx[3 * i + a] = (uint32_t)r;
        }
    }
    size_t cells = (size_t)counts[0] * counts[1] * counts[2];
    if (cells != n)
        return 0;
    memset(seen, 0, n);
    for (size_t i = 0; i < n; i++) {
        size_t c = (idx[3 * i + 2] * (size_t)counts[1] + idx[3 * i + 1]) * counts[0] + idx[3 * i];
        if (c >= n || seen[c])
            return 0;
        seen[c] = 1;
    }
    return 1;
}

static ag_status make_pattern(ag_splittree *t, int32_t parent, const inst *g, size_t n,
                              const uint32_t counts[3], const double step[3], uint8_t *moved)
{
    ag_box b = t->nodes[g[0].node].box;
    for (size_t i = 1; i < n; i++)
        for (int a = 0; a < 3; a++) {
            const ag_box *c = &t->nodes[g[i].node].box;
            if (c->min[a] < b.min[a])
                b.min[a] = c->min[a];
            if (c->max[a] > b.max[a])
                b.max[a] = c->max[a];
        }
    ag_pattern *np = realloc(t->patterns, (t->npatterns + 1) * sizeof *np);
    if (!np)
        return AG_ERR_NOMEM;
    t->patterns = np;
    /* detach the instances' slots from the parent */
    for (size_t i = 0; i < n; i++)
        moved[g[i].slot] = 1;
    int32_t prev = -1;
    ag_tnode *P = &t->nodes[parent];
    for (int32_t s = P->first_child, nx; s >= 0; s = nx) {
        nx = t->nodes[s].next_sibling;
        if (moved[s]) {
            if (prev >= 0)
                t->nodes[prev].next_sibling = nx;
            else
                t->nodes[parent].first_child = nx;
            if (t->nodes[parent].last_child == s)
                t->nodes[parent].last_child = prev;
            for (int32_t k = s; k >= 0 && t->nodes[k].kind == AG_NODE_SPLIT;) {
                int32_t c = t->nodes[k].first_child;
                t->nodes[k].kind = AG_NODE_DEAD;
                k = c;
            }
            moved[s] = 0;
        } else {
            prev = s;
        }
    }
    int32_t pn = ag_splittree_insert(t, parent, &b, AG_NODE_PATTERN);
    if (pn < 0)
        return AG_ERR_NOMEM;
    ag_pattern *p = &t->patterns[t->npatterns];
    p->rule = g[0].rule;
    p->rot = g[0].rot;
    memcpy(p->counts, counts, sizeof p->counts);
    memcpy(p->step, step, sizeof p->step);
    p->node = pn;
    t->nodes[pn].pattern = (int32_t)t->npatterns++;
    t->nodes[pn].first_child = t->nodes[pn].last_child = -1;
    /* members in cell order (x fastest) so the pattern's cells map to them in order */
    for (size_t i = 0; i < n; i++) {
        int32_t v = g[i].node;
        t->nodes[v].octant = 0;
        memset(t->nodes[v].pivot, 0, sizeof t->nodes[v].pivot);
        ag_splittree_attach(t, pn, v);
    }
    return AG_OK;
}

ag_status ag_patterns_find(ag_splittree *t, const ag_patterns_options *opt, ag_error *err)
{
    size_t minn = opt && opt->min_instances ? opt->min_instances : 2;
    if (minn < 2)
        minn = 2;
    size_t N0 = t->nnodes;
    inst *buf = malloc((N0 + 1) * sizeof *buf);
    inst *row = malloc((N0 + 1) * sizeof *row);
    uint32_t *idx = malloc((3 * N0 + 3) * sizeof *idx);
    double *tmp = malloc((N0 + 1) * sizeof *tmp);
    uint8_t *seen = malloc(N0 + 1);
    uint8_t *moved = calloc(2 * N0 + 16, 1); /* indexed by node; new nodes are added at the end */
    ag_status st = AG_ERR_NOMEM;
    if (!buf || !row || !idx || !tmp || !seen || !moved)
        goto done;
    for (size_t pi = 0; pi < N0; pi++) {
        int kind = t->nodes[pi].kind;
        if (kind != AG_NODE_ROOT && kind != AG_NODE_COMPONENT)
            continue;
        size_t n = 0;
        for (int32_t s = t->nodes[pi].first_child; s >= 0; s = t->nodes[s].next_sibling) {
            int32_t e = ag_splittree_chain_end(t, s);
            if (e < 0 || t->nodes[e].kind != AG_NODE_COMPONENT || t->nodes[e].rule < 0 ||
                t->rule_count[t->nodes[e].rule] < minn)
                continue;
            buf[n].rule = t->nodes[e].rule;
            buf[n].rot = t->nodes[e].rule_rot;
            buf[n].node = e;
            buf[n].slot = s;
            n++;
        }
        if (n < minn)
            continue;
        qsort(buf, n, sizeof *buf, cmp_inst);
        for (size_t i = 0, j; i < n; i = j) {
            for (j = i + 1; j < n && buf[j].rule == buf[i].rule && buf[j].rot == buf[i].rot; j++)
                ;
            size_t g = j - i;
            if (g < minn)
                continue;
            uint32_t counts[3];
            double step[3], origin[3];
            if (grid_fit(t, buf + i, g, t->tol, counts, step, origin, idx, tmp, seen)) {
                /* order members by cell */
                inst *sorted = row;
                for (size_t k = 0; k < g; k++) {
                    size_t c = (idx[3 * k + 2] * (size_t)counts[1] + idx[3 * k + 1]) * counts[0] +
                               idx[3 * k];
                    sorted[c] = buf[i + k];
                }
                if ((st = make_pattern(t, (int32_t)pi, sorted, g, counts, step, moved)))
                    goto done;
                continue;
            }
            /* rows: for each axis, instances sharing the other two coordinates */
            int best_axis = -1;
            size_t best_cover = 0;
            for (int a = 0; a < 3; a++) {
                size_t cover = 0;
                uint8_t *taken = seen;
                memset(taken, 0, g);
                for (size_t k = 0; k < g; k++) {
                    if (taken[k])
                        continue;
                    size_t r = 0;
                    for (size_t l = k; l < g; l++) {
                        const ag_box *x = &t->nodes[buf[i + k].node].box,
                                     *y = &t->nodes[buf[i + l].node].box;
                        int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
                        if (!taken[l] && fabs(x->min[b1] - y->min[b1]) <= t->tol &&
                            fabs(x->min[b2] - y->min[b2]) <= t->tol) {
                            taken[l] = 1;
                            r++;
                        }
                    }
                    if (r >= minn)
                        cover += r;
                }
                if (cover > best_cover) {
                    best_cover = cover;
                    best_axis = a;
                }
            }
            if (best_axis < 0)
                continue;
            int a = best_axis, b1 = (a + 1) % 3, b2 = (a + 2) % 3;
            uint8_t *taken = calloc(g, 1);
            if (!taken)
                goto done;
            for (size_t k = 0; k < g; k++) {
                if (taken[k])
                    continue;
                size_t r = 0;
                for (size_t l = k; l < g; l++) {
                    const ag_box *x = &t->nodes[buf[i + k].node].box,
                                 *y = &t->nodes[buf[i + l].node].box;
                    if (!taken[l] && fabs(x->min[b1] - y->min[b1]) <= t->tol &&
                        fabs(x->min[b2] - y->min[b2]) <= t->tol) {
                        taken[l] = 1;
                        row[r++] = buf[i + l];
                    }
                }
                if (r < minn)
                    continue;
                if (!grid_fit(t, row, r, t->tol, counts, step, origin, idx, tmp, seen))
                    continue;
                inst *sorted = malloc(r * sizeof *sorted);
                if (!sorted) {
                    free(taken);
                    goto done;
                }
                for (size_t q = 0; q < r; q++)
                    sorted[idx[3 * q + a]] = row[q];
                st = make_pattern(t, (int32_t)pi, sorted, r, counts, step, moved);
                free(sorted);
                if (st) {
                    free(taken);
                    goto done;
                }
            }
            free(taken);
        }
    }
    st = AG_OK;
done:
    free(buf);
    free(row);
    free(idx);
    free(tmp);
    free(seen);
    free(moved);
    if (st)
        return ag_error_set(err, st, 0, "out of memory while finding patterns");
    return AG_OK;
}
