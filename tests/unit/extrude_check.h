/* Independent checks of extruded buildings for the extrusion tests: they look only at the
 * triangles a building became, never at the shell's or the batch's own verdict.
 *
 * - closed 2-manifold: vertices welded on a hash grid, every directed edge used exactly
 *   once and its reverse exactly once, no two triangles on the same three vertices (a
 *   zero-area double-sided sliver passes the edge count but not this), no triangle of
 *   zero area whose edges are not shared by a neighbour with area (checked through the
 *   edge count);
 * - containment: every vertex within `margin` of the footprint (inside, or that close to
 *   its boundary) and not below the ground;
 * - the rise: the highest vertex.
 *
 * Header-only (static functions) so every extrusion test can include it. */
#ifndef AG_TEST_EXTRUDE_CHECK_H
#define AG_TEST_EXTRUDE_CHECK_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh.h"

typedef struct {
    uint64_t key;
    uint32_t a, b;
} xc_edge;

static int xc_cmp_edge(const void *x, const void *y)
{
    const xc_edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : p->b > q->b;
}

static int xc_cmp_u32x3(const void *x, const void *y)
{
    const uint32_t *p = x, *q = y;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

typedef struct {
    int64_t cx, cy, cz;
    uint32_t v;
} xc_cell;

static int xc_cmp_cell(const void *x, const void *y)
{
    const xc_cell *p = x, *q = y;
    if (p->cx != q->cx)
        return p->cx < q->cx ? -1 : 1;
    if (p->cy != q->cy)
        return p->cy < q->cy ? -1 : 1;
    if (p->cz != q->cz)
        return p->cz < q->cz ? -1 : 1;
    return p->v < q->v ? -1 : p->v > q->v;
}

static uint32_t xc_find(uint32_t *par, uint32_t x)
{
    while (par[x] != x)
        x = par[x] = par[par[x]];
    return x;
}

/* Welds the vertices used by triangles of `component` (-1: all) within tol: id[v] gets the
 * welded id (a representative vertex index). Cells of side tol; vertices in the same or a
 * neighbouring cell closer than tol are one. */
static void xc_weld(const ag_mesh *m, long component, double tol, uint32_t *id)
{
    size_t n = m->nverts;
    xc_cell *c = malloc((n ? n : 1) * sizeof *c);
    uint32_t *par = malloc((n ? n : 1) * sizeof *par);
    uint8_t *used = calloc(n ? n : 1, 1);
    for (size_t t = 0; t < m->ntris; t++)
        if (component < 0 || m->tri_component[t] == (uint32_t)component)
            for (int k = 0; k < 3; k++)
                used[m->tri[3 * t + k]] = 1;
    size_t nc = 0;
    for (size_t v = 0; v < n; v++) {
        par[v] = (uint32_t)v;
        if (!used[v])
            continue;
        const double *p = &m->pos[3 * v];
        c[nc].cx = (int64_t)floor(p[0] / tol);
        c[nc].cy = (int64_t)floor(p[1] / tol);
        c[nc].cz = (int64_t)floor(p[2] / tol);
        c[nc].v = (uint32_t)v;
        nc++;
    }
    qsort(c, nc, sizeof *c, xc_cmp_cell);
    for (size_t i = 0; i < nc; i++) {
        for (int dx = -1; dx <= 1; dx++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dz = -1; dz <= 1; dz++) {
                    xc_cell key = {c[i].cx + dx, c[i].cy + dy, c[i].cz + dz, 0};
                    size_t lo = 0, hi = nc;
                    while (lo < hi) {
                        size_t mid = (lo + hi) / 2;
                        if (xc_cmp_cell(&c[mid], &key) < 0)
                            lo = mid + 1;
                        else
                            hi = mid;
                    }
                    for (size_t j = lo; j < nc && c[j].cx == key.cx && c[j].cy == key.cy &&
                                        c[j].cz == key.cz;
                         j++) {
                        const double *p = &m->pos[3 * c[i].v], *q = &m->pos[3 * c[j].v];
                        double d = sqrt((p[0] - q[0]) * (p[0] - q[0]) +
                                        (p[1] - q[1]) * (p[1] - q[1]) +
                                        (p[2] - q[2]) * (p[2] - q[2]));
                        if (d <= tol) {
                            uint32_t a = xc_find(par, c[i].v), b = xc_find(par, c[j].v);
                            if (a != b)
                                par[a > b ? a : b] = a < b ? a : b;
                        }
                    }
                }
    }
    for (size_t v = 0; v < n; v++)
        id[v] = xc_find(par, (uint32_t)v);
    free(c);
    free(par);
    free(used);
}

/* 1 when the triangles of `component` (-1: all) form a closed 2-manifold after welding
 * at tol; else 0 with the first reason in why. */
static int xc_closed_manifold(const ag_mesh *m, long component, double tol, char *why,
                              size_t nwhy)
{
    uint32_t *id = malloc((m->nverts ? m->nverts : 1) * sizeof *id);
    xc_weld(m, component, tol, id);
    size_t nt = 0;
    for (size_t t = 0; t < m->ntris; t++)
        nt += component < 0 || m->tri_component[t] == (uint32_t)component;
    xc_edge *e = malloc((3 * nt + 1) * sizeof *e);
    uint32_t *tv = malloc((3 * nt + 1) * sizeof *tv);
    size_t ne = 0, ntv = 0;
    int ok = 1;
    if (why && nwhy)
        why[0] = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        if (!(component < 0 || m->tri_component[t] == (uint32_t)component))
            continue;
        uint32_t v[3];
        for (int k = 0; k < 3; k++)
            v[k] = id[m->tri[3 * t + k]];
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue; /* collapsed by the weld: no edges of its own */
        for (int k = 0; k < 3; k++) {
            e[ne].a = v[k];
            e[ne].b = v[(k + 1) % 3];
            ne++;
        }
        /* sorted vertex triple: two triangles on the same three vertices are a sliver */
        uint32_t s0 = v[0], s1 = v[1], s2 = v[2], tmp;
        if (s0 > s1) { tmp = s0; s0 = s1; s1 = tmp; }
        if (s1 > s2) { tmp = s1; s1 = s2; s2 = tmp; }
        if (s0 > s1) { tmp = s0; s0 = s1; s1 = tmp; }
        tv[3 * ntv] = s0;
        tv[3 * ntv + 1] = s1;
        tv[3 * ntv + 2] = s2;
        ntv++;
    }
    if (!ne) {
        ok = 0;
        if (why)
            snprintf(why, nwhy, "no triangles");
    }
    qsort(e, ne, sizeof *e, xc_cmp_edge);
    for (size_t i = 0; i < ne && ok; i++) {
        if (i + 1 < ne && e[i + 1].a == e[i].a && e[i + 1].b == e[i].b) {
            ok = 0;
            if (why)
                snprintf(why, nwhy, "directed edge %u-%u used more than once", e[i].a, e[i].b);
            break;
        }
        xc_edge key = {0, e[i].b, e[i].a};
        xc_edge *r = bsearch(&key, e, ne, sizeof *e, xc_cmp_edge);
        if (!r) {
            ok = 0;
            if (why)
                snprintf(why, nwhy, "directed edge %u-%u has no reverse (open)", e[i].a, e[i].b);
        }
    }
    qsort(tv, ntv, 3 * sizeof *tv, xc_cmp_u32x3);
    for (size_t i = 0; i + 1 < ntv && ok; i++)
        if (xc_cmp_u32x3(&tv[3 * i], &tv[3 * i + 3]) == 0) {
            ok = 0;
            if (why)
                snprintf(why, nwhy, "two triangles on vertices %u %u %u (a double-sided sliver)",
                         tv[3 * i], tv[3 * i + 1], tv[3 * i + 2]);
        }
    free(id);
    free(e);
    free(tv);
    return ok;
}

/* Distance from (x, y) to the segment a-b. */
static double xc_seg_dist(double x, double y, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(a[0] + t * dx - x, a[1] + t * dy - y);
}

/* How far the triangles of `component` (-1: all) reach outside the footprint (loops of
 * xy pairs, even-odd inside): 0 when every vertex is inside; also below z0. */
static double xc_outside(const ag_mesh *m, long component, const double *const *loops,
                         const size_t *sizes, size_t nloops, double z0)
{
    double worst = 0;
    uint8_t *used = calloc(m->nverts ? m->nverts : 1, 1);
    for (size_t t = 0; t < m->ntris; t++)
        if (component < 0 || m->tri_component[t] == (uint32_t)component)
            for (int k = 0; k < 3; k++)
                used[m->tri[3 * t + k]] = 1;
    for (size_t v = 0; v < m->nverts; v++) {
        if (!used[v])
            continue;
        const double *p = &m->pos[3 * v];
        if (p[2] < z0)
            worst = fmax(worst, z0 - p[2]);
        int in = 0;
        double dmin = INFINITY;
        for (size_t l = 0; l < nloops; l++) {
            const double *xy = loops[l];
            size_t n = sizes[l];
            for (size_t i = 0, j = n - 1; i < n; j = i++) {
                if ((xy[2 * i + 1] > p[1]) != (xy[2 * j + 1] > p[1]) &&
                    p[0] < xy[2 * j] + (p[1] - xy[2 * j + 1]) * (xy[2 * i] - xy[2 * j]) /
                                           (xy[2 * i + 1] - xy[2 * j + 1]))
                    in = !in;
                dmin = fmin(dmin, xc_seg_dist(p[0], p[1], &xy[2 * j], &xy[2 * i]));
            }
        }
        if (!in)
            worst = fmax(worst, dmin);
    }
    free(used);
    return worst;
}

/* Highest z of the triangles of `component` (-1: all). */
static double xc_top(const ag_mesh *m, long component)
{
    double top = -INFINITY;
    for (size_t t = 0; t < m->ntris; t++)
        if (component < 0 || m->tri_component[t] == (uint32_t)component)
            for (int k = 0; k < 3; k++)
                top = fmax(top, m->pos[3 * m->tri[3 * t + k] + 2]);
    return top;
}

#endif
