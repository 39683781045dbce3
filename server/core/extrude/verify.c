#include "verify.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tolerance.h"

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

typedef struct {
    uint32_t a, b;
} dedge;

static int cmp_dedge(const void *x, const void *y)
{
    const dedge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : p->b > q->b;
}

static int cmp_tri(const void *x, const void *y)
{
    const uint32_t *p = x, *q = y;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

typedef struct {
    double x;
    uint32_t v;
} by_x;

static int cmp_by_x(const void *p, const void *q)
{
    double a = ((const by_x *)p)->x, b = ((const by_x *)q)->x;
    return a < b ? -1 : a > b;
}

static uint32_t root(uint32_t *par, uint32_t x)
{
    while (par[x] != x)
        x = par[x] = par[par[x]];
    return x;
}

/* Welded ids of the vertices the triangles use (sorted sweep along x, union-find). */
static int weld(const ag_mesh *m, size_t t0, size_t t1, double tol, uint32_t *id)
{
    size_t nv = 0;
    by_x *vs = malloc((3 * (t1 - t0) + 1) * sizeof *vs);
    if (!vs)
        return 0;
    for (size_t t = t0; t < t1; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = m->tri[3 * t + k];
            vs[nv++] = (by_x){m->pos[3 * v], v};
        }
    qsort(vs, nv, sizeof *vs, cmp_by_x);
    for (size_t i = 0; i < nv; i++)
        id[vs[i].v] = vs[i].v;
    for (size_t i = 0; i < nv; i++) {
        const double *p = &m->pos[3 * vs[i].v];
        for (size_t j = i + 1; j < nv; j++) {
            const double *q = &m->pos[3 * vs[j].v];
            if (q[0] - p[0] > tol)
                break;
            if (vs[j].v != vs[i].v && fabs(q[1] - p[1]) <= tol && fabs(q[2] - p[2]) <= tol &&
                hypot(hypot(q[0] - p[0], q[1] - p[1]), q[2] - p[2]) <= tol) {
                uint32_t a = root(id, vs[i].v), b = root(id, vs[j].v);
                if (a != b)
                    id[a > b ? a : b] = a < b ? a : b;
            }
        }
    }
    for (size_t i = 0; i < nv; i++)
        id[vs[i].v] = root(id, vs[i].v);
    free(vs);
    return 1;
}

static int closed_manifold(const ag_mesh *m, size_t t0, size_t t1, double tol, char *why,
                           size_t nwhy)
{
    size_t nt = t1 - t0;
    uint32_t *id = malloc((m->nverts ? m->nverts : 1) * sizeof *id);
    dedge *e = malloc((3 * nt + 1) * sizeof *e);
    uint32_t *tv = malloc((3 * nt + 1) * sizeof *tv);
    int ok = id && e && tv && weld(m, t0, t1, tol, id);
    if (!ok)
        snprintf(why, nwhy, "out of memory checking the building");
    size_t ne = 0, ntv = 0;
    for (size_t t = t0; ok && t < t1; t++) {
        uint32_t v[3] = {id[m->tri[3 * t]], id[m->tri[3 * t + 1]], id[m->tri[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue; /* shorter than the weld tolerance: no edges of its own */
        for (int k = 0; k < 3; k++)
            e[ne++] = (dedge){v[k], v[(k + 1) % 3]};
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2 - a; b++)
                if (v[b] > v[b + 1]) {
                    uint32_t x = v[b];
                    v[b] = v[b + 1];
                    v[b + 1] = x;
                }
        memcpy(&tv[3 * ntv++], v, sizeof v);
    }
    if (ok && !ne) {
        ok = 0;
        snprintf(why, nwhy, "the building has no triangles");
    }
    if (ok) {
        qsort(e, ne, sizeof *e, cmp_dedge);
        for (size_t i = 0; i < ne && ok; i++) {
            if (i + 1 < ne && !cmp_dedge(&e[i], &e[i + 1])) {
                ok = 0;
                const double *p = &m->pos[3 * e[i].a];
                snprintf(why, nwhy, "an edge at (%.3f, %.3f, %.3f) is shared by more than two "
                         "faces (not a closed 2-manifold)", p[0], p[1], p[2]);
                break;
            }
            dedge r = {e[i].b, e[i].a};
            if (!bsearch(&r, e, ne, sizeof *e, cmp_dedge)) {
                ok = 0;
                const double *p = &m->pos[3 * e[i].a];
                snprintf(why, nwhy, "the building is open at an edge from (%.3f, %.3f, %.3f)",
                         p[0], p[1], p[2]);
            }
        }
    }
    if (ok) {
        qsort(tv, ntv, 3 * sizeof *tv, cmp_tri);
        for (size_t i = 0; i + 1 < ntv && ok; i++)
            if (!cmp_tri(&tv[3 * i], &tv[3 * i + 3])) {
                ok = 0;
                const double *p = &m->pos[3 * tv[3 * i]];
                snprintf(why, nwhy, "two faces lie on each other near (%.3f, %.3f, %.3f) (a "
                         "double-sided sliver)", p[0], p[1], p[2]);
            }
    }
    free(id);
    free(e);
    free(tv);
    return ok;
}

/* --- within reach of the footprint ------------------------------------------------------- */

static double seg_dist(double x, double y, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(a[0] + t * dx - x, a[1] + t * dy - y);
}

/* Distance of (x, y) outside the union of the loops (even-odd) and the plan-frame forced
 * polygons (each alone); 0 inside. */
static double outside_by(const ag_plan *plan, double x, double y)
{
    int in = 0;
    double d = INFINITY;
    for (size_t L = 0; L < plan->nloops; L++) {
        const ag_plan_loop *l = &plan->loops[L];
        for (size_t i = 0, j = l->n - 1; i < l->n; j = i++) {
            const double *a = &l->xy[2 * j], *b = &l->xy[2 * i];
            if ((b[1] > y) != (a[1] > y) && x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
                in = !in;
            d = fmin(d, seg_dist(x, y, a, b));
        }
    }
    if (in)
        return 0;
    for (size_t k = 0; k < plan->nsteps; k++) {
        const ag_plan_step *s = &plan->steps[k];
        if (!s->npoints || !s->plan_frame)
            continue;
        int inq = 0;
        for (size_t i = 0, j = s->npoints - 1; i < s->npoints; j = i++) {
            const double *a = &s->points[2 * j], *b = &s->points[2 * i];
            if ((b[1] > y) != (a[1] > y) && x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
                inq = !inq;
            d = fmin(d, seg_dist(x, y, a, b));
        }
        if (inq)
            return 0;
    }
    return d;
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
            double d = outside_by(plan, p[0], p[1]);
            if (d > worst) {
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
    return 1;
}
