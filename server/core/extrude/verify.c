#include "verify.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/search.h"
#include "keysort.h"
#include "weld_points.h"
#include "../base/tolerance.h"

/* How far outwards profile p leads (m, >= 0) and, when its last segment leans inwards,
 * the height it rises per metre it moves in (0: it does not). */
static void profile_reach(const ag_profile *p, double cap, double *out, double *rise)
{
    double o = 0;
    for (size_t i = 0; i < p->npoints; i++)
        o = fmax(o, -p->points[i].w);
    const ag_profile_point *a = &p->points[p->npoints - 2], *b = &p->points[p->npoints - 1];
    double slope = (b->w - a->w) / (b->z - a->z);
    if (slope < 0 && cap > b->z)
        o = fmax(o, -(b->w + slope * (cap - b->z)));
    *out = o;
    *rise = slope > 0 ? 1 / slope : 0;
}

void ag_verify_reach(const ag_plan *plan, double *outwards, double *height)
{
    double prof_out = 0, rise = 0, top = 0;
    for (size_t i = 0; i < plan->nprofiles; i++) {
        double o, r;
        const ag_profile *p = &plan->profiles[i];
        profile_reach(p, plan->cap_height, &o, &r);
        prof_out = fmax(prof_out, o);
        rise = fmax(rise, r);
        top = fmax(top, p->points[p->npoints - 1].z);
    }
    /* profiles of steps and offsets count from their heights, and add to each other */
    double out = prof_out, base = 0;
    for (size_t k = 0; k < plan->noffsets; k++) {
        const ag_plan_offset *o = &plan->offsets[k];
        double w = fmax(o->outside, 0);
        for (size_t e = 0; e < o->nedges; e++)
            if (o->edges[e].has_outside)
                w = fmax(w, o->edges[e].outside);
        out += w + prof_out;
        base = fmax(base, o->z);
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        const ag_plan_step *s = &plan->steps[k];
        double w = s->depth > 0 ? s->depth : 0;
        if (s->npoints && !s->plan_frame)
            for (size_t i = 0; i < s->npoints; i++)
                w = fmax(w, hypot(s->points[2 * i], s->points[2 * i + 1]));
        out += w + prof_out;
        base = fmax(base, s->at.z);
    }
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t L = 0; L < plan->nloops; L++)
        for (size_t i = 0; i < plan->loops[L].n; i++)
            for (int k = 0; k < 2; k++) {
                lo[k] = fmin(lo[k], plan->loops[L].xy[2 * i + k]);
                hi[k] = fmax(hi[k], plan->loops[L].xy[2 * i + k]);
            }
    double extent = plan->nloops ? hypot(hi[0] - lo[0], hi[1] - lo[1]) : 0;
    *outwards = out;
    *height = plan->cap_height > 0 ? plan->cap_height
                                   : base + top + (extent + 2 * out) * rise;
}

/* --- closed 2-manifold -------------------------------------------------------------------- */

/* Welded ids of the vertices the triangles use. */
static int weld(const ag_mesh *m, size_t t0, size_t t1, double tol, uint32_t *id,
                ag_keyed *vs)
{
    size_t nv = 0;
    for (size_t t = t0; t < t1; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->tri[3 * t + k];
            id[v] = v;
            vs[nv++] = (ag_keyed){ag_keysort_double(m->pos[3 * v]), v};
        }
    return ag_weld_points(m->pos, vs, nv, tol, id) == AG_OK;
}

/* Index of key in sorted e[0..n), or n. */
static size_t find_key(const ag_keyed *e, size_t n, uint64_t key)
{
    size_t lo = ag_search_lower_u64(&e->key, n, sizeof *e, key);
    return lo < n && e[lo].key == key ? lo : n;
}

static int closed_manifold(const ag_mesh *m, size_t t0, size_t t1, double tol, char *why,
                           size_t nwhy)
{
    size_t nt = t1 - t0;
    uint32_t *id = malloc((m->nverts ? m->nverts : 1) * sizeof *id);
    ag_keyed *e = malloc((3 * nt + 1) * sizeof *e);
    ag_keyed *tv = malloc((nt + 1) * sizeof *tv);
    int ok = id && e && tv && weld(m, t0, t1, tol, id, e);
    if (!ok)
        snprintf(why, nwhy, "out of memory checking the building");
    size_t ne = 0, ntv = 0;
    for (size_t t = t0; ok && t < t1; t++) {
        uint32_t v[3] = {id[m->tri[3 * t]], id[m->tri[3 * t + 1]], id[m->tri[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue; /* shorter than the weld tolerance: no edges of its own */
        for (int k = 0; k < 3; k++)
            e[ne++] = (ag_keyed){(uint64_t)v[k] << 32 | v[(k + 1) % 3], (uint32_t)t};
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2 - a; b++)
                if (v[b] > v[b + 1]) {
                    uint32_t x = v[b];
                    v[b] = v[b + 1];
                    v[b + 1] = x;
                }
        /* the triple sorted: the two smallest as the key, the largest as the value */
        tv[ntv++] = (ag_keyed){(uint64_t)v[0] << 32 | v[1], v[2]};
    }
    if (ok && !ne) {
        ok = 0;
        snprintf(why, nwhy, "the building has no triangles");
    }
    if (ok && ag_keysort(e, ne, NULL) != AG_OK) {
        ok = 0;
        snprintf(why, nwhy, "out of memory checking the building");
    }
    for (size_t i = 0; ok && i < ne; i++) {
        if (i + 1 < ne && e[i].key == e[i + 1].key) {
            ok = 0;
            const double *p = &m->pos[3 * (e[i].key >> 32)];
            snprintf(why, nwhy, "an edge at (%.3f, %.3f, %.3f) is shared by more than two faces "
                     "(not a closed 2-manifold)", p[0], p[1], p[2]);
            break;
        }
        uint64_t rev = (e[i].key << 32) | (e[i].key >> 32);
        if (find_key(e, ne, rev) == ne) {
            ok = 0;
            const double *p = &m->pos[3 * (e[i].key >> 32)];
            snprintf(why, nwhy, "the building is open at an edge from (%.3f, %.3f, %.3f)", p[0],
                     p[1], p[2]);
        }
    }
    if (ok) {
        /* by the two smallest vertices; a run of equal keys holds the largest ones */
        ok = ag_keysort(tv, ntv, NULL) == AG_OK;
        if (!ok)
            snprintf(why, nwhy, "out of memory checking the building");
        for (size_t i = 0; ok && i < ntv; i++)
            for (size_t j = i + 1; ok && j < ntv && tv[j].key == tv[i].key; j++)
                if (tv[j].val == tv[i].val) {
                    ok = 0;
                    const double *p = &m->pos[3 * (tv[i].key >> 32)];
                    snprintf(why, nwhy, "two faces lie on each other near (%.3f, %.3f, %.3f) "
                             "(a double-sided sliver)", p[0], p[1], p[2]);
                }
    }
    free(id);
    free(e);
    free(tv);
    return ok;
}

/* --- within reach of the footprint ------------------------------------------------------- */

static double seg_dist2(double x, double y, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double ex = a[0] + t * dx - x, ey = a[1] + t * dy - y;
    return ex * ex + ey * ey;
}

static int inside_ring(const double *xy, size_t n, double x, double y)
{
    int in = 0;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double *a = &xy[2 * j], *b = &xy[2 * i];
        if ((b[1] > y) != (a[1] > y) && x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
            in = !in;
    }
    return in;
}

/* Is (x, y) within `allowed` of the union of the loops (even-odd) and the plan-frame
 * forced polygons (each alone)? *dist gets the distance when it is not. */
static int within(const ag_plan *plan, double x, double y, double allowed, double *dist)
{
    int in = 0;
    double d2 = INFINITY, a2 = allowed * allowed;
    for (size_t L = 0; L < plan->nloops; L++) {
        const ag_plan_loop *l = &plan->loops[L];
        in ^= inside_ring(l->xy, l->n, x, y);
    }
    if (in)
        return 1;
    for (size_t L = 0; L < plan->nloops; L++) {
        const ag_plan_loop *l = &plan->loops[L];
        for (size_t i = 0, j = l->n - 1; i < l->n; j = i++) {
            d2 = fmin(d2, seg_dist2(x, y, &l->xy[2 * j], &l->xy[2 * i]));
            if (d2 <= a2)
                return 1;
        }
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        const ag_plan_step *s = &plan->steps[k];
        if (!s->npoints || !s->plan_frame)
            continue;
        if (inside_ring(s->points, s->npoints, x, y))
            return 1;
        for (size_t i = 0, j = s->npoints - 1; i < s->npoints; j = i++)
            d2 = fmin(d2, seg_dist2(x, y, &s->points[2 * j], &s->points[2 * i]));
        if (d2 <= a2)
            return 1;
    }
    *dist = sqrt(d2);
    return 0;
}


/* --- a shell that overlaps itself ---------------------------------------------------------
 * A closed 2-manifold can still pass through itself (two parts of a roof swept over each
 * other): the edge counts do not see it, the winding number does. Just inside each face
 * the shell must wind once; it winds twice where that face lies inside another part. The
 * winding number about q is counted along a ray from q: +1 for each face it leaves
 * through, -1 for each it enters through. The rays lean off the vertical by amounts no
 * plan of whole or decimal metres lines up with, so a ray meets no edge or corner of a
 * grid-aligned roof exactly; a probe counts as overlapping only when two rays of
 * different leans agree, so a graze within rounding of an edge cannot make a defect. */

/* Faces whose inscribed circle is so small that the probe would lie closer than this
 * (relative to the building's size) are slivers with no inside to probe. */
#define AG_VERIFY_WINDING_THIN 1e-10

typedef struct {
    double a[3], e1[3], e2[3]; /* a corner and the two edges from it (about the origin o) */
    double lo[2], hi[2], zhi;
} vtri;

static void cross3(const double *u, const double *v, double *w)
{
    w[0] = u[1] * v[2] - u[2] * v[1];
    w[1] = u[2] * v[0] - u[0] * v[2];
    w[2] = u[0] * v[1] - u[1] * v[0];
}

static double dot3(const double *u, const double *v)
{
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
}

/* The faces in cells of the plan, so that a ray, which leans little, meets only the faces
 * over the few cells it passes (a building of 12,000 triangles would otherwise test every
 * face for every probe). Faces over more cells than VGRID_MAX_CELLS are kept in a list
 * every ray tests. */
#define VGRID_MAX_CELLS 16

typedef struct {
    double x0, y0, cell;
    size_t nx, ny;
    uint32_t *start; /* nx * ny + 1 offsets into items */
    uint32_t *items;
    uint32_t *big;
    size_t nbig;
    uint32_t *seen; /* the query that last took each face */
    uint32_t query;
    uint32_t *cand; /* one query's faces */
    double zmax;
} vgrid;

static void vgrid_free(vgrid *g)
{
    free(g->start);
    free(g->items);
    free(g->big);
    free(g->seen);
    free(g->cand);
}

/* Cell f clamped to [0, n) (a NaN to 0). */
static size_t vgrid_index(double f, size_t n)
{
    if (!(f >= 0))
        return 0;
    return f < (double)n ? (size_t)f : n - 1;
}

static void vgrid_cells(const vgrid *g, double lo_x, double lo_y, double hi_x, double hi_y,
                        size_t *ix0, size_t *iy0, size_t *ix1, size_t *iy1)
{
    *ix0 = vgrid_index(floor((lo_x - g->x0) / g->cell), g->nx);
    *iy0 = vgrid_index(floor((lo_y - g->y0) / g->cell), g->ny);
    *ix1 = vgrid_index(floor((hi_x - g->x0) / g->cell), g->nx);
    *iy1 = vgrid_index(floor((hi_y - g->y0) / g->cell), g->ny);
}

static int vgrid_build(vgrid *g, const vtri *T, size_t n)
{
    memset(g, 0, sizeof *g);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    g->zmax = -INFINITY;
    for (size_t t = 0; t < n; t++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], T[t].lo[d]);
            hi[d] = fmax(hi[d], T[t].hi[d]);
            g->zmax = fmax(g->zmax, T[t].zhi);
        }
    double side = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    size_t cells = (size_t)ceil(sqrt((double)n)) + 1;
    int finite = isfinite(side) && isfinite(lo[0]) && isfinite(lo[1]);
    g->cell = finite && side > 0 ? side / (double)cells : 1;
    g->x0 = finite ? lo[0] : 0;
    g->y0 = finite ? lo[1] : 0;
    g->nx = finite ? vgrid_index((hi[0] - lo[0]) / g->cell, cells + 1) + 1 : 1;
    g->ny = finite ? vgrid_index((hi[1] - lo[1]) / g->cell, cells + 1) + 1 : 1;
    g->start = calloc(g->nx * g->ny + 1, sizeof *g->start);
    g->big = malloc((n ? n : 1) * sizeof *g->big);
    g->seen = calloc(n ? n : 1, sizeof *g->seen);
    g->cand = malloc((n ? n : 1) * sizeof *g->cand);
    if (!g->start || !g->big || !g->seen || !g->cand)
        return 0;
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < n; t++) {
            size_t ix0, iy0, ix1, iy1;
            vgrid_cells(g, T[t].lo[0], T[t].lo[1], T[t].hi[0], T[t].hi[1], &ix0, &iy0, &ix1,
                        &iy1);
            if ((ix1 - ix0 + 1) * (iy1 - iy0 + 1) > VGRID_MAX_CELLS) {
                if (pass == 0)
                    g->big[g->nbig++] = (uint32_t)t;
                continue;
            }
            for (size_t iy = iy0; iy <= iy1; iy++)
                for (size_t ix = ix0; ix <= ix1; ix++) {
                    size_t c = iy * g->nx + ix;
                    if (pass == 0)
                        g->start[c + 1]++;
                    else
                        g->items[g->start[c]++] = (uint32_t)t;
                }
        }
        if (pass == 0) {
            for (size_t c = 0; c < g->nx * g->ny; c++)
                g->start[c + 1] += g->start[c];
            total = g->start[g->nx * g->ny];
            g->items = malloc((total ? total : 1) * sizeof *g->items);
            if (!g->items)
                return 0;
        }
    }
    /* the fill moved each start to the next cell's: move them back */
    for (size_t c = g->nx * g->ny; c > 0; c--)
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    return 1;
}

/* The faces a ray from q along (dx, dy, 1) may meet, into g->cand; their number. */
static size_t vgrid_query(vgrid *g, const double *q, double dx, double dy)
{
    double rise = fmax(0, g->zmax - q[2]);
    double ex = q[0] + rise * dx, ey = q[1] + rise * dy;
    size_t ix0, iy0, ix1, iy1, n = 0;
    vgrid_cells(g, fmin(q[0], ex), fmin(q[1], ey), fmax(q[0], ex), fmax(q[1], ey), &ix0, &iy0,
                &ix1, &iy1);
    g->query++;
    for (size_t iy = iy0; iy <= iy1; iy++)
        for (size_t ix = ix0; ix <= ix1; ix++) {
            size_t c = iy * g->nx + ix;
            for (uint32_t k = g->start[c]; k < g->start[c + 1]; k++) {
                uint32_t t = g->items[k];
                if (g->seen[t] != g->query) {
                    g->seen[t] = g->query;
                    g->cand[n++] = t;
                }
            }
        }
    for (size_t k = 0; k < g->nbig; k++)
        g->cand[n++] = g->big[k];
    return n;
}

/* Winding number of the faces about q along the ray q + t (dx, dy, 1), t > 0. */
static long winding_along(const vtri *T, vgrid *g, const double *q, double dx, double dy)
{
    const double d[3] = {dx, dy, 1};
    long w = 0;
    size_t n = vgrid_query(g, q, dx, dy);
    for (size_t k = 0; k < n; k++) {
        const vtri *f = &T[g->cand[k]];
        if (f->zhi < q[2])
            continue;
        /* where the ray is while it is below the face's top */
        double rise = f->zhi - q[2];
        double x0 = q[0], x1 = q[0] + rise * dx, y0 = q[1], y1 = q[1] + rise * dy;
        if (fmax(x0, x1) < f->lo[0] || fmin(x0, x1) > f->hi[0] || fmax(y0, y1) < f->lo[1] ||
            fmin(y0, y1) > f->hi[1])
            continue;
        /* Moller-Trumbore */
        double p[3], s[3], qv[3];
        cross3(d, f->e2, p);
        double det = dot3(f->e1, p);
        if (det == 0)
            continue;
        for (int i = 0; i < 3; i++)
            s[i] = q[i] - f->a[i];
        double u = dot3(s, p) / det;
        if (u < 0 || u > 1)
            continue;
        cross3(s, f->e1, qv);
        double v = dot3(d, qv) / det;
        if (v < 0 || u + v > 1)
            continue;
        if (dot3(f->e2, qv) / det <= 0)
            continue;
        double nrm[3];
        cross3(f->e1, f->e2, nrm);
        w += dot3(nrm, d) > 0 ? 1 : -1;
    }
    return w;
}

/* The winding number at q, `eps` behind the middle of face f (normal nrm of length len),
 * along two rays of different leans; 1 when they disagree (a graze within rounding). */
static long probe_winding(const vtri *T, vgrid *g, const vtri *f, const double *nrm,
                          double len, double eps, double *q)
{
    for (int d = 0; d < 3; d++)
        q[d] = f->a[d] + 0.3311 * f->e1[d] + 0.3552 * f->e2[d] - eps * nrm[d] / len;
    long w = winding_along(T, g, q, 0.0123456789, 0.00713286);
    return w != 1 && winding_along(T, g, q, -0.00871234, 0.0151112) == w ? w : 1;
}

/* 1 when the shell winds once just inside each of its faces; else 0 with why. */
static int winds_once(const ag_mesh *m, size_t t0, size_t t1, double tol, double size,
                      char *why, size_t nwhy)
{
    size_t nt = t1 - t0, n = 0;
    vtri *T = malloc((nt ? nt : 1) * sizeof *T);
    uint32_t *id = malloc((m->nverts ? m->nverts : 1) * sizeof *id);
    ag_keyed *e = malloc((3 * nt + 1) * sizeof *e);
    if (!T || !id || !e || !weld(m, t0, t1, tol, id, e)) {
        free(T);
        free(id);
        free(e);
        snprintf(why, nwhy, "out of memory checking the building");
        return 0;
    }
    free(e);
    /* welded corners: faces that share an edge share its points exactly, so no ray slips
     * between them */
    const double *o = &m->pos[3 * id[m->tri[3 * t0]]];
    for (size_t t = t0; t < t1; t++) {
        uint32_t v[3] = {id[m->tri[3 * t]], id[m->tri[3 * t + 1]], id[m->tri[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue;
        vtri *f = &T[n++];
        double p[3][3];
        for (int c = 0; c < 3; c++)
            for (int d = 0; d < 3; d++)
                p[c][d] = m->pos[3 * v[c] + d] - o[d];
        for (int d = 0; d < 3; d++) {
            f->a[d] = p[0][d];
            f->e1[d] = p[1][d] - p[0][d];
            f->e2[d] = p[2][d] - p[0][d];
        }
        for (int d = 0; d < 2; d++) {
            f->lo[d] = fmin(p[0][d], fmin(p[1][d], p[2][d]));
            f->hi[d] = fmax(p[0][d], fmax(p[1][d], p[2][d]));
        }
        f->zhi = fmax(p[0][2], fmax(p[1][2], p[2][2]));
    }
    vgrid g;
    int ok = vgrid_build(&g, T, n);
    if (!ok)
        snprintf(why, nwhy, "out of memory checking the building");
    for (size_t t = 0; t < n && ok; t++) {
        const vtri *f = &T[t];
        double nrm[3];
        cross3(f->e1, f->e2, nrm);
        double len = sqrt(dot3(nrm, nrm));
        double e3[3] = {f->e2[0] - f->e1[0], f->e2[1] - f->e1[1], f->e2[2] - f->e1[2]};
        double per = sqrt(dot3(f->e1, f->e1)) + sqrt(dot3(f->e2, f->e2)) + sqrt(dot3(e3, e3));
        /* the probe: a hair behind a point near the centre (weights no grid of whole or
         * decimal metres lines up with), well within the face's inscribed circle (len /
         * per is its radius) and far above rounding */
        double eps = fmin(AG_VERIFY_WINDING_PROBE * size, 0.01 * len / per);
        if (!(eps > AG_VERIFY_WINDING_THIN * size))
            continue; /* a sliver too thin to probe */
        double q[3];
        long w = probe_winding(T, &g, f, nrm, len, eps, q);
        /* a wedge thinner than the probe (a spike a few micrometres wide near its tip)
         * puts the probe beyond its other wall: probed again much closer, an overlap still
         * winds twice and a face turned inside out still winds 0 */
        double near = fmax(1e-3 * eps, AG_VERIFY_WINDING_THIN * size);
        if (w != 1 && near < eps)
            w = probe_winding(T, &g, f, nrm, len, near, q);
        if (w != 1) {
            snprintf(why, nwhy, "the building overlaps itself near (%.3f, %.3f, %.3f): it winds "
                     "%ld times there (parts swept through each other)", q[0] + o[0],
                     q[1] + o[1], q[2] + o[2], w);
            ok = 0;
        }
    }
    vgrid_free(&g);
    free(T);
    free(id);
    return ok;
}

/* --- folds of horizontal faces ----------------------------------------------------------- */

typedef struct {
    double z, x0, x1;
    uint32_t t;
    int up;
} flat_tri;

static int cmp_flat_tri(const void *a, const void *b)
{
    const flat_tri *x = a, *y = b;
    if (x->z != y->z)
        return x->z < y->z ? -1 : 1;
    return x->x0 < y->x0 ? -1 : x->x0 > y->x0;
}

/* Area of the intersection of two counter-clockwise triangles in the plane. */
static double overlap_area(const double a[3][2], const double b[3][2])
{
    double poly[2][12][2];
    int n = 3, cur = 0;
    memcpy(poly[0], a, sizeof(double[3][2]));
    for (int e = 0; e < 3 && n; e++) {
        const double *p = b[e], *q = b[(e + 1) % 3];
        int k = 0;
        for (int i = 0; i < n; i++) {
            const double *u = poly[cur][i], *v = poly[cur][(i + 1) % n];
            double du = (q[0] - p[0]) * (u[1] - p[1]) - (q[1] - p[1]) * (u[0] - p[0]);
            double dv = (q[0] - p[0]) * (v[1] - p[1]) - (q[1] - p[1]) * (v[0] - p[0]);
            if (du >= 0 && k < 12)
                poly[1 - cur][k][0] = u[0], poly[1 - cur][k][1] = u[1], k++;
            if ((du >= 0) != (dv >= 0) && k < 12) {
                double r = du / (du - dv);
                poly[1 - cur][k][0] = u[0] + r * (v[0] - u[0]);
                poly[1 - cur][k][1] = u[1] + r * (v[1] - u[1]);
                k++;
            }
        }
        n = k;
        cur = 1 - cur;
    }
    double area = 0;
    for (int i = 0; i < n; i++)
        area += poly[cur][i][0] * poly[cur][(i + 1) % n][1] - poly[cur][(i + 1) % n][0] * poly[cur][i][1];
    return area / 2;
}

/* The corners of triangle t in the plane, about o, counter-clockwise seen from its outside
 * (an upward triangle as it is, a downward one reversed); 1 when upward. */
static int flat_corners(const ag_mesh *m, uint32_t t, const double *o, double c[3][2])
{
    for (int k = 0; k < 3; k++) {
        const double *p = &m->pos[3 * m->tri[3 * t + k]];
        c[k][0] = p[0] - o[0];
        c[k][1] = p[1] - o[1];
    }
    double a = (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]);
    if (a < 0) {
        double x = c[1][0], y = c[1][1];
        c[1][0] = c[2][0], c[1][1] = c[2][1];
        c[2][0] = x, c[2][1] = y;
    }
    return a > 0;
}

/* An upward and a downward horizontal triangle at one height whose insides overlap (more
 * than a sliver of the point tolerance along the building): a sheet of two faces back to
 * back with the solid on neither side. Its edges pair and it adds no volume, and the probes
 * behind faces find it only where one falls into it; here every pair is compared. */
static int no_flat_fold(const ag_mesh *m, size_t t0, size_t t1, double min_area, char *why,
                        size_t nwhy)
{
    /* most buildings have no upward and downward horizontal triangles at all */
    size_t nup = 0, ndown = 0;
    for (size_t t = t0; t < t1; t++) {
        const double *a = &m->pos[3 * m->tri[3 * t]], *b = &m->pos[3 * m->tri[3 * t + 1]],
                     *c = &m->pos[3 * m->tri[3 * t + 2]];
        if (a[2] != b[2] || b[2] != c[2])
            continue;
        double area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        nup += area > 0;
        ndown += area < 0;
    }
    if (!nup || !ndown)
        return 1;
    size_t n = 0;
    flat_tri *F = malloc((nup + ndown) * sizeof *F);
    if (!F) {
        snprintf(why, nwhy, "out of memory checking the building");
        return 0;
    }
    for (size_t t = t0; t < t1; t++) {
        const double *a = &m->pos[3 * m->tri[3 * t]], *b = &m->pos[3 * m->tri[3 * t + 1]],
                     *c = &m->pos[3 * m->tri[3 * t + 2]];
        if (a[2] != b[2] || b[2] != c[2])
            continue;
        double area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if (area == 0)
            continue;
        F[n++] = (flat_tri){a[2], fmin(a[0], fmin(b[0], c[0])), fmax(a[0], fmax(b[0], c[0])),
                            (uint32_t)t, area > 0};
    }
    qsort(F, n, sizeof *F, cmp_flat_tri);
    int ok = 1;
    for (size_t g = 0; ok && g < n;) {
        size_t e = g, ups = 0;
        while (e < n && F[e].z == F[g].z)
            ups += F[e++].up;
        if (ups && ups < e - g) {
            const double *o = &m->pos[3 * m->tri[3 * F[g].t]];
            for (size_t i = g; ok && i < e; i++)
                for (size_t j = i + 1; ok && j < e && F[j].x0 <= F[i].x1; j++) {
                    if (F[i].up == F[j].up)
                        continue;
                    double A[3][2], B[3][2];
                    flat_corners(m, F[i].t, o, A);
                    flat_corners(m, F[j].t, o, B);
                    if (overlap_area(A, B) > min_area) {
                        ok = 0;
                        snprintf(why, nwhy, "an upward and a downward face overlap near (%.3f, "
                                 "%.3f, %.3f): a horizontal face folded inside out",
                                 o[0] + (A[0][0] + A[1][0] + A[2][0]) / 3,
                                 o[1] + (A[0][1] + A[1][1] + A[2][1]) / 3, F[g].z);
                    }
                }
        }
        g = e;
    }
    free(F);
    return ok;
}

int ag_verify_building(const ag_mesh *m, size_t t0, size_t t1, const ag_plan *plan, char *why,
                       size_t nwhy)
{
    char local[160];
    if (!why || !nwhy) {
        why = local;
        nwhy = sizeof local;
    }
    why[0] = 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, mag = 0;
    for (size_t L = 0; L < plan->nloops; L++)
        for (size_t i = 0; i < plan->loops[L].n; i++)
            for (int k = 0; k < 2; k++) {
                double v = plan->loops[L].xy[2 * i + k];
                lo[k] = fmin(lo[k], v);
                hi[k] = fmax(hi[k], v);
                mag = fmax(mag, fabs(v));
            }
    double extent = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    ag_extrude_tol tol = ag_extrude_tolerances(extent, mag);
    if (!closed_manifold(m, t0, t1, tol.point, why, nwhy))
        return 0;
    double out, top;
    ag_verify_reach(plan, &out, &top);
    double slack = AG_VERIFY_REACH_REL * tol.size + tol.point;
    double allowed = AG_VERIFY_MITRE * out + slack;
    double worst = 0, wx = 0, wy = 0, zmin = INFINITY, zmax = -INFINITY;
    uint8_t *seen = calloc(m->nverts ? m->nverts : 1, 1);
    if (!seen) {
        snprintf(why, nwhy, "out of memory checking the building");
        return 0;
    }
    for (size_t t = t0; t < t1; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->tri[3 * t + k];
            if (seen[v])
                continue;
            seen[v] = 1;
            const double *p = &m->pos[3 * v];
            zmin = fmin(zmin, p[2]);
            zmax = fmax(zmax, p[2]);
            double d = 0;
            if (!within(plan, p[0], p[1], allowed, &d) && d > worst) {
                worst = d;
                wx = p[0];
                wy = p[1];
            }
        }
    free(seen);
    if (worst > allowed) {
        snprintf(why, nwhy, "it reaches %.3g m outside its footprint at (%.3f, %.3f) (its "
                 "profiles lead %.3g m out)", worst, wx, wy, out);
        return 0;
    }
    if (zmin < -slack || zmax > top + slack + AG_VERIFY_REACH_REL * top) {
        snprintf(why, nwhy, "its height runs from %.4g to %.4g m (the plan allows 0 to %.4g m)",
                 zmin, zmax, top);
        return 0;
    }
    if (!no_flat_fold(m, t0, t1, tol.point * fmax(tol.size, extent), why, nwhy))
        return 0;
    return winds_once(m, t0, t1, tol.point, fmax(tol.size, extent), why, nwhy);
}
