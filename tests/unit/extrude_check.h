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
#include <unistd.h>

#include "core/mesh.h"

typedef struct {
    uint64_t key;
    uint32_t a, b;
} xc_edge;

static inline int xc_cmp_edge(const void *x, const void *y)
{
    const xc_edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : p->b > q->b;
}

static inline int xc_cmp_u32x3(const void *x, const void *y)
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

static inline int xc_cmp_cell(const void *x, const void *y)
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

static inline uint32_t xc_find(uint32_t *par, uint32_t x)
{
    while (par[x] != x)
        x = par[x] = par[par[x]];
    return x;
}

/* Welds the vertices used by triangles of `component` (-1: all) within tol: id[v] gets the
 * welded id (a representative vertex index). Cells of side tol; vertices in the same or a
 * neighbouring cell closer than tol are one. */
static inline void xc_weld(const ag_mesh *m, long component, double tol, uint32_t *id)
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
static inline int xc_closed_manifold(const ag_mesh *m, long component, double tol, char *why,
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
static inline double xc_seg_dist(double x, double y, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(a[0] + t * dx - x, a[1] + t * dy - y);
}

/* How far the triangles of `component` (-1: all) reach outside the footprint (loops of
 * xy pairs, even-odd inside): 0 when every vertex is inside; also below z0. */
static inline double xc_outside(const ag_mesh *m, long component, const double *const *loops,
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
static inline double xc_top(const ag_mesh *m, long component)
{
    double top = -INFINITY;
    for (size_t t = 0; t < m->ntris; t++)
        if (component < 0 || m->tri_component[t] == (uint32_t)component)
            for (int k = 0; k < 3; k++)
                top = fmax(top, m->pos[3 * m->tri[3 * t + k] + 2]);
    return top;
}

/* --- volume and winding from the triangles alone --------------------------------------- */

/* The corners of triangle t of m about the point o (UTM-sized coordinates keep their
 * digits). */
static inline void xc_corners_about(const ag_mesh *m, size_t t, const double *o, double p[3][3])
{
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            p[k][d] = m->pos[3 * m->tri[3 * t + k] + d] - o[d];
}

/* Volume of the triangles, computed here from the mesh alone. */
static inline double xc_mesh_volume(const ag_mesh *m)
{
    if (!m->ntris)
        return 0;
    const double *o = &m->pos[3 * m->tri[0]];
    double v = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        double p[3][3];
        xc_corners_about(m, t, o, p);
        v += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
             p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
             p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
    }
    return v / 6;
}

/* Solid angle of triangle (a, b, c) seen from the origin (van Oosterom and Strackee). */
static inline double xc_solid_angle(const double a[3], const double b[3], const double c[3])
{
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                 a[2] * (b[0] * c[1] - b[1] * c[0]);
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
    return 2 * atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
}

/* The winding number of the triangles about a point just inside each of them (a hair
 * behind a point near its centre) that is furthest from 1: 1 everywhere for a shell that bounds its
 * solid once; 2 or more where a face of the shell lies inside another part of it (a shell
 * overlapping itself), 0 behind a face with no solid behind it (a fin of two faces back to
 * back, a double-sided sliver): neither shows in welding and counting faces per edge. */
static inline long xc_max_winding(const ag_mesh *m)
{
    if (!m->ntris)
        return 0;
    const double *o = &m->pos[3 * m->tri[0]];
    long worst = 1;
    for (size_t s = 0; s < m->ntris; s++) {
        double p[3][3];
        xc_corners_about(m, s, o, p);
        double u[3], v[3], n[3];
        for (int d = 0; d < 3; d++)
            u[d] = p[1][d] - p[0][d], v[d] = p[2][d] - p[0][d];
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double per = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) +
                     sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
                     sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) +
                          (u[2] - v[2]) * (u[2] - v[2]));
        /* a hair behind a point near the centre (off the thirds where grid-aligned walls
         * pass), well inside the face's inscribed circle (radius len / per); a sliver too
         * thin for that has no inside to probe */
        double eps = fmin(1e-6, 0.01 * len / (per > 0 ? per : 1));
        if (!(eps > 1e-9))
            continue;
        double q[3];
        for (int d = 0; d < 3; d++)
            q[d] = 0.3137 * p[0][d] + 0.3311 * p[1][d] + 0.3552 * p[2][d] - eps * n[d] / len;
        double omega = 0;
        for (size_t t = 0; t < m->ntris; t++) {
            double a[3][3], oq[3] = {o[0] + q[0], o[1] + q[1], o[2] + q[2]};
            xc_corners_about(m, t, oq, a);
            omega += xc_solid_angle(a[0], a[1], a[2]);
        }
        long w = lround(omega / (4 * M_PI));
        if (labs(w - 1) > labs(worst - 1))
            worst = w;
    }
    return worst;
}

/* Area of the intersection of two counter-clockwise triangles in the plane (one clipped by
 * the other's edges). */
static inline double xc_tri_overlap(const double a[3][2], const double b[3][2])
{
    double poly[2][16][2];
    int n = 3, cur = 0;
    for (int i = 0; i < 3; i++)
        poly[0][i][0] = a[i][0], poly[0][i][1] = a[i][1];
    for (int e = 0; e < 3 && n; e++) {
        const double *p = b[e], *q = b[(e + 1) % 3];
        int m = 0;
        for (int i = 0; i < n; i++) {
            const double *s = poly[cur][i], *t = poly[cur][(i + 1) % n];
            double ds = (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0]);
            double dt = (q[0] - p[0]) * (t[1] - p[1]) - (q[1] - p[1]) * (t[0] - p[0]);
            if (ds >= 0 && m < 16)
                poly[1 - cur][m][0] = s[0], poly[1 - cur][m][1] = s[1], m++;
            if (((ds >= 0) != (dt >= 0)) && m < 16) {
                double r = ds / (ds - dt);
                poly[1 - cur][m][0] = s[0] + r * (t[0] - s[0]);
                poly[1 - cur][m][1] = s[1] + r * (t[1] - s[1]);
                m++;
            }
        }
        n = m;
        cur = 1 - cur;
    }
    double area = 0;
    for (int i = 0; i < n; i++)
        area += poly[cur][i][0] * poly[cur][(i + 1) % n][1] - poly[cur][(i + 1) % n][0] * poly[cur][i][1];
    return area / 2;
}

/* Folds of horizontal faces: pairs of an upward and a downward triangle at the same height
 * whose insides overlap by more than min_area (a double-sided sheet the solid is on neither
 * side of; it leaves the edges paired and the volume unchanged, so welding, counting faces
 * per edge and the volume miss it, and probes behind faces see it only where one falls in
 * it). Returns the number of such pairs. */
static inline size_t xc_flat_folds(const ag_mesh *m, double min_area)
{
    if (!m->ntris)
        return 0;
    const double *o = &m->pos[3 * m->tri[0]];
    size_t folds = 0;
    for (size_t s = 0; s < m->ntris; s++) {
        double p[3][3];
        xc_corners_about(m, s, o, p);
        if (p[0][2] != p[1][2] || p[1][2] != p[2][2])
            continue;
        double a[3][2] = {{p[0][0], p[0][1]}, {p[1][0], p[1][1]}, {p[2][0], p[2][1]}};
        double sa = (a[1][0] - a[0][0]) * (a[2][1] - a[0][1]) - (a[2][0] - a[0][0]) * (a[1][1] - a[0][1]);
        if (!(sa > 0))
            continue; /* s: the upward one */
        for (size_t t = 0; t < m->ntris; t++) {
            double q[3][3];
            xc_corners_about(m, t, o, q);
            if (q[0][2] != p[0][2] || q[1][2] != p[0][2] || q[2][2] != p[0][2])
                continue;
            /* the downward one, reversed to counter-clockwise */
            double b[3][2] = {{q[0][0], q[0][1]}, {q[2][0], q[2][1]}, {q[1][0], q[1][1]}};
            double sb = (b[1][0] - b[0][0]) * (b[2][1] - b[0][1]) - (b[2][0] - b[0][0]) * (b[1][1] - b[0][1]);
            if (!(sb > 0))
                continue;
            if (xc_tri_overlap(a, b) > min_area)
                folds++;
        }
    }
    return folds;
}

/* --- generated plans ------------------------------------------------------------------- */

/* A polyomino of cells on a G x G grid (its outer boundary only, counter-clockwise: the
 * cells are grown from the centre and holes are filled), at most max / 2 corners written to
 * xy; rnd gives numbers in [0, 1). Returns its corners. */
static inline size_t xc_polyomino(int G, double cell, double *xy, size_t max,
                                  double (*rnd)(void))
{
    unsigned char in[18][18] = {{0}};
    int cnt = 2 + (int)(rnd() * G * G * 0.5);
    in[G / 2 + 1][G / 2 + 1] = 1;
    for (int k = 1; k < cnt; k++)
        for (int tries = 0; tries < 200; tries++) {
            int x = 1 + (int)(rnd() * G), y = 1 + (int)(rnd() * G);
            if (in[x][y])
                continue;
            /* edge neighbours only, and no cell touching another only at a corner */
            int nb = in[x - 1][y] || in[x + 1][y] || in[x][y - 1] || in[x][y + 1];
            int pinch = (in[x - 1][y - 1] && !in[x - 1][y] && !in[x][y - 1]) ||
                        (in[x + 1][y - 1] && !in[x + 1][y] && !in[x][y - 1]) ||
                        (in[x - 1][y + 1] && !in[x - 1][y] && !in[x][y + 1]) ||
                        (in[x + 1][y + 1] && !in[x + 1][y] && !in[x][y + 1]);
            if (nb && !pinch) {
                in[x][y] = 1;
                break;
            }
        }
    /* walk the outer boundary with the inside on the left, from the lowest-left cell */
    int sx = -1, sy = -1;
    for (int y = 0; y < 18 && sx < 0; y++)
        for (int x = 0; x < 18; x++)
            if (in[x][y]) {
                sx = x, sy = y;
                break;
            }
    int x = sx, y = sy, d = 0; /* at corner (x, y), heading +x along the bottom */
    int dx[4] = {1, 0, -1, 0}, dy[4] = {0, 1, 0, -1};
    size_t n = 0;
    do {
        /* the cells ahead-left and ahead-right of the edge from (x, y) in direction d */
        int nx = x + dx[d], ny = y + dy[d];
        xy[2 * n] = x * cell, xy[2 * n + 1] = y * cell;
        int left, right;
        /* the edge (x,y)->(nx,ny): left cell and right cell */
        switch (d) {
        case 0: left = in[x][y], right = y > 0 ? in[x][y - 1] : 0; break;
        case 1: left = in[x - 1][y], right = in[x][y]; break;
        case 2: left = in[x - 1][y - 1], right = in[x - 1][y]; break;
        default: left = in[x][y - 1], right = in[x - 1][y - 1]; break;
        }
        (void)left;
        (void)right;
        x = nx, y = ny;
        /* next direction: prefer a left turn, then straight, then right */
        int cells[4]; /* the four cells around corner (x, y): ll, lr, ul, ur */
        cells[0] = in[x - 1][y - 1];
        cells[1] = in[x][y - 1];
        cells[2] = in[x - 1][y];
        cells[3] = in[x][y];
        int nd = -1;
        for (int turn = 1; turn >= -1 && nd < 0; turn--) {
            int c = (d + turn + 4) % 4;
            int l, r;
            switch (c) {
            case 0: l = cells[3], r = cells[1]; break;
            case 1: l = cells[2], r = cells[3]; break;
            case 2: l = cells[0], r = cells[2]; break;
            default: l = cells[1], r = cells[0]; break;
            }
            if (l && !r)
                nd = c;
        }
        if (nd < 0)
            return 0;
        if (nd != d)
            n++;
        else
            continue;
        d = nd;
    } while (!(x == sx && y == sy) && n < max / 2);
    return n;
}

/* --- the CGAL oracle (../shared/tools/cgal_skeleton, built into build/oracle) --------------- */

/* The oracle binary, or NULL (with a line saying why, so the caller can skip). */
static inline const char *xc_oracle(void)
{
    static const char *path = AG_REPO_DIR "/build/oracle/cgal_skeleton";
    FILE *f = fopen(path, "rb");
    if (!f) {
        printf("the CGAL oracle %s is absent (make builds it from ../shared/tools/cgal_skeleton "
               "with libcgal-dev and g++): its checks are skipped\n", path);
        return NULL;
    }
    fclose(f);
    return path;
}

typedef struct {
    size_t nloops;
    const double *const *loops; /* outer ring counter-clockwise first, then its holes */
    const size_t *sizes;
} xc_polygon;

/* CGAL's roof of one polygon, read from the oracle's OBJ (y up: x, height, -y): faces as
 * plan polygons with the height of each corner. */
typedef struct {
    size_t nfaces;
    size_t *start; /* nfaces + 1 into pts */
    double *pts;   /* x, y, z per corner */
} xc_roof;

static inline void xc_roof_free(xc_roof *r)
{
    free(r->start);
    free(r->pts);
    memset(r, 0, sizeof *r);
}

static inline int xc_roof_read(const char *path, xc_roof *r)
{
    memset(r, 0, sizeof *r);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    double *v = NULL;
    size_t nv = 0, cv = 0, np = 0, cp = 0, cf = 0;
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (nv == cv) {
                cv = cv ? 2 * cv : 256;
                v = realloc(v, 3 * cv * sizeof *v);
            }
            double x, h, ny;
            sscanf(line + 2, "%lf %lf %lf", &x, &h, &ny);
            v[3 * nv] = x;
            v[3 * nv + 1] = -ny;
            v[3 * nv + 2] = h;
            nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            if (r->nfaces + 2 > cf) {
                cf = cf ? 2 * cf : 64;
                r->start = realloc(r->start, cf * sizeof *r->start);
            }
            if (!r->nfaces)
                r->start[0] = 0;
            char *s = line + 2, *end;
            for (long k; (k = strtol(s, &end, 10)), end != s; s = end) {
                if (np == cp) {
                    cp = cp ? 2 * cp : 256;
                    r->pts = realloc(r->pts, 3 * cp * sizeof *r->pts);
                }
                memcpy(&r->pts[3 * np++], &v[3 * (k - 1)], 3 * sizeof *v);
            }
            r->start[++r->nfaces] = np;
        }
    }
    fclose(f);
    free(v);
    return r->nfaces > 0;
}

/* The height of CGAL's roof over (x, y): the plane of the face whose plan polygon holds
 * it; NAN when none does. */
static inline double xc_roof_height(const xc_roof *r, double x, double y)
{
    for (size_t f = 0; f < r->nfaces; f++) {
        const double *p = &r->pts[3 * r->start[f]];
        size_t n = r->start[f + 1] - r->start[f];
        int in = 0;
        double dmin = INFINITY;
        for (size_t i = 0, j = n - 1; i < n; j = i++) {
            const double *a = &p[3 * j], *b = &p[3 * i];
            if ((b[1] > y) != (a[1] > y) &&
                x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
                in = !in;
            double ab[2] = {a[0], a[1]}, bb[2] = {b[0], b[1]};
            dmin = fmin(dmin, xc_seg_dist(x, y, ab, bb));
        }
        if (!in && dmin > 2e-6) /* the oracle writes 6 decimals */
            continue;
        /* the face's plane through its corners, by least squares on z = ax + by + c */
        double S[3][3] = {{0}}, B[3] = {0};
        for (size_t i = 0; i < n; i++) {
            double row[3] = {p[3 * i] - p[0], p[3 * i + 1] - p[1], 1};
            for (int a = 0; a < 3; a++) {
                B[a] += row[a] * p[3 * i + 2];
                for (int b = 0; b < 3; b++)
                    S[a][b] += row[a] * row[b];
            }
        }
        double det = S[0][0] * (S[1][1] * S[2][2] - S[1][2] * S[2][1]) -
                     S[0][1] * (S[1][0] * S[2][2] - S[1][2] * S[2][0]) +
                     S[0][2] * (S[1][0] * S[2][1] - S[1][1] * S[2][0]);
        if (!(fabs(det) > 0))
            continue;
        double sol[3];
        for (int c = 0; c < 3; c++) {
            double M[3][3];
            memcpy(M, S, sizeof M);
            for (int a = 0; a < 3; a++)
                M[a][c] = B[a];
            sol[c] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                      M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                      M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
        }
        return sol[0] * (x - p[0]) + sol[1] * (y - p[1]) + sol[2];
    }
    return NAN;
}

/* CGAL's highest offset time (the 45° roof's rise) of each polygon, into rise[]; NAN where
 * CGAL did not build it. With objdir, CGAL also writes each roof to objdir/p<i>.obj.
 * Returns 0 when the oracle could not be run. */
static inline int xc_cgal_run(const char *oracle, const xc_polygon *p, size_t n, double *rise,
                       const char *objdir)
{
    const char *dir = getenv("TMPDIR");
    char path[512];
    snprintf(path, sizeof path, "%s/ag_oracle_XXXXXX", dir && dir[0] ? dir : P_tmpdir);
    int fd = mkstemp(path);
    if (fd < 0)
        return 0;
    FILE *f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        remove(path);
        return 0;
    }
    for (size_t i = 0; i < n; i++) {
        rise[i] = NAN;
        fprintf(f, "P p%zu\n", i);
        for (size_t l = 0; l < p[i].nloops; l++) {
            fprintf(f, "L %zu\n", p[i].sizes[l]);
            for (size_t k = 0; k < p[i].sizes[l]; k++)
                fprintf(f, "%.17g %.17g 45\n", p[i].loops[l][2 * k], p[i].loops[l][2 * k + 1]);
        }
        fprintf(f, "E\n");
    }
    fclose(f);
    char cmd[1200];
    if (objdir)
        snprintf(cmd, sizeof cmd, "'%s' --obj '%s' '%s'", oracle, objdir, path);
    else
        snprintf(cmd, sizeof cmd, "'%s' '%s'", oracle, path);
    FILE *pp = popen(cmd, "r");
    if (!pp) {
        remove(path);
        return 0;
    }
    char line[512];
    while (fgets(line, sizeof line, pp)) {
        size_t k;
        char status[64];
        double h;
        if (sscanf(line, "p%zu,%*[^,],%*[^,],%*[^,],%*[^,],%*[^,],%63[^,],%lf", &k, status, &h) == 3 &&
            k < n && strcmp(status, "ok") == 0)
            rise[k] = h;
    }
    int rc = pclose(pp);
    remove(path);
    return rc == 0;
}

static inline int xc_cgal_rises(const char *oracle, const xc_polygon *p, size_t n, double *rise)
{
    return xc_cgal_run(oracle, p, n, rise, NULL);
}

#endif
