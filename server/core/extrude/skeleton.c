#include "skeleton.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eventq.h"
#include "predicates.h"
#include "tolerance.h"

#define NONE UINT32_MAX

typedef struct {
    double nx, ny; /* inward unit normal; direction is (ny, -nx) */
    double c, s;   /* the edge's line at height z: n . p = c + s z */
    uint32_t start, end;
    uint32_t face;
    int32_t loop, edge, profile, seg;
    uint32_t ver;
    uint8_t alive;
    uint8_t paused;  /* held still while other edges make a horizontal face */
    uint8_t growing; /* a plan edit's edge, growing to its size in a flat interval */
    int32_t step;    /* 0: from the plan; k + 1: made by plan edit k; -1: an offset's side */
    int32_t clock;   /* profile heights count from: 0 the plan, k + 1 plan edit k, then
                      * nsteps + 1 + k offset event k */
} sk_edge;

typedef struct {
    double x, y, z; /* where the corner was made */
    double vx, vy;  /* plan velocity per metre of height */
    uint32_t in, out;
    uint32_t vert; /* shell vertex where it was made */
    uint32_t stamp;
    uint8_t alive, settled;
} sk_corner;

typedef struct {
    const ag_plan *plan;
    ag_shell *shell;
    ag_eventq q;
    sk_edge *e;
    size_t ne, cap_e;
    sk_corner *c;
    size_t nc, cap_c;
    uint32_t *live_c; /* corners that may still split edges (lazily compacted) */
    size_t nlive_c, cap_live_c;
    uint32_t *live_e;
    size_t nlive_e, cap_live_e;
    uint32_t *touched; /* corners made while handling one event */
    size_t ntouched, cap_touched;
    uint32_t stamp;
    double ox, oy; /* local origin */
    double d1, d2, d3;
    double zcur;
    /* Horizontal profile segments: the sweep runs in a virtual height in which each
     * height H with a horizontal segment is stretched to an interval [vs, vs + 1] of
     * the same real height; edges with the horizontal segment move by its width over
     * that interval, all others are held still. */
    size_t nflat;
    double *flat_h; /* real heights, ascending */
    ag_status st;
    ag_error *err;
    ag_skeleton_stats stats;
    /* while the groups of one batch of intersections are handled: new corners are settled
     * (merged, zipped) only after all of them, so a collinear merge made at one point
     * cannot run along the line over another point of the same height before it is met */
    int defer_settle;
} sk;

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *n = realloc(*p, c * elem);
    if (!n)
        return 0;
    *p = n;
    *cap = c;
    return 1;
}

static void fail(sk *S, ag_status st)
{
    if (S->st == AG_OK)
        S->st = st;
}

static inline double edx(const sk_edge *e) { return e->ny; }
static inline double edy(const sk_edge *e) { return -e->nx; }

static inline void cpos(const sk_corner *c, double z, double *x, double *y)
{
    *x = c->x + c->vx * (z - c->z);
    *y = c->y + c->vy * (z - c->z);
}

/* Real height of virtual height v. */
static double real_z(const sk *S, double v)
{
    for (size_t k = 0; k < S->nflat; k++) {
        double vs = S->flat_h[k] + (double)k;
        if (v < vs)
            return v - (double)k;
        if (v <= vs + 1)
            return S->flat_h[k];
    }
    return v - (double)S->nflat;
}

/* Virtual height of real height z: `after` places z behind a flat interval at z. */
static double virtual_z(const sk *S, double z, int after)
{
    size_t k = 0;
    while (k < S->nflat && (S->flat_h[k] < z || (after && S->flat_h[k] == z)))
        k++;
    return z + (double)k;
}

static uint32_t vertex(sk *S, double x, double y, double z)
{
    z = real_z(S, z);
    uint32_t id = 0;
    if (ag_shell_add_vertex(S->shell, x + S->ox, y + S->oy, z, &id) != AG_OK)
        fail(S, AG_ERR_NOMEM);
    return id;
}

static void seg(sk *S, uint32_t face, uint32_t a, uint32_t b)
{
    if (ag_shell_add_segment(S->shell, face, a, b) != AG_OK)
        fail(S, AG_ERR_NOMEM);
}

static uint32_t new_face(sk *S, const sk_edge *e)
{
    ag_shell_face f = {AG_SHELL_FACE_SIDE, e->loop, e->edge, e->profile, e->seg, 0, 0};
    if (e->growing)
        f.segment = -1; /* the flat growth of a plan edit */
    uint32_t id = 0;
    if (ag_shell_add_face(S->shell, &f, &id) != AG_OK)
        fail(S, AG_ERR_NOMEM);
    return id;
}

static uint32_t add_edge(sk *S)
{
    if (!grow((void **)&S->e, &S->cap_e, S->ne + 1, sizeof(sk_edge)) ||
        !grow((void **)&S->live_e, &S->cap_live_e, S->nlive_e + 1, sizeof(uint32_t))) {
        fail(S, AG_ERR_NOMEM);
        return NONE;
    }
    memset(&S->e[S->ne], 0, sizeof(sk_edge));
    S->e[S->ne].alive = 1;
    S->e[S->ne].start = S->e[S->ne].end = NONE;
    S->live_e[S->nlive_e++] = (uint32_t)S->ne;
    return (uint32_t)S->ne++;
}

/* A corner joining edge `in` to edge `out` at (x, y, z); velocity is set by settle(). */
static uint32_t add_corner(sk *S, uint32_t in, uint32_t out, double x, double y, double z,
                           uint32_t vert)
{
    if (!grow((void **)&S->c, &S->cap_c, S->nc + 1, sizeof(sk_corner)) ||
        !grow((void **)&S->touched, &S->cap_touched, S->ntouched + 1, sizeof(uint32_t)) ||
        !grow((void **)&S->live_c, &S->cap_live_c, S->nlive_c + 1, sizeof(uint32_t))) {
        fail(S, AG_ERR_NOMEM);
        return NONE;
    }
    uint32_t k = (uint32_t)S->nc++;
    sk_corner *c = &S->c[k];
    memset(c, 0, sizeof *c);
    c->x = x;
    c->y = y;
    c->z = z;
    c->in = in;
    c->out = out;
    c->vert = vert;
    c->alive = 1;
    S->e[in].end = k;
    S->e[in].ver++;
    S->e[out].start = k;
    S->e[out].ver++;
    S->touched[S->ntouched++] = k;
    S->live_c[S->nlive_c++] = k;
    return k;
}

/* The corner stops at vertex v: its arc closes the faces on both sides. */
static void retire(sk *S, uint32_t k, uint32_t v)
{
    sk_corner *c = &S->c[k];
    if (!c->alive)
        return;
    seg(S, S->e[c->in].face, c->vert, v);
    seg(S, S->e[c->out].face, v, c->vert);
    c->alive = 0;
}

static void kill_edge(sk *S, uint32_t e)
{
    S->e[e].alive = 0;
    S->e[e].ver++;
}

/* --- event computation ------------------------------------------------------------------- */

static void push(sk *S, const ag_event *ev)
{
    if (ag_eventq_push(&S->q, ev) != AG_OK)
        fail(S, AG_ERR_NOMEM);
}

static void edge_event(sk *S, uint32_t ei)
{
    const sk_edge *e = &S->e[ei];
    if (!e->alive || e->start == NONE || e->end == NONE)
        return;
    const sk_corner *a = &S->c[e->start], *b = &S->c[e->end];
    if (!a->settled || !b->settled || !a->alive || !b->alive)
        return;
    double z0 = fmax(fmax(a->z, b->z), S->zcur);
    double ax, ay, bx, by;
    cpos(a, z0, &ax, &ay);
    cpos(b, z0, &bx, &by);
    double dx = edx(e), dy = edy(e);
    double len = dx * (bx - ax) + dy * (by - ay);
    double rate = dx * (b->vx - a->vx) + dy * (b->vy - a->vy);
    if (!(rate < -1e-12))
        return;
    double dz = len / -rate;
    if (dz < 0)
        dz = 0;
    ag_event ev = {0};
    ev.type = AG_EVENT_EDGE;
    ev.z = z0 + dz;
    cpos(a, ev.z, &ax, &ay);
    cpos(b, ev.z, &bx, &by);
    ev.x = (ax + bx) / 2;
    ev.y = (ay + by) / 2;
    ev.a = ei;
    ev.ver = e->ver;
    if (isfinite(ev.z))
        push(S, &ev);
}

/* Is edge fi the one after (or before) the corner's neighbouring edge, and that edge of
 * no length at height z? Then the corner merely starts on fi's line where a side edge
 * was put in (an offset event's cut), which is no split. */
static int zero_gap(const sk *S, uint32_t k, uint32_t fi, double z)
{
    const sk_corner *c = &S->c[k];
    const sk_edge *o = &S->e[c->out], *i = &S->e[c->in];
    const sk_edge *g = NULL;
    if (o->end != NONE && S->c[o->end].out == fi)
        g = o;
    else if (i->start != NONE && S->c[i->start].in == fi)
        g = i;
    if (!g || g->start == NONE || g->end == NONE)
        return 0;
    double ax, ay, bx, by;
    cpos(&S->c[g->start], z, &ax, &ay);
    cpos(&S->c[g->end], z, &bx, &by);
    return hypot(bx - ax, by - ay) <= S->d2;
}

static void split_event(sk *S, uint32_t k, uint32_t fi)
{
    const sk_corner *c = &S->c[k];
    const sk_edge *f = &S->e[fi];
    if (!c->alive || !c->settled || !f->alive || fi == c->in || fi == c->out)
        return;
    if (f->start == NONE || f->end == NONE)
        return;
    const sk_corner *fa = &S->c[f->start], *fb = &S->c[f->end];
    if (!fa->settled || !fb->settled)
        return;
    double z0 = fmax(c->z, S->zcur), px, py;
    cpos(c, z0, &px, &py);
    double dist = f->nx * px + f->ny * py - (f->c + f->s * z0);
    double closing = f->s - (f->nx * c->vx + f->ny * c->vy);
    if (dist < -S->d2 && f->s < 0 && closing < -1e-12) {
        /* an edge moving outwards (a soffit) meets a part of the plan growing towards it
         * from outside: parts of a growing plan collide from the outside */
        dist = -dist;
        closing = -closing;
    } else if (!(closing > 1e-12) || dist < -S->d2) {
        return;
    }
    double dz = dist > 0 ? dist / closing : 0;
    if (dz <= 0 && zero_gap(S, k, fi, z0))
        return;
    double z = z0 + dz;
    if (!isfinite(z))
        return;
    double x, y, ax, ay, bx, by;
    cpos(c, z, &x, &y);
    cpos(fa, z, &ax, &ay);
    cpos(fb, z, &bx, &by);
    double dx = edx(f), dy = edy(f);
    double len = dx * (bx - ax) + dy * (by - ay);
    double t = dx * (x - ax) + dy * (y - ay);
    /* an edge that has shrunk to a point by then is handled by its edge event */
    if (len <= S->d3 || t < -S->d3 || t > len + S->d3)
        return;
    ag_event ev = {0};
    ev.type = AG_EVENT_SPLIT;
    ev.z = z;
    ev.x = x;
    ev.y = y;
    ev.a = k;
    ev.b = fi;
    ev.ver = f->ver;
    push(S, &ev);
}

/* --- corner settling: velocity, collinear merge, ridge zip ------------------------------- */

static void settle(sk *S, uint32_t k);

static int velocity(sk *S, sk_corner *c)
{
    const sk_edge *a = &S->e[c->in], *b = &S->e[c->out];
    double det = a->nx * b->ny - a->ny * b->nx;
    if (fabs(det) <= AG_EXTRUDE_PARALLEL)
        return 0;
    c->vx = (a->s * b->ny - b->s * a->ny) / det;
    c->vy = (a->nx * b->s - b->nx * a->s) / det;
    return 1;
}

static void merge(sk *S, uint32_t k)
{
    sk_corner *c = &S->c[k];
    uint32_t ein = c->in, eout = c->out;
    int min_vol = S->plan->priority == AG_PRIORITY_MIN_VOLUME;
    double sin_ = S->e[ein].s, sout = S->e[eout].s;
    /* the tags of the segments the two edges are on now */
    int32_t pin = ag_profile_priority(&S->plan->profiles[S->e[ein].profile], S->e[ein].seg);
    int32_t pout = ag_profile_priority(&S->plan->profiles[S->e[eout].profile], S->e[eout].seg);
    int in_wins = pin != pout ? pin > pout : min_vol ? sin_ > sout : sin_ < sout;
    double z = c->z;
    uint32_t vl = c->vert;
    S->stats.merges++;
    c->alive = 0; /* made and retired at the same point: no arc */
    if (in_wins) {
        uint32_t loser = eout, m = S->e[loser].end;
        uint32_t x_out = S->c[m].out;
        double px, py;
        cpos(&S->c[m], z, &px, &py);
        uint32_t vm = vertex(S, px, py, z);
        retire(S, m, vm);
        seg(S, S->e[loser].face, vm, vl);
        seg(S, S->e[ein].face, vl, vm);
        kill_edge(S, loser);
        if (x_out == loser || x_out == ein) {
            kill_edge(S, ein); /* the loop was only these two edges */
            return;
        }
        uint32_t k2 = add_corner(S, ein, x_out, px, py, z, vm);
        if (k2 != NONE)
            settle(S, k2);
    } else {
        uint32_t loser = ein, m = S->e[loser].start;
        uint32_t y_in = S->c[m].in;
        double px, py;
        cpos(&S->c[m], z, &px, &py);
        uint32_t vm = vertex(S, px, py, z);
        retire(S, m, vm);
        seg(S, S->e[loser].face, vl, vm);
        seg(S, S->e[eout].face, vm, vl);
        kill_edge(S, loser);
        if (y_in == loser || y_in == eout) {
            kill_edge(S, eout);
            return;
        }
        uint32_t k2 = add_corner(S, y_in, eout, px, py, z, vm);
        if (k2 != NONE)
            settle(S, k2);
    }
}

static void zip(sk *S, uint32_t k)
{
    sk_corner *c = &S->c[k];
    uint32_t B = c->in, A = c->out;
    uint32_t cA = S->e[A].end, cB = S->e[B].start;
    double z = c->z;
    uint32_t vl = c->vert;
    S->stats.zips++;
    c->alive = 0;
    double pax, pay, pbx, pby;
    cpos(&S->c[cA], z, &pax, &pay);
    cpos(&S->c[cB], z, &pbx, &pby);
    if (cA == cB) {
        uint32_t vp = vertex(S, pax, pay, z);
        retire(S, cA, vp);
        seg(S, S->e[A].face, vp, vl);
        seg(S, S->e[B].face, vl, vp);
        kill_edge(S, A);
        kill_edge(S, B);
        return;
    }
    double dx = edx(&S->e[A]), dy = edy(&S->e[A]);
    double lenA = dx * (pax - c->x) + dy * (pay - c->y);
    double lenB = dx * (pbx - c->x) + dy * (pby - c->y);
    if (fabs(lenA - lenB) <= S->d2 * 10) {
        double px = (pax + pbx) / 2, py = (pay + pby) / 2;
        uint32_t vp = vertex(S, px, py, z);
        uint32_t yin = S->c[cB].in, xout = S->c[cA].out;
        retire(S, cA, vp);
        retire(S, cB, vp);
        seg(S, S->e[A].face, vp, vl);
        seg(S, S->e[B].face, vl, vp);
        kill_edge(S, A);
        kill_edge(S, B);
        if (yin == xout) {
            /* a single edge is left between the two: it has shrunk to this point */
            kill_edge(S, yin);
            return;
        }
        uint32_t k2 = add_corner(S, yin, xout, px, py, z, vp);
        if (k2 != NONE)
            settle(S, k2);
    } else if (lenA < lenB) {
        uint32_t vp = vertex(S, pax, pay, z);
        uint32_t xout = S->c[cA].out;
        retire(S, cA, vp);
        seg(S, S->e[A].face, vp, vl);
        seg(S, S->e[B].face, vl, vp);
        kill_edge(S, A);
        uint32_t k2 = add_corner(S, B, xout, pax, pay, z, vp);
        if (k2 != NONE)
            settle(S, k2);
    } else {
        uint32_t vp = vertex(S, pbx, pby, z);
        uint32_t yin = S->c[cB].in;
        retire(S, cB, vp);
        seg(S, S->e[A].face, vp, vl);
        seg(S, S->e[B].face, vl, vp);
        kill_edge(S, B);
        uint32_t k2 = add_corner(S, yin, A, pbx, pby, z, vp);
        if (k2 != NONE)
            settle(S, k2);
    }
}

static void settle(sk *S, uint32_t k)
{
    if (S->st != AG_OK)
        return;
    sk_corner *c = &S->c[k];
    if (!c->alive)
        return;
    if (c->in == c->out) {
        /* a loop of one edge: it has closed */
        kill_edge(S, c->in);
        c->alive = 0;
        return;
    }
    if (velocity(S, c)) {
        c->settled = 1;
        return;
    }
    const sk_edge *a = &S->e[c->in], *b = &S->e[c->out];
    double dot = a->nx * b->nx + a->ny * b->ny;
    if (dot > 0) {
        if (fabs(a->s - b->s) <= AG_EXTRUDE_SAME_SLOPE) {
            /* collinear, same slope: the corner moves with the common plane */
            double nx = a->nx + b->nx, ny = a->ny + b->ny, l = hypot(nx, ny);
            c->vx = a->s * nx / l;
            c->vy = a->s * ny / l;
            c->settled = 1;
            return;
        }
        merge(S, k);
    } else {
        zip(S, k);
    }
}

/* --- after an event: schedule new events ------------------------------------------------- */

static void compact_live(sk *S)
{
    size_t w = 0;
    for (size_t i = 0; i < S->nlive_c; i++)
        if (S->c[S->live_c[i]].alive)
            S->live_c[w++] = S->live_c[i];
    S->nlive_c = w;
    w = 0;
    for (size_t i = 0; i < S->nlive_e; i++)
        if (S->e[S->live_e[i]].alive)
            S->live_e[w++] = S->live_e[i];
    S->nlive_e = w;
}

static void schedule_touched(sk *S)
{
    if (S->st != AG_OK)
        return;
    compact_live(S);
    S->stamp++;
    for (size_t i = 0; i < S->ntouched; i++) {
        sk_corner *c = &S->c[S->touched[i]];
        if (!c->alive)
            continue;
        uint32_t es[2] = {c->in, c->out};
        for (int j = 0; j < 2; j++) {
            sk_edge *e = &S->e[es[j]];
            if (!e->alive)
                continue;
            /* the edge changed: its collapse and every corner's hit on it are new */
            edge_event(S, es[j]);
            for (size_t q = 0; q < S->nlive_c; q++)
                split_event(S, S->live_c[q], es[j]);
        }
        for (size_t q = 0; q < S->nlive_e; q++)
            split_event(S, S->touched[i], S->live_e[q]);
    }
    S->ntouched = 0;
}

/* --- generalized intersection event ------------------------------------------------------ */

typedef struct {
    double ang;
    uint32_t edge;
    int out;
} ray;

static int cmp_ray(const void *a, const void *b)
{
    const ray *x = a, *y = b;
    if (x->ang != y->ang)
        return x->ang < y->ang ? -1 : 1;
    if (x->out != y->out)
        return y->out - x->out; /* outgoing first on ties */
    /* the same way along one line: a fixed order, so that handling the point again pairs
     * the same edges (and keeps the corners) instead of swapping them for ever */
    return x->edge < y->edge ? -1 : x->edge > y->edge;
}

typedef struct {
    uint32_t *arr;
    size_t n, cap;
} u32vec;

static int vpush(u32vec *v, uint32_t x)
{
    if (!grow((void **)&v->arr, &v->cap, v->n + 1, sizeof(uint32_t)))
        return 0;
    v->arr[v->n++] = x;
    return 1;
}

typedef struct {
    u32vec C, E, splits;
    ray *rays;
    size_t cap_rays;
} scratch;

static int near_l(sk *S, uint32_t k, double z, double lx, double ly, double spread)
{
    const sk_corner *c = &S->c[k];
    double x, y;
    cpos(c, z, &x, &y);
    /* a fast corner (nearly parallel edges) may drift by |v| * spread: bounded so that
     * unrelated corners are not pulled in */
    double drift = hypot(c->vx, c->vy) * spread;
    double tol = 2 * S->d2 + (drift < 100 * S->d3 ? drift : 100 * S->d3);
    return hypot(x - lx, y - ly) <= tol;
}

/* The point nearest (least squares) to the planes of the edges meeting at an event, near
 * the events' mean (lx, ly, z): events of one cluster computed from fast corners can be
 * tens of micrometres apart, and their mean is then off the faces' planes. Kept only when
 * it moves less than the cluster's drift allowance. */
static void apex(const sk *S, const uint32_t *es, size_t n, double spread, double *lx,
                 double *ly, double *z)
{
    if (n < 3)
        return;
    double A[3][3] = {{0}}, b[3] = {0};
    const double lam = 1e-6; /* pulls the free directions (parallel planes) to the mean */
    for (size_t i = 0; i < n; i++) {
        const sk_edge *e = &S->e[es[i]];
        /* plane: nx x + ny y - s z = c, through the mean: residual r, row g */
        double g[3] = {e->nx, e->ny, -e->s}, w = 1 / (1 + e->s * e->s);
        double r = e->c + e->s * *z - e->nx * *lx - e->ny * *ly;
        for (int p = 0; p < 3; p++) {
            b[p] += w * g[p] * r;
            for (int q = 0; q < 3; q++)
                A[p][q] += w * g[p] * g[q];
        }
    }
    for (int p = 0; p < 3; p++)
        A[p][p] += lam;
    /* Cramer's rule on the 3 x 3 normal equations for the move d */
    double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                 A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                 A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    if (!(fabs(det) > 1e-300))
        return;
    double d[3];
    for (int c = 0; c < 3; c++) {
        double M[3][3];
        memcpy(M, A, sizeof M);
        for (int p = 0; p < 3; p++)
            M[p][c] = b[p];
        d[c] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) / det;
    }
    double allow = 2 * S->d2 + fmin(100 * S->d3, 10 * spread);
    if (!(hypot(d[0], d[1]) <= allow && fabs(d[2]) <= S->d1))
        return;
    *lx += d[0];
    *ly += d[1];
    *z = fmax(*z + d[2], S->zcur);
}

static void intersection(sk *S, ag_event *evs, size_t n, scratch *W)
{
    S->stamp++;
    uint32_t mark = S->stamp;
    W->C.n = W->E.n = W->splits.n = 0;
    double z = 0, lx = 0, ly = 0, zmin = INFINITY, zmax = -INFINITY;
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        ag_event *ev = &evs[i];
        if (ev->type == AG_EVENT_EDGE) {
            sk_edge *e = &S->e[ev->a];
            if (!e->alive || e->ver != ev->ver)
                continue;
            uint32_t ks[2] = {e->start, e->end};
            for (int j = 0; j < 2; j++)
                if (S->c[ks[j]].stamp != mark) {
                    S->c[ks[j]].stamp = mark;
                    vpush(&W->C, ks[j]);
                }
        } else {
            sk_corner *c = &S->c[ev->a];
            sk_edge *f = &S->e[ev->b];
            if (!c->alive || !f->alive || f->ver != ev->ver)
                continue;
            if (c->stamp != mark) {
                c->stamp = mark;
                vpush(&W->C, ev->a);
            }
            vpush(&W->splits, ev->b);
        }
        z += ev->z;
        lx += ev->x;
        ly += ev->y;
        zmin = fmin(zmin, ev->z);
        zmax = fmax(zmax, ev->z);
        used++;
    }
    if (!used || !W->C.n)
        return;
    z /= used;
    lx /= used;
    ly /= used;
    if (z < S->zcur)
        z = S->zcur;
    double spread = zmax - zmin + 1e-3 * S->d1;
    /* split edges whose end is at the point: the corner there arrives instead */
    for (size_t i = 0; i < W->splits.n; i++) {
        sk_edge *f = &S->e[W->splits.arr[i]];
        uint32_t ks[2] = {f->start, f->end};
        for (int j = 0; j < 2; j++)
            if (S->c[ks[j]].stamp != mark && near_l(S, ks[j], z, lx, ly, spread)) {
                S->c[ks[j]].stamp = mark;
                vpush(&W->C, ks[j]);
            }
    }
    /* chains: neighbours of arriving corners that are at the point too */
    for (size_t i = 0; i < W->C.n; i++) {
        sk_corner *c = &S->c[W->C.arr[i]];
        uint32_t ks[2] = {S->e[c->in].start, S->e[c->out].end};
        for (int j = 0; j < 2; j++)
            if (S->c[ks[j]].stamp != mark && S->c[ks[j]].alive &&
                near_l(S, ks[j], z, lx, ly, spread)) {
                S->c[ks[j]].stamp = mark;
                vpush(&W->C, ks[j]);
            }
    }
    S->stats.intersections++;
    /* edges at the point */
    for (size_t i = 0; i < W->C.n; i++) {
        sk_corner *c = &S->c[W->C.arr[i]];
        uint32_t es[2] = {c->in, c->out};
        for (int j = 0; j < 2; j++)
            {
                int seen = 0;
                for (size_t q = 0; q < W->E.n; q++)
                    if (W->E.arr[q] == es[j])
                        seen = 1;
                if (!seen)
                    vpush(&W->E, es[j]);
            }
    }
    apex(S, W->E.arr, W->E.n, spread, &lx, &ly, &z);
    uint32_t vl = vertex(S, lx, ly, z);
    size_t nrays = 0;
    size_t need = 2 * (W->E.n + W->splits.n) + 2;
    if (!grow((void **)&W->rays, &W->cap_rays, need, sizeof(ray))) {
        fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < W->E.n; i++) {
        sk_edge *e = &S->e[W->E.arr[i]];
        int st = S->c[e->start].stamp == mark, en = S->c[e->end].stamp == mark;
        double a = atan2(edy(e), edx(e));
        if (st && en) {
            kill_edge(S, W->E.arr[i]);
        } else if (st) {
            W->rays[nrays++] = (ray){a, W->E.arr[i], 1};
        } else if (en) {
            W->rays[nrays++] = (ray){a > 0 ? a - M_PI : a + M_PI, W->E.arr[i], 0};
        }
    }
    for (size_t i = 0; i < W->splits.n; i++) {
        uint32_t fi = W->splits.arr[i];
        sk_edge *f = &S->e[fi];
        if (!f->alive || f->start == NONE || f->end == NONE ||
            S->c[f->start].stamp == mark || S->c[f->end].stamp == mark)
            continue;
        int dup = 0;
        for (size_t q = 0; q < nrays; q++)
            if (W->rays[q].edge == fi)
                dup = 1;
        if (dup)
            continue;
        /* still crossing the point? */
        double ax, ay, bx, by;
        cpos(&S->c[f->start], z, &ax, &ay);
        cpos(&S->c[f->end], z, &bx, &by);
        double dx = edx(f), dy = edy(f);
        double t = dx * (lx - ax) + dy * (ly - ay), len = dx * (bx - ax) + dy * (by - ay);
        double off = fabs(f->nx * lx + f->ny * ly - (f->c + f->s * z));
        if (t < -S->d3 || t > len + S->d3 || off > S->d3 + spread * (1 + fabs(f->s)))
            continue;
        uint32_t f2 = add_edge(S);
        if (f2 == NONE)
            return;
        f = &S->e[fi];
        sk_edge *g = &S->e[f2];
        *g = *f;
        g->ver = 0;
        g->alive = 1;
        g->start = NONE;
        g->end = f->end;
        S->c[f->end].in = f2;
        f->end = NONE;
        f->ver++;
        double a = atan2(dy, dx);
        W->rays[nrays++] = (ray){a > 0 ? a - M_PI : a + M_PI, fi, 0};
        W->rays[nrays++] = (ray){a, f2, 1};
    }
    if (!nrays) {
        for (size_t i = 0; i < W->C.n; i++)
            retire(S, W->C.arr[i], vl);
        return;
    }
    qsort(W->rays, nrays, sizeof(ray), cmp_ray);
    /* near-ties: an outgoing ray goes before an incoming one (a ridge, zipped later) */
    for (size_t i = 0; i + 1 < nrays; i++)
        if (!W->rays[i].out && W->rays[i + 1].out && W->rays[i + 1].ang - W->rays[i].ang < 1e-9) {
            ray t = W->rays[i];
            W->rays[i] = W->rays[i + 1];
            W->rays[i + 1] = t;
        }
    if (nrays >= 2 && !W->rays[nrays - 1].out && W->rays[0].out &&
        W->rays[0].ang + 2 * M_PI - W->rays[nrays - 1].ang < 1e-9) {
        /* wrap-around tie: rotate the last (incoming) ray behind the first */
        ray t = W->rays[nrays - 1];
        memmove(&W->rays[1], &W->rays[0], (nrays - 1) * sizeof(ray));
        W->rays[0] = t;
        W->rays[0].ang -= 2 * M_PI;
        t = W->rays[0];
        W->rays[0] = W->rays[1];
        W->rays[1] = t;
    }
    /* pair each outgoing ray with the next incoming one counter-clockwise */
    long bal = 0, minbal = 0;
    size_t start = 0;
    int nout = 0;
    for (size_t i = 0; i < nrays; i++) {
        bal += W->rays[i].out ? 1 : -1;
        nout += W->rays[i].out;
        if (bal < minbal) {
            minbal = bal;
            start = i + 1;
        }
    }
    if (bal != 0) {
        ag_error_set(S->err, AG_ERR_INTERNAL, 0,
                     "inconsistent intersection at (%.6f, %.6f, %.6f): %d edges leave, %d arrive",
                     lx + S->ox, ly + S->oy, z, nout, (int)nrays - nout);
        fail(S, AG_ERR_INTERNAL);
        return;
    }
    uint32_t *stack = malloc(nrays * sizeof *stack);
    uint32_t *pairs = malloc(nrays * sizeof *pairs);
    uint8_t *keep = calloc(W->C.n + 1, 1);
    if (!stack || !pairs || !keep) {
        free(stack);
        free(pairs);
        free(keep);
        fail(S, AG_ERR_NOMEM);
        return;
    }
    size_t sp = 0, np = 0;
    int nested = 0;
    for (size_t j = 0; j < nrays; j++) {
        ray *r = &W->rays[(start + j) % nrays];
        if (r->out) {
            if (sp)
                nested = 1;
            stack[sp++] = r->edge;
        } else if (sp) {
            pairs[2 * np] = r->edge;
            pairs[2 * np + 1] = stack[--sp];
            np++;
        }
    }
    if (nested)
        S->stats.irregular++;
    /* a corner that is paired again with the same two edges only touched the others:
     * it carries on unchanged (re-making it would find the same touch again) */
    for (size_t p = 0; p < np; p++)
        for (size_t i = 0; i < W->C.n; i++) {
            sk_corner *c = &S->c[W->C.arr[i]];
            if (!keep[i] && c->in == pairs[2 * p] && c->out == pairs[2 * p + 1]) {
                keep[i] = 1;
                pairs[2 * p] = NONE;
                break;
            }
        }
    for (size_t i = 0; i < W->C.n; i++)
        if (!keep[i])
            retire(S, W->C.arr[i], vl);
    size_t first_new = S->ntouched;
    for (size_t p = 0; p < np; p++)
        if (pairs[2 * p] != NONE)
            add_corner(S, pairs[2 * p], pairs[2 * p + 1], lx, ly, z, vl);
    free(stack);
    free(pairs);
    free(keep);
    size_t last_new = S->ntouched;
    for (size_t i = first_new; i < last_new && S->st == AG_OK && !S->defer_settle; i++)
        settle(S, S->touched[i]);
}

/* --- profile direction events ------------------------------------------------------------ */

/* Slope per unit of virtual height: a horizontal segment covers its width in one unit. */
static double seg_slope(const ag_profile *p, int32_t seg)
{
    const ag_profile_point *a = &p->points[seg], *b = &p->points[seg + 1];
    if (b->z == a->z)
        return b->w - a->w;
    return (b->w - a->w) / (b->z - a->z);
}

static int seg_flat(const ag_profile *p, int32_t seg)
{
    return p->points[seg + 1].z == p->points[seg].z;
}

#define FLAT_MARK UINT32_MAX
#define OFFSET_MARK (UINT32_MAX - 2)

/* Edge e's part in offset event o: returns 0 when disabled, else 1 with its distance
 * (outwards) and profile after (-1: its own). */
static int offset_tuple(const ag_plan_offset *o, const sk_edge *e, double *w, int32_t *prof)
{
    *w = o->outside;
    *prof = o->profile;
    for (size_t i = 0; i < o->nedges && !e->step; i++) {
        const ag_offset_edge *x = &o->edges[i];
        if (x->loop != e->loop || x->edge != e->edge)
            continue;
        if (x->disabled)
            return 0;
        if (x->has_outside)
            *w = x->outside;
        if (x->profile >= 0)
            *prof = x->profile;
    }
    return 1;
}

static void direction(sk *S, ag_event *evs, size_t n)
{
    double z = evs[0].z;
    S->stamp++;
    uint32_t mark = S->stamp;
    S->stats.directions++;
    compact_live(S);
    /* edges that change: a profile switching segment (new face), or an edge held
     * still for / released after a flat interval (same face) */
    u32vec ch = {0}, ks = {0};
    int flat_start = 0, flat_end = 0;
    const ag_plan_offset *off = NULL; /* an offset event starting here */
    int32_t off_clock = 0;
    for (size_t j = 0; j < n; j++) {
        if (evs[j].a == FLAT_MARK) {
            flat_start |= evs[j].b == 0;
            flat_end |= evs[j].b == 1;
        }
        if (evs[j].a == OFFSET_MARK && evs[j].ver == 0) {
            off = &S->plan->offsets[evs[j].b];
            off_clock = (int32_t)(S->plan->nsteps + 1 + evs[j].b);
        }
    }
    double *off_w = malloc((S->nlive_e ? S->nlive_e : 1) * sizeof *off_w);
    int32_t *off_p = malloc((S->nlive_e ? S->nlive_e : 1) * sizeof *off_p);
    if (!off_w || !off_p) {
        free(off_w);
        free(off_p);
        fail(S, AG_ERR_NOMEM);
        return;
    }
    uint8_t *newface = malloc(S->nlive_e ? S->nlive_e : 1);
    if (!newface) {
        free(off_w);
        free(off_p);
        fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < S->nlive_e; i++) {
        uint32_t ei = S->live_e[i];
        sk_edge *e = &S->e[ei];
        int hit = 0;
        for (size_t j = 0; j < n && !hit; j++)
            if (evs[j].a != FLAT_MARK && (uint32_t)e->profile == evs[j].a &&
                (uint32_t)e->seg + 1 == evs[j].b && (uint32_t)e->clock == evs[j].ver)
                hit = 1;
        const ag_profile *p = &S->plan->profiles[e->profile];
        if (off && !e->growing && !e->paused && offset_tuple(off, e, &off_w[ch.n], &off_p[ch.n])) {
            newface[ch.n] = 3; /* moves by its offset over this flat interval */
            if (!vpush(&ch, ei))
                fail(S, AG_ERR_NOMEM);
            continue;
        }
        int next_flat = hit ? seg_flat(p, e->seg + 1) : seg_flat(p, e->seg);
        int grown = flat_end && e->growing;
        int pause = !hit && !e->growing && flat_start && !next_flat && !e->paused;
        int release = !hit && flat_end && e->paused;
        if (!hit && !pause && !release && !grown)
            continue;
        /* a grown edge whose own profile turns at the same height takes the next segment */
        newface[ch.n] = (uint8_t)(grown ? (hit ? 1 : 2) : hit);
        if (!vpush(&ch, ei))
            fail(S, AG_ERR_NOMEM);
    }
    for (size_t i = 0; i < ch.n; i++) {
        sk_edge *e = &S->e[ch.arr[i]];
        uint32_t cs[2] = {e->start, e->end};
        for (int j = 0; j < 2; j++)
            if (S->c[cs[j]].stamp != mark) {
                S->c[cs[j]].stamp = mark;
                if (!vpush(&ks, cs[j]))
                    fail(S, AG_ERR_NOMEM);
            }
    }
    /* retire the corners there, remembering their vertex at this height */
    uint32_t *verts = malloc((ks.n ? ks.n : 1) * sizeof *verts);
    double *xy = malloc((ks.n ? ks.n : 1) * 2 * sizeof *xy);
    if (!verts || !xy) {
        fail(S, AG_ERR_NOMEM);
        goto out;
    }
    for (size_t i = 0; i < ks.n; i++) {
        sk_corner *c = &S->c[ks.arr[i]];
        cpos(c, z, &xy[2 * i], &xy[2 * i + 1]);
        verts[i] = vertex(S, xy[2 * i], xy[2 * i + 1], z);
        retire(S, ks.arr[i], verts[i]);
        c->stamp = (uint32_t)i; /* index into verts until re-made */
    }
    for (size_t i = 0; i < ch.n; i++) {
        sk_edge *e = &S->e[ch.arr[i]];
        const ag_profile *p = &S->plan->profiles[e->profile];
        double s_new;
        if (newface[i] == 3 && off_w[i] == 0) {
            /* no move: it waits through the interval, on its new profile if it has one */
            if (off_p[i] >= 0) {
                uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
                seg(S, e->face, ve, vs);
                e->profile = off_p[i];
                e->seg = 0;
                e->clock = off_clock;
                e->face = new_face(S, e);
                seg(S, e->face, vs, ve);
            }
            e->paused = 1;
            s_new = 0;
        } else if (newface[i] == 3) {
            uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
            seg(S, e->face, ve, vs);
            if (off_p[i] >= 0) {
                e->profile = off_p[i];
                e->seg = 0;
                e->clock = off_clock;
            }
            e->growing = 1; /* its flat face; at the interval's end it carries on */
            e->paused = 0;
            s_new = -off_w[i];
            e->face = new_face(S, e);
            seg(S, e->face, vs, ve);
        } else if (newface[i]) {
            uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
            seg(S, e->face, ve, vs);
            if (newface[i] == 1)
                e->seg++; /* a grown plan edit keeps its profile's first segment */
            s_new = seg_slope(p, e->seg);
            e->paused = 0;
            e->growing = 0; /* before new_face: the new face is a profile segment's */
            e->face = new_face(S, e);
            seg(S, e->face, vs, ve);
        } else if (e->paused) {
            s_new = seg_slope(p, e->seg);
            e->paused = 0;
        } else {
            s_new = 0;
            e->paused = 1;
        }
        e->c += (e->s - s_new) * z;
        e->s = s_new;
        e->ver++;
    }
    size_t first_new = S->ntouched;
    for (size_t i = 0; i < ks.n; i++) {
        sk_corner *c = &S->c[ks.arr[i]];
        c->stamp = 0;
        add_corner(S, c->in, c->out, xy[2 * i], xy[2 * i + 1], z, verts[i]);
    }
    size_t last_new = S->ntouched;
    for (size_t i = first_new; i < last_new && S->st == AG_OK; i++)
        settle(S, S->touched[i]);
out:
    free(newface);
    free(off_w);
    free(off_p);
    free(verts);
    free(xy);
    free(ch.arr);
    free(ks.arr);
}


/* --- profile offset events: side edges ---------------------------------------------------- */

/* After an offset event's interval has started: where a moving edge A meets a waiting
 * (disabled) edge B, a side edge of zero length is put between them along the mitre
 * the two would share if both moved; it holds still while A's corner slides out along
 * it, cutting A's offset region there, and then follows the side profile. */
static void insert_sides(sk *S, size_t k)
{
    const ag_plan_offset *o = &S->plan->offsets[k];
    if (o->side < 0)
        return;
    compact_live(S);
    size_t nlive = S->nlive_c;
    for (size_t i = 0; i < nlive && S->st == AG_OK; i++) {
        uint32_t ck = S->live_c[i];
        sk_corner *c = &S->c[ck];
        if (!c->alive)
            continue;
        const sk_edge *ein = &S->e[c->in], *eout = &S->e[c->out];
        int a_in;
        if (ein->growing && eout->paused)
            a_in = 1;
        else if (eout->growing && ein->paused)
            a_in = 0;
        else
            continue;
        const sk_edge *A = a_in ? ein : eout, *B = a_in ? eout : ein;
        /* the shared mitre: where a corner of A and B would go if both moved out */
        double det = A->nx * B->ny - A->ny * B->nx, mx, my;
        if (fabs(det) <= AG_EXTRUDE_PARALLEL) {
            mx = -A->nx;
            my = -A->ny;
        } else {
            mx = (-B->ny + A->ny) / det;
            my = (-A->nx + B->nx) / det;
        }
        double ml = hypot(mx, my);
        if (!(ml > 0))
            continue;
        double dx = (a_in ? -mx : mx) / ml, dy = (a_in ? -my : my) / ml;
        double nx = -dy, ny = dx;
        /* A's end must slide away from B along the side edge, else there is nothing to cut */
        double d2 = A->nx * ny - A->ny * nx;
        if (fabs(d2) <= AG_EXTRUDE_PARALLEL)
            continue;
        double vx = (A->s * ny) / d2, vy = (-A->s * nx) / d2; /* n_A.v = s_A, n_side.v = 0 */
        if (!((a_in ? -1 : 1) * (vx * dx + vy * dy) > 0))
            continue;
        double px, py;
        cpos(c, c->z, &px, &py);
        uint32_t se = add_edge(S);
        if (se == NONE)
            return;
        c = &S->c[ck];
        A = a_in ? &S->e[c->in] : &S->e[c->out];
        sk_edge *e = &S->e[se];
        e->nx = nx;
        e->ny = ny;
        e->s = 0;
        e->c = nx * px + ny * py;
        e->loop = A->loop;
        e->edge = A->edge;
        e->profile = o->side;
        e->seg = 0;
        e->step = -1;
        e->clock = (int32_t)(S->plan->nsteps + 1 + k);
        e->paused = 1; /* released with the others at the interval's end */
        e->face = new_face(S, e);
        uint32_t other = c->out;
        c->out = se;
        e->start = ck;
        S->e[other].ver++;
        if (!grow((void **)&S->touched, &S->cap_touched, S->ntouched + 1, sizeof(uint32_t))) {
            fail(S, AG_ERR_NOMEM);
            return;
        }
        S->touched[S->ntouched++] = ck;
        size_t first = S->ntouched - 1;
        add_corner(S, se, other, px, py, c->z, c->vert);
        size_t last = S->ntouched;
        for (size_t t = first; t < last && S->st == AG_OK; t++)
            settle(S, S->touched[t]);
        S->stats.offset_sides++;
    }
}

/* --- profile offset events: the inside boundary ------------------------------------------- */

#define GAP_MARK (UINT32_MAX - 3)

/* Edge e's gap in offset event o (metres inwards) and its profiles after the event:
 * `inside` for the outer shell's face towards the gap, `inner` for the inner shell (-1:
 * e's own). */
static void gap_tuple(const ag_plan_offset *o, const sk_edge *e, double *from, double *to,
                      int32_t *inside, int32_t *inner)
{
    *from = o->gap_from;
    *to = o->gap_to;
    *inside = o->inside;
    *inner = o->inner;
    for (size_t i = 0; i < o->nedges && !e->step; i++) {
        const ag_offset_edge *x = &o->edges[i];
        if (x->loop != e->loop || x->edge != e->edge)
            continue;
        if (x->has_gap) {
            *from = x->gap_from;
            *to = x->gap_to;
        }
        if (x->inside)
            *inside = x->inside - 1;
        if (x->inner)
            *inner = x->inner - 1;
    }
}

/* One loop of an inset: corners (local plan coordinates) and, per corner i, the active
 * edge the inset's edge from corner i to i + 1 came from. */
typedef struct {
    size_t n, cap, cap_src;
    double *xy;
    uint32_t *src;
    size_t nloops, cap_loops;
    size_t *start; /* nloops + 1 */
} inset;

static void inset_free(inset *in)
{
    free(in->xy);
    free(in->src);
    free(in->start);
}

/* The active plan at virtual height v inset by each edge's distance (dist[i] for live edge
 * i), computed as the cross-section at height 1 of a sweep whose edges rise at slope
 * dist: the same engine keeps the inset's topology (splits, vanishing parts) right. */
static ag_status inset_plan(sk *S, double v, const double *dist, const uint32_t *slot,
                            inset *out, char *why, size_t nwhy)
{
    memset(out, 0, sizeof *out);
    ag_plan *P = ag_plan_create();
    double *xy = malloc(2 * (S->nlive_e + 1) * sizeof *xy);
    int32_t *pr = malloc((S->nlive_e + 1) * sizeof *pr);
    uint8_t *seen = calloc(S->nlive_e + 1, 1);
    ag_shell *sh = NULL;
    ag_error e2 = {0};
    ag_status st = P && xy && pr && seen ? AG_OK : AG_ERR_NOMEM;
    for (size_t i = 0; i < S->nlive_e && st == AG_OK; i++) {
        char name[24];
        snprintf(name, sizeof name, "g%zu", i);
        ag_profile_point pts[2] = {{0, 0}, {dist[i], 1}};
        st = ag_plan_add_profile(P, name, pts, 2, NULL, NULL, &e2);
    }
    for (size_t i = 0; i < S->nlive_e && st == AG_OK; i++) {
        if (seen[i])
            continue;
        size_t n = 0;
        uint32_t ei = S->live_e[i];
        for (;;) {
            const sk_edge *e = &S->e[ei];
            uint32_t q = slot[ei];
            if (q != NONE && seen[q])
                break;
            if (q == NONE || e->start == NONE || e->end == NONE || n >= S->nlive_e) {
                st = AG_ERR_INTERNAL;
                snprintf(why, nwhy, "the active plan does not close into loops");
                break;
            }
            seen[q] = 1;
            cpos(&S->c[e->start], v, &xy[2 * n], &xy[2 * n + 1]);
            pr[n++] = (int32_t)q;
            ei = S->c[e->end].out;
        }
        if (st == AG_OK && n >= 3)
            st = ag_plan_add_loop(P, xy, n, pr, &e2);
    }
    double extent = 0;
    if (st == AG_OK && P->nloops) {
        P->cap_height = 1;
        st = ag_plan_validate(P, NULL, &extent, &e2);
        if (st == AG_OK)
            st = ag_skeleton_build(P, extent, NULL, &sh, NULL, &e2);
    }
    if (st != AG_OK && !why[0])
        snprintf(why, nwhy, "%.120s", e2.text[0] ? e2.text : "out of memory");
    /* the cap's loops; each cap edge's twin is the side face of the edge it came from */
    for (size_t f = 0; sh && st == AG_OK && f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        if (fc->kind != AG_SHELL_FACE_CAP)
            continue;
        for (uint32_t l = fc->first_loop; l < fc->first_loop + (fc->nloops & 0x7fffffffu); l++) {
            uint32_t a = sh->loop_start[l], b = sh->loop_start[l + 1];
            size_t first = out->n;
            for (uint32_t h = a; h < b && st == AG_OK; h++) {
                uint32_t t = sh->he_twin[h];
                if (t == UINT32_MAX || sh->faces[sh->he_face[t]].profile < 0) {
                    st = AG_ERR_INTERNAL;
                    snprintf(why, nwhy, "the inset is not closed");
                    break;
                }
                uint32_t src = (uint32_t)sh->faces[sh->he_face[t]].profile;
                /* a corner between two pieces of one edge's line is no corner */
                uint32_t hp = h == a ? b - 1 : h - 1, tp = sh->he_twin[hp];
                if (tp != UINT32_MAX && sh->he_face[tp] == sh->he_face[t])
                    continue;
                if (!grow((void **)&out->xy, &out->cap, out->n + 1, 2 * sizeof *out->xy)) {
                    st = AG_ERR_NOMEM;
                    break;
                }
                if (!grow((void **)&out->src, &out->cap_src, out->n + 1, sizeof *out->src)) {
                    st = AG_ERR_NOMEM;
                    break;
                }
                out->xy[2 * out->n] = sh->pos[3 * sh->idx[h]];
                out->xy[2 * out->n + 1] = sh->pos[3 * sh->idx[h] + 1];
                out->src[out->n++] = src;
            }
            if (st != AG_OK)
                break;
            if (out->n - first < 3) {
                out->n = first; /* nothing left of it */
                continue;
            }
            if (!grow((void **)&out->start, &out->cap_loops, out->nloops + 2, sizeof *out->start)) {
                st = AG_ERR_NOMEM;
                break;
            }
            out->start[out->nloops] = first;
            out->start[++out->nloops] = out->n;
        }
    }
    if (st == AG_ERR_NOMEM && !why[0])
        snprintf(why, nwhy, "out of memory");
    ag_shell_free(sh);
    ag_plan_free(P);
    free(xy);
    free(pr);
    free(seen);
    return st;
}

/* At the end of offset event k's interval (virtual height v): opens the gap. The inset
 * at gap_from, reversed, becomes the outer shell's inner boundary; the inset at gap_to
 * the inner shell's boundary; the ring between them gets a floor facing up. Both insets
 * lie strictly inside the active plan, so nothing is crossed when they are put in. */
static void insert_gap(sk *S, size_t k, double v)
{
    const ag_plan_offset *o = &S->plan->offsets[k];
    compact_live(S);
    size_t n = S->nlive_e;
    if (!n)
        return;
    int32_t clock = (int32_t)(S->plan->nsteps + 1 + k);
    double *d = malloc(2 * n * sizeof *d);
    int32_t *pin = malloc(2 * n * sizeof *pin);
    uint32_t *slot = malloc(S->ne * sizeof *slot);
    inset ins[2];
    memset(ins, 0, sizeof ins);
    char why[160] = "";
    ag_status st = d && pin && slot ? AG_OK : AG_ERR_NOMEM;
    for (size_t i = 0; st == AG_OK && i < S->ne; i++)
        slot[i] = NONE;
    for (size_t i = 0; st == AG_OK && i < n; i++) {
        slot[S->live_e[i]] = (uint32_t)i;
        gap_tuple(o, &S->e[S->live_e[i]], &d[i], &d[n + i], &pin[i], &pin[n + i]);
    }
    if (st == AG_OK)
        st = inset_plan(S, v, d, slot, &ins[0], why, sizeof why);
    if (st == AG_OK)
        st = inset_plan(S, v, d + n, slot, &ins[1], why, sizeof why);
    if (st != AG_OK) {
        ag_error_set(S->err, st == AG_ERR_NOMEM ? AG_ERR_NOMEM : AG_ERR_INVALID, (long)k + 1,
                     "offset %zu at height %g: the inside boundary could not be made (%s)", k,
                     o->z, why[0] ? why : "out of memory");
        fail(S, st == AG_ERR_NOMEM ? AG_ERR_NOMEM : AG_ERR_INVALID);
        goto out;
    }
    if (!ins[0].nloops)
        goto out; /* the active plan is narrower than the gap's start: no gap */
    S->stats.offset_gaps++;
    ag_shell_face ff = {AG_SHELL_FACE_CAP, -1, -1, o->inside, -1, 0, 0};
    uint32_t floor_face = 0;
    if (ag_shell_add_face(S->shell, &ff, &floor_face) != AG_OK) {
        fail(S, AG_ERR_NOMEM);
        goto out;
    }
    size_t first_new = S->ntouched;
    for (int side = 0; side < 2 && S->st == AG_OK; side++) {
        const inset *in = &ins[side];
        for (size_t L = 0; L < in->nloops && S->st == AG_OK; L++) {
            size_t a = in->start[L], m = in->start[L + 1] - a;
            uint32_t v0 = (uint32_t)S->shell->nverts, e0 = (uint32_t)S->ne;
            for (size_t j = 0; j < m; j++)
                vertex(S, in->xy[2 * (a + j)], in->xy[2 * (a + j) + 1], v);
            for (size_t j = 0; j < m && S->st == AG_OK; j++) {
                size_t jn = (j + 1) % m;
                const double *p = &in->xy[2 * (a + j)], *q = &in->xy[2 * (a + jn)];
                uint32_t src = S->live_e[in->src[a + j]];
                uint32_t id = add_edge(S);
                if (id == NONE)
                    break;
                sk_edge *e = &S->e[id];
                const sk_edge *E = &S->e[src];
                double len = hypot(q[0] - p[0], q[1] - p[1]);
                /* the outer shell's boundary runs backwards: its inside is towards the plan's */
                double sg = side == 0 ? -1 : 1;
                e->nx = sg * -(q[1] - p[1]) / len;
                e->ny = sg * (q[0] - p[0]) / len;
                e->loop = E->loop;
                e->edge = E->edge;
                e->step = E->step;
                int32_t prof = pin[(size_t)side * n + in->src[a + j]];
                if (prof >= 0) {
                    e->profile = prof;
                    e->seg = 0;
                    e->clock = clock;
                    e->s = seg_slope(&S->plan->profiles[prof], 0);
                } else {
                    e->profile = E->profile;
                    e->seg = E->seg;
                    e->clock = E->clock;
                    e->s = E->s;
                }
                e->c = e->nx * p[0] + e->ny * p[1] - e->s * v;
                e->face = new_face(S, e);
                uint32_t vp = v0 + (uint32_t)j, vq = v0 + (uint32_t)jn;
                if (side == 0) {
                    seg(S, e->face, vq, vp);
                    seg(S, floor_face, vp, vq);
                } else {
                    seg(S, e->face, vp, vq);
                    seg(S, floor_face, vq, vp);
                }
            }
            if (S->st != AG_OK || S->ne != e0 + m)
                break;
            for (size_t j = 0; j < m && S->st == AG_OK; j++) {
                uint32_t ej = e0 + (uint32_t)j, eprev = e0 + (uint32_t)((j + m - 1) % m);
                const double *p = &in->xy[2 * (a + j)];
                if (side == 0)
                    add_corner(S, ej, eprev, p[0], p[1], v, v0 + (uint32_t)j);
                else
                    add_corner(S, eprev, ej, p[0], p[1], v, v0 + (uint32_t)j);
            }
        }
    }
    size_t last_new = S->ntouched;
    for (size_t i = first_new; i < last_new && S->st == AG_OK; i++)
        settle(S, S->touched[i]);
out:
    inset_free(&ins[0]);
    inset_free(&ins[1]);
    free(d);
    free(pin);
    free(slot);
}

/* --- plan edits (natural steps) ----------------------------------------------------------- */

/* Finds the active piece of an anchor's edge at height z and the point on it (local
 * coordinates); returns the edge or NONE. */
static uint32_t anchor_point(sk *S, const ag_anchor *a, double z, double *px, double *py);

#define STEP_SEED 1e-3 /* side of the protrusion a natural step grows from */

static uint32_t make_edge(sk *S, double ax, double ay, double bx, double by, double slope, double z,
                          int32_t step, int32_t profile, int growing)
{
    uint32_t id = add_edge(S);
    if (id == NONE)
        return NONE;
    sk_edge *e = &S->e[id];
    double len = hypot(bx - ax, by - ay);
    e->nx = -(by - ay) / len;
    e->ny = (bx - ax) / len;
    e->s = slope;
    e->c = e->nx * ax + e->ny * ay - slope * z;
    e->loop = -1;
    e->edge = step - 1;
    e->profile = profile;
    e->seg = 0;
    e->step = step;
    e->clock = step;
    e->growing = (uint8_t)growing;
    e->face = new_face(S, e);
    return id;
}

/* At the start of a flat interval: a tiny protrusion (or recess) is put into the active
 * edge at each natural step's anchor; during the interval it grows to the step's width
 * and depth while the other edges wait, so it meets the rest of the plan through the
 * ordinary events and cannot make the plan self-intersect. */
static void insert_steps(sk *S, double v)
{
    const ag_plan *P = S->plan;
    for (size_t k = 0; k < P->nsteps && S->st == AG_OK; k++) {
        const ag_plan_step *st = &P->steps[k];
        if (st->npoints)
            continue; /* forced: see forced_step */
        size_t fk = 0;
        while (fk < S->nflat && S->flat_h[fk] != st->at.z)
            fk++;
        if (fk == S->nflat || fabs(S->flat_h[fk] + (double)fk - v) > 1e-9)
            continue;
        compact_live(S);
        double x, y;
        uint32_t ei = anchor_point(S, &st->at, v, &x, &y);
        if (ei == NONE) {
            S->stats.steps_skipped++;
            continue;
        }
        sk_edge *e = &S->e[ei];
        double dx = edx(e), dy = edy(e), h = STEP_SEED / 2;
        double sx, sy, ex, ey;
        cpos(&S->c[e->start], v, &sx, &sy);
        cpos(&S->c[e->end], v, &ex, &ey);
        double t = dx * (x - sx) + dy * (y - sy), len = dx * (ex - sx) + dy * (ey - sy);
        if (t - h < 10 * S->d3 || t + h > len - 10 * S->d3) {
            S->stats.steps_skipped++;
            continue;
        }
        double out = st->depth > 0 ? -1 : 1; /* protrusion: outwards (-n) */
        double ax = x - h * dx, ay = y - h * dy, bx = x + h * dx, by = y + h * dy;
        double a2x = ax + out * STEP_SEED * e->nx, a2y = ay + out * STEP_SEED * e->ny;
        double b2x = bx + out * STEP_SEED * e->nx, b2y = by + out * STEP_SEED * e->ny;
        /* growth over the unit interval: sides to the width, front to the depth; a
         * protrusion's edges move outwards (negative slope), a recess's inwards */
        double side = (st->width / 2 - h) * (st->depth > 0 ? -1 : 1);
        double front = (fabs(st->depth) - STEP_SEED) * (st->depth > 0 ? -1 : 1);
        int32_t sid = (int32_t)k + 1;
        uint32_t e2 = add_edge(S);
        uint32_t s1 = make_edge(S, ax, ay, a2x, a2y, side, v, sid, st->profile, 1);
        uint32_t f = make_edge(S, a2x, a2y, b2x, b2y, front, v, sid, st->profile, 1);
        uint32_t s2 = make_edge(S, b2x, b2y, bx, by, side, v, sid, st->profile, 1);
        if (e2 == NONE || s1 == NONE || f == NONE || s2 == NONE)
            return;
        e = &S->e[ei];
        sk_edge *g = &S->e[e2];
        *g = *e;
        g->ver = 0;
        g->alive = 1;
        g->end = e->end;
        S->c[e->end].in = e2;
        uint32_t va = vertex(S, ax, ay, v), va2 = vertex(S, a2x, a2y, v);
        uint32_t vb2 = vertex(S, b2x, b2y, v), vb = vertex(S, bx, by, v);
        ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, (int32_t)k, st->profile, -1, 0, 0};
        uint32_t floor = 0;
        if (ag_shell_add_face(S->shell, &ff, &floor) != AG_OK) {
            fail(S, AG_ERR_NOMEM);
            return;
        }
        seg(S, e->face, vb, va); /* the piece of the edge the step replaces */
        seg(S, floor, va, vb);
        seg(S, floor, vb, vb2);
        seg(S, floor, vb2, va2);
        seg(S, floor, va2, va);
        seg(S, S->e[s1].face, va, va2);
        seg(S, S->e[f].face, va2, vb2);
        seg(S, S->e[s2].face, vb2, vb);
        size_t first = S->ntouched;
        add_corner(S, ei, s1, ax, ay, v, va);
        add_corner(S, s1, f, a2x, a2y, v, va2);
        add_corner(S, f, s2, b2x, b2y, v, vb2);
        add_corner(S, s2, e2, bx, by, v, vb);
        size_t last = S->ntouched;
        for (size_t i = first; i < last && S->st == AG_OK; i++)
            settle(S, S->touched[i]);
        S->stats.steps++;
    }
}

/* --- plan edits (forced steps) ------------------------------------------------------------ */

#define FORCED_MARK (UINT32_MAX - 1)

typedef struct {
    double x, y;
    double te, tq;     /* parameters along the active edge and along the polygon edge */
    uint32_t e;        /* active edge crossed */
    uint32_t qi;       /* polygon edge crossing it */
    uint32_t vert;
    int enters;        /* the active edge enters the polygon here */
    uint32_t p_before, p_after, q_before, q_after;
} xing;

static int cmp_xing_e(const void *a, const void *b)
{
    const xing *x = *(const xing *const *)a, *y = *(const xing *const *)b;
    if (x->e != y->e)
        return x->e < y->e ? -1 : 1;
    return x->te < y->te ? -1 : x->te > y->te;
}

static int cmp_xing_q(const void *a, const void *b)
{
    const xing *x = *(const xing *const *)a, *y = *(const xing *const *)b;
    if (x->qi != y->qi)
        return x->qi < y->qi ? -1 : 1;
    return x->tq < y->tq ? -1 : x->tq > y->tq;
}

static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(ax + t * dx - px, ay + t * dy - py);
}

/* Is (x, y) inside the active plan at height v? Even-odd over the live edges. */
static int in_active(sk *S, double v, double x, double y)
{
    int in = 0;
    for (size_t i = 0; i < S->nlive_e; i++) {
        const sk_edge *e = &S->e[S->live_e[i]];
        double ax, ay, bx, by;
        cpos(&S->c[e->start], v, &ax, &ay);
        cpos(&S->c[e->end], v, &bx, &by);
        if ((ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay))
            in = !in;
    }
    return in;
}

static uint32_t forced_edge(sk *S, double ax, double ay, double bx, double by, double v,
                            const ag_plan_step *st, int32_t sid)
{
    double slope = seg_slope(&S->plan->profiles[st->profile], 0);
    return make_edge(S, ax, ay, bx, by, slope, v, sid, st->profile, 0);
}

/* Unites the step's polygon Q with the active plan at virtual height v: active edges are
 * cut where Q crosses them, the parts inside Q end (their faces closed at v), Q's parts
 * outside the plan become new edges with the step's profile, and Q minus the plan gets a
 * floor face. Near-touching configurations are refused (skipped) rather than guessed. */
static void forced_step(sk *S, size_t k, double v)
{
    const ag_plan_step *st = &S->plan->steps[k];
    size_t n = st->npoints;
    compact_live(S);
    double *q = malloc(2 * n * sizeof *q);
    if (!q) {
        fail(S, AG_ERR_NOMEM);
        return;
    }
    xing *X = NULL, **byE = NULL, **byQ = NULL;
    size_t nx = 0, capx = 0;
    uint32_t *cvert = NULL, *qin = NULL, *qout = NULL, *qvert = NULL;
    uint8_t *cin = NULL, *qinside = NULL;
    /* the polygon in local plan coordinates, counter-clockwise */
    if (st->plan_frame) {
        for (size_t i = 0; i < n; i++) {
            q[2 * i] = st->points[2 * i] - S->ox;
            q[2 * i + 1] = st->points[2 * i + 1] - S->oy;
        }
    } else {
        double ax, ay;
        uint32_t ei = anchor_point(S, &st->at, v, &ax, &ay);
        if (ei == NONE)
            goto skip;
        const sk_edge *e = &S->e[ei];
        double dx = edx(e), dy = edy(e);
        for (size_t i = 0; i < n; i++) {
            double u = st->points[2 * i], w = st->points[2 * i + 1];
            q[2 * i] = ax + u * dx - w * e->nx;
            q[2 * i + 1] = ay + u * dy - w * e->ny;
        }
    }
    double area = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        area += q[2 * i] * q[2 * j + 1] - q[2 * j] * q[2 * i + 1];
    }
    if (area < 0)
        for (size_t i = 0; i < n / 2; i++)
            for (int c = 0; c < 2; c++) {
                double t = q[2 * i + c];
                q[2 * i + c] = q[2 * (n - 1 - i) + c];
                q[2 * (n - 1 - i) + c] = t;
            }
    double tol = 10 * S->d3;
    /* crossings; anything closer than tol that is not a clean crossing is refused */
    for (size_t i = 0; i < S->nlive_e; i++) {
        uint32_t ei = S->live_e[i];
        const sk_edge *e = &S->e[ei];
        double a[2], b[2];
        cpos(&S->c[e->start], v, &a[0], &a[1]);
        cpos(&S->c[e->end], v, &b[0], &b[1]);
        for (size_t j = 0; j < n; j++) {
            const double *c = &q[2 * j], *d = &q[2 * ((j + 1) % n)];
            if (seg_dist(c[0], c[1], a[0], a[1], b[0], b[1]) <= tol ||
                seg_dist(a[0], a[1], c[0], c[1], d[0], d[1]) <= tol)
                goto skip;
            double oa = ag_pred_orient2d(c, d, a), ob = ag_pred_orient2d(c, d, b);
            double oc = ag_pred_orient2d(a, b, c), od = ag_pred_orient2d(a, b, d);
            /* every corner is some edge's first: the tests above covered all corner to
             * edge distances, so the signs here are clear */
            if ((oa > 0) == (ob > 0) || (oc > 0) == (od > 0))
                continue;
            if (!grow((void **)&X, &capx, nx + 1, sizeof *X)) {
                fail(S, AG_ERR_NOMEM);
                goto out;
            }
            xing *x = &X[nx++];
            memset(x, 0, sizeof *x);
            x->te = oa / (oa - ob);
            x->tq = oc / (oc - od);
            x->x = a[0] + x->te * (b[0] - a[0]);
            x->y = a[1] + x->te * (b[1] - a[1]);
            x->e = ei;
            x->qi = (uint32_t)j;
            x->enters = oa < 0; /* the active edge starts right of Q's edge: outside Q */
            x->p_before = x->p_after = x->q_before = x->q_after = NONE;
        }
    }
    /* corners of the active plan inside Q, Q's corners inside the plan */
    cin = calloc(S->nc ? S->nc : 1, 1);
    cvert = malloc((S->nc ? S->nc : 1) * sizeof *cvert);
    qin = malloc(n * sizeof *qin);
    qout = malloc(n * sizeof *qout);
    qvert = malloc(n * sizeof *qvert);
    qinside = malloc(2 * n); /* n corners, then n edges without crossings */
    byE = malloc((nx ? nx : 1) * sizeof *byE);
    byQ = malloc((nx ? nx : 1) * sizeof *byQ);
    if (!cin || !cvert || !qin || !qout || !qvert || !qinside || !byE || !byQ) {
        fail(S, AG_ERR_NOMEM);
        goto out;
    }
    int any_out = 0;
    for (size_t i = 0; i < n; i++) {
        size_t i2 = (i + 1) % n;
        qinside[i] = (uint8_t)in_active(S, v, q[2 * i], q[2 * i + 1]);
        qinside[n + i] = (uint8_t)in_active(S, v, (q[2 * i] + q[2 * i2]) / 2,
                                            (q[2 * i + 1] + q[2 * i2 + 1]) / 2);
        any_out |= !qinside[i];
        qin[i] = qout[i] = NONE;
    }
    int any_in = 0;
    for (size_t i = 0; i < S->nlive_c; i++) {
        uint32_t c = S->live_c[i];
        double x, y;
        cpos(&S->c[c], v, &x, &y);
        cin[c] = (uint8_t)ag_pred_point_in_polygon(q, n, x, y);
        any_in |= cin[c];
    }
    if (!nx && !any_out && !any_in) {
        goto skip; /* wholly inside the active plan: nothing changes */
    }
    for (size_t i = 0; i < nx; i++)
        byE[i] = byQ[i] = &X[i];
    qsort(byE, nx, sizeof *byE, cmp_xing_e);
    qsort(byQ, nx, sizeof *byQ, cmp_xing_q);
    /* the crossings must alternate in and out along every edge of either outline, and
     * agree with the sides its corners are on */
    int bad = 0;
    for (size_t i = 0; i < nx; i++) {
        const xing *a = byE[i], *b = byQ[i];
        if (i == 0 || byE[i - 1]->e != a->e)
            bad |= a->enters == cin[S->e[a->e].start];
        else
            bad |= a->enters == byE[i - 1]->enters;
        if (i + 1 == nx || byE[i + 1]->e != a->e)
            bad |= a->enters != cin[S->e[a->e].end];
        /* Q enters the plan where the active edge leaves Q */
        if (i == 0 || byQ[i - 1]->qi != b->qi)
            bad |= b->enters != qinside[b->qi];
        else
            bad |= b->enters == byQ[i - 1]->enters;
        if (i + 1 == nx || byQ[i + 1]->qi != b->qi)
            bad |= b->enters == qinside[(b->qi + 1) % n];
    }
    if (bad) {
        goto skip;
    }
    ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, (int32_t)k, st->profile, -1, 0, 0};
    uint32_t floor = 0;
    if (ag_shell_add_face(S->shell, &ff, &floor) != AG_OK) {
        fail(S, AG_ERR_NOMEM);
        goto out;
    }
    for (size_t i = 0; i < nx; i++)
        X[i].vert = vertex(S, X[i].x, X[i].y, v);
    /* corners inside Q end here */
    size_t nlive_c = S->nlive_c;
    for (size_t i = 0; i < nlive_c; i++) {
        uint32_t c = S->live_c[i];
        if (!cin[c])
            continue;
        double x, y;
        cpos(&S->c[c], v, &x, &y);
        cvert[c] = vertex(S, x, y, v);
        retire(S, c, cvert[c]);
    }
    /* the active edges: pieces inside Q are closed, pieces outside carry on */
    size_t nlive_e = S->nlive_e, xi = 0;
    for (size_t i = 0; i < nlive_e && S->st == AG_OK; i++) {
        uint32_t ei = S->live_e[i];
        size_t x0 = xi;
        while (xi < nx && byE[xi]->e == ei)
            xi++;
        uint32_t cs = S->e[ei].start, ce = S->e[ei].end;
        int inside = cin[cs];
        if (x0 == xi && !inside)
            continue;
        uint32_t cur = inside ? NONE : ei, va = inside ? cvert[cs] : NONE;
        for (size_t j = x0; j <= xi; j++) {
            int last = j == xi;
            uint32_t vb = last ? (cin[ce] ? cvert[ce] : NONE) : byE[j]->vert;
            if (inside) {
                uint32_t face = S->e[ei].face;
                seg(S, face, vb, va);
                seg(S, floor, va, vb);
                if (!last) {
                    /* an outside piece starts at this crossing: a copy of the edge */
                    uint32_t g = add_edge(S);
                    if (g == NONE)
                        break;
                    S->e[g] = S->e[ei];
                    S->e[g].ver = 0;
                    S->e[g].alive = 1;
                    S->e[g].start = S->e[g].end = NONE;
                    byE[j]->p_after = g;
                    cur = g;
                }
            } else {
                if (last) {
                    S->e[cur].end = ce;
                    S->c[ce].in = cur;
                    S->e[cur].ver++;
                } else {
                    byE[j]->p_before = cur;
                    S->e[cur].ver++;
                    cur = NONE;
                }
            }
            va = vb;
            inside = !inside;
        }
        if (cin[cs])
            kill_edge(S, ei); /* its outside pieces, if any, carry on as copies */
    }
    /* Q's pieces outside the active plan become edges */
    int32_t sid = (int32_t)k + 1;
    for (size_t i = 0; i < n; i++)
        qvert[i] = NONE;
    xi = 0;
    for (size_t i = 0; i < n && S->st == AG_OK; i++) {
        size_t x0 = xi;
        while (xi < nx && byQ[xi]->qi == i)
            xi++;
        size_t i2 = (i + 1) % n;
        /* inside at Q's corner i: Q enters the plan where the active edge leaves Q */
        int inside = x0 < xi ? byQ[x0]->enters : qinside[n + i];
        double ax = q[2 * i], ay = q[2 * i + 1];
        uint32_t va = NONE;
        if (!inside) {
            if (qvert[i] == NONE)
                qvert[i] = vertex(S, ax, ay, v);
            va = qvert[i];
        }
        for (size_t j = x0; j <= xi; j++) {
            int last = j == xi;
            double bx = last ? q[2 * i2] : byQ[j]->x, by = last ? q[2 * i2 + 1] : byQ[j]->y;
            uint32_t vb;
            if (last) {
                if (!inside && qvert[i2] == NONE)
                    qvert[i2] = vertex(S, bx, by, v);
                vb = qvert[i2];
            } else {
                vb = byQ[j]->vert;
            }
            if (!inside) {
                uint32_t g = forced_edge(S, ax, ay, bx, by, v, st, sid);
                if (g == NONE)
                    goto out;
                seg(S, S->e[g].face, va, vb);
                seg(S, floor, vb, va);
                if (j == x0)
                    qout[i] = g;
                else
                    byQ[j - 1]->q_after = g;
                if (last)
                    qin[i2] = g;
                else
                    byQ[j]->q_before = g;
            }
            ax = bx;
            ay = by;
            va = vb;
            inside = !inside;
        }
    }
    /* the new corners: at the crossings and at Q's corners outside the plan */
    size_t first = S->ntouched;
    for (size_t i = 0; i < nx && S->st == AG_OK; i++) {
        xing *x = &X[i];
        uint32_t in = x->enters ? x->p_before : x->q_before;
        uint32_t out = x->enters ? x->q_after : x->p_after;
        if (in == NONE || out == NONE) {
            ag_error_set(S->err, AG_ERR_INTERNAL, 0, "forced step %zu: inconsistent crossing at "
                         "(%.6f, %.6f)", k, x->x + S->ox, x->y + S->oy);
            fail(S, AG_ERR_INTERNAL);
            goto out;
        }
        add_corner(S, in, out, x->x, x->y, v, x->vert);
    }
    for (size_t i = 0; i < n && S->st == AG_OK; i++)
        if (qin[i] != NONE && qout[i] != NONE)
            add_corner(S, qin[i], qout[i], q[2 * i], q[2 * i + 1], v, qvert[i]);
    size_t last = S->ntouched;
    for (size_t i = first; i < last && S->st == AG_OK; i++)
        settle(S, S->touched[i]);
    S->stats.steps++;
    goto out;
skip:
    S->stats.steps_skipped++;
out:
    free(q);
    free(X);
    free(byE);
    free(byQ);
    free(cin);
    free(cvert);
    free(qin);
    free(qout);
    free(qvert);
    free(qinside);
}

/* --- anchors ----------------------------------------------------------------------------- */

static uint32_t anchor_point(sk *S, const ag_anchor *a, double z, double *px, double *py)
{
    if (a->loop < 0 || (size_t)a->loop >= S->plan->nloops || a->edge < 0 ||
        (size_t)a->edge >= S->plan->loops[a->loop].n)
        return NONE;
    const ag_plan_loop *lp = &S->plan->loops[a->loop];
    size_t i = (size_t)a->edge, j = (i + 1) % lp->n;
    double bx = lp->xy[2 * i] - S->ox, by = lp->xy[2 * i + 1] - S->oy;
    double ex = lp->xy[2 * j] - S->ox, ey = lp->xy[2 * j + 1] - S->oy;
    double len = hypot(ex - bx, ey - by), dx = (ex - bx) / len, dy = (ey - by) / len;
    /* the pieces of this edge in the active plan, as parameters along its direction */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t q = 0; q < S->nlive_e; q++) {
        const sk_edge *e = &S->e[S->live_e[q]];
        if (!e->alive || e->step || e->loop != a->loop || e->edge != a->edge)
            continue;
        double ax, ay, cx, cy;
        cpos(&S->c[e->start], z, &ax, &ay);
        cpos(&S->c[e->end], z, &cx, &cy);
        lo = fmin(lo, dx * (ax - bx) + dy * (ay - by));
        hi = fmax(hi, dx * (cx - bx) + dy * (cy - by));
    }
    if (!(hi > lo))
        return NONE;
    double t = a->absolute ? a->along : lo + a->along * (hi - lo);
    for (size_t q = 0; q < S->nlive_e; q++) {
        uint32_t id = S->live_e[q];
        const sk_edge *e = &S->e[id];
        if (!e->alive || e->step || e->loop != a->loop || e->edge != a->edge)
            continue;
        double ax, ay, cx, cy;
        cpos(&S->c[e->start], z, &ax, &ay);
        cpos(&S->c[e->end], z, &cx, &cy);
        double t0 = dx * (ax - bx) + dy * (ay - by), t1 = dx * (cx - bx) + dy * (cy - by);
        if (t < t0 - S->d3 || t > t1 + S->d3)
            continue;
        /* the point on the edge's line at this height */
        double off = e->c + e->s * z - (e->nx * bx + e->ny * by);
        *px = bx + t * dx + off * e->nx;
        *py = by + t * dy + off * e->ny;
        return id;
    }
    return NONE;
}

static void locate_anchor(sk *S, ag_anchor *a, double z)
{
    double x, y;
    uint32_t id = anchor_point(S, a, z, &x, &y);
    if (id == NONE)
        return;
    const sk_edge *e = &S->e[id];
    a->found = 1;
    a->pos[0] = x + S->ox;
    a->pos[1] = y + S->oy;
    a->pos[2] = real_z(S, z);
    /* the face's outward normal: the plane n.p - s z = c, pointing away from inside */
    double nl = sqrt(1 + e->s * e->s);
    a->normal[0] = -e->nx / nl;
    a->normal[1] = -e->ny / nl;
    a->normal[2] = e->s / nl;
    a->face = (int32_t)e->face;
    a->tangent[0] = edx(e);
    a->tangent[1] = edy(e);
    a->tangent[2] = 0;
}

/* --- the cap ----------------------------------------------------------------------------- */

static void cap(sk *S, double z)
{
    compact_live(S);
    if (!S->nlive_e)
        return;
    S->stats.capped = 1;
    ag_shell_face f = {AG_SHELL_FACE_CAP, -1, -1, -1, -1, 0, 0};
    uint32_t face = 0;
    if (ag_shell_add_face(S->shell, &f, &face) != AG_OK) {
        fail(S, AG_ERR_NOMEM);
        return;
    }
    uint32_t *verts = calloc(S->nc ? S->nc : 1, sizeof *verts);
    if (!verts) {
        fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < S->nlive_c; i++) {
        uint32_t k = S->live_c[i];
        double x, y;
        cpos(&S->c[k], z, &x, &y);
        verts[k] = vertex(S, x, y, z);
        retire(S, k, verts[k]);
    }
    for (size_t i = 0; i < S->nlive_e; i++) {
        sk_edge *e = &S->e[S->live_e[i]];
        seg(S, e->face, verts[e->end], verts[e->start]);
        seg(S, face, verts[e->start], verts[e->end]);
        e->alive = 0;
    }
    free(verts);
}

/* --- driver ------------------------------------------------------------------------------ */

static int cmp_event_x(const void *a, const void *b)
{
    double x = ((const ag_event *)a)->x, y = ((const ag_event *)b)->x;
    return x < y ? -1 : x > y;
}

typedef struct {
    double z;
    uint32_t root, i;
} gsort;

static int cmp_gsort(const void *a, const void *b)
{
    const gsort *x = a, *y = b;
    if (x->z != y->z)
        return x->z < y->z ? -1 : 1;
    if (x->root != y->root)
        return x->root < y->root ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static uint32_t uf_find(uint32_t *p, uint32_t x)
{
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

/* Plan speed of the fastest corner an intersection event moves (m per unit of height). */
static double event_speed(const sk *S, const ag_event *ev)
{
    uint32_t ks[2] = {ev->a, NONE};
    if (ev->type == AG_EVENT_EDGE) {
        ks[0] = S->e[ev->a].start;
        ks[1] = S->e[ev->a].end;
    }
    double v = 0;
    for (int j = 0; j < 2; j++)
        if (ks[j] != NONE)
            v = fmax(v, hypot(S->c[ks[j]].vx, S->c[ks[j]].vy));
    return v;
}

static int event_valid(sk *S, const ag_event *ev)
{
    if (ev->type == AG_EVENT_EDGE)
        return S->e[ev->a].alive && S->e[ev->a].ver == ev->ver;
    if (ev->type == AG_EVENT_SPLIT)
        return S->c[ev->a].alive && S->e[ev->b].alive && S->e[ev->b].ver == ev->ver;
    return 1;
}

ag_status ag_skeleton_build(const ag_plan *plan, double extent, const ag_skeleton_options *opt,
                            ag_shell **out, ag_skeleton_stats *stats, ag_error *err)
{
    *out = NULL;
    sk S;
    memset(&S, 0, sizeof S);
    S.plan = plan;
    S.err = err;
    double scale = ag_extrude_scale(extent);
    S.d1 = AG_EXTRUDE_DELTA1 * scale;
    S.d2 = AG_EXTRUDE_DELTA2 * scale;
    S.d3 = AG_EXTRUDE_DELTA3 * scale;
    S.shell = ag_shell_create();
    if (!S.shell)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* local origin: the first corner */
    S.ox = plan->loops[0].xy[0];
    S.oy = plan->loops[0].xy[1];
    size_t ncorners = 0;
    ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, -1, -1, -1, 0, 0};
    uint32_t floor_face = 0;
    if (ag_shell_add_face(S.shell, &ff, &floor_face) != AG_OK)
        fail(&S, AG_ERR_NOMEM);
    /* heights with a horizontal segment, ascending and distinct */
    size_t maxflat = 0;
    for (size_t i = 0; i < plan->nprofiles; i++)
        maxflat += plan->profiles[i].npoints;
    S.flat_h = malloc((maxflat ? maxflat : 1) * sizeof *S.flat_h);
    if (!S.flat_h)
        fail(&S, AG_ERR_NOMEM);
    for (size_t i = 0; i < plan->nprofiles && S.flat_h; i++) {
        const ag_profile *p = &plan->profiles[i];
        for (size_t j = 0; j + 1 < p->npoints; j++) {
            if (!seg_flat(p, (int32_t)j))
                continue;
            double h = p->points[j].z;
            size_t k = 0;
            while (k < S.nflat && S.flat_h[k] < h)
                k++;
            if (k < S.nflat && S.flat_h[k] == h)
                continue;
            memmove(&S.flat_h[k + 1], &S.flat_h[k], (S.nflat - k) * sizeof *S.flat_h);
            S.flat_h[k] = h;
            S.nflat++;
        }
    }
    for (size_t k = 0; k < plan->nsteps && S.flat_h; k++) {
        if (plan->steps[k].npoints)
            continue; /* forced steps are not grown */
        double h = plan->steps[k].at.z;
        size_t q = 0;
        while (q < S.nflat && S.flat_h[q] < h)
            q++;
        if (q < S.nflat && S.flat_h[q] == h)
            continue;
        double *nf = realloc(S.flat_h, (S.nflat + 1 + maxflat) * sizeof *nf);
        if (!nf) {
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        S.flat_h = nf;
        memmove(&S.flat_h[q + 1], &S.flat_h[q], (S.nflat - q) * sizeof *S.flat_h);
        S.flat_h[q] = h;
        S.nflat++;
    }
    /* offset events: a flat interval each, of their own */
    for (size_t k = 0; k < plan->noffsets && S.flat_h && S.st == AG_OK; k++) {
        double h = plan->offsets[k].z;
        size_t q = 0;
        while (q < S.nflat && S.flat_h[q] < h)
            q++;
        if (q < S.nflat && S.flat_h[q] == h) {
            ag_error_set(err, AG_ERR_INVALID, (long)k + 1,
                         "offset %zu at height %g coincides with a horizontal profile segment, a "
                         "natural step or another offset there (move it)", k, h);
            fail(&S, AG_ERR_INVALID);
            break;
        }
        double *nf = realloc(S.flat_h, (S.nflat + 1 + maxflat) * sizeof *nf);
        if (!nf) {
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        S.flat_h = nf;
        memmove(&S.flat_h[q + 1], &S.flat_h[q], (S.nflat - q) * sizeof *S.flat_h);
        S.flat_h[q] = h;
        S.nflat++;
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        const ag_plan_step *st = &plan->steps[k];
        const ag_profile *p = &plan->profiles[st->profile];
        for (size_t j = 1; j + 1 < p->npoints; j++) {
            ag_event ev = {0};
            ev.type = AG_EVENT_DIRECTION;
            ev.z = virtual_z(&S, st->at.z + p->points[j].z, 1);
            ev.a = (uint32_t)st->profile;
            ev.b = (uint32_t)j;
            ev.ver = (uint32_t)k + 1;
            push(&S, &ev);
        }
    }
    for (size_t k = 0; k < plan->noffsets && S.st == AG_OK; k++) {
        const ag_plan_offset *o = &plan->offsets[k];
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = OFFSET_MARK;
        ev.b = (uint32_t)k;
        ev.z = virtual_z(&S, o->z, 0);
        push(&S, &ev);
        if (o->has_gap) {
            ev.a = GAP_MARK; /* the gap opens when the interval ends */
            ev.z += 1;
            push(&S, &ev);
        }
        /* the profiles the event hands out count their heights from it */
        for (size_t e = 0; e < 3 * (o->nedges + 2); e++) {
            size_t x = e % (o->nedges + 2), which = e / (o->nedges + 2);
            int32_t pi;
            if (which == 0)
                pi = x == o->nedges ? o->profile : x == o->nedges + 1 ? o->side
                                                                      : o->edges[x].profile;
            else if (!o->has_gap || x == o->nedges + 1)
                continue;
            else if (which == 1)
                pi = x == o->nedges ? o->inside : o->edges[x].inside - 1;
            else
                pi = x == o->nedges ? o->inner : o->edges[x].inner - 1;
            if (pi < 0)
                continue;
            const ag_profile *pr = &plan->profiles[pi];
            for (size_t j = 1; j + 1 < pr->npoints; j++) {
                ag_event d = {0};
                d.type = AG_EVENT_DIRECTION;
                d.z = virtual_z(&S, o->z + pr->points[j].z, 1);
                d.a = (uint32_t)pi;
                d.b = (uint32_t)j;
                d.ver = (uint32_t)(plan->nsteps + 1 + k);
                push(&S, &d);
            }
        }
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        if (!plan->steps[k].npoints)
            continue;
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = FORCED_MARK;
        ev.b = (uint32_t)k;
        ev.z = virtual_z(&S, plan->steps[k].at.z, 1);
        push(&S, &ev);
    }
    for (size_t k = 0; k < S.nflat; k++) {
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = FLAT_MARK;
        ev.b = 0;
        ev.z = S.flat_h[k] + (double)k;
        push(&S, &ev);
        ev.b = 1;
        ev.z += 1;
        push(&S, &ev);
    }
    double top_profile = 0;
    for (size_t i = 0; i < plan->nprofiles; i++) {
        const ag_profile *p = &plan->profiles[i];
        top_profile = fmax(top_profile, virtual_z(&S, p->points[p->npoints - 1].z, 1));
        for (size_t j = 1; j + 1 < p->npoints; j++) {
            ag_event ev = {0};
            ev.type = AG_EVENT_DIRECTION;
            double z = p->points[j].z;
            if (seg_flat(p, (int32_t)j))
                ev.z = virtual_z(&S, z, 0); /* the flat interval starts */
            else if (seg_flat(p, (int32_t)j - 1))
                ev.z = virtual_z(&S, z, 0) + 1; /* it ends */
            else
                ev.z = virtual_z(&S, z, 1);
            ev.a = (uint32_t)i;
            ev.b = (uint32_t)j;
            push(&S, &ev);
        }
    }
    ag_anchor *anchors = opt ? opt->anchors : NULL;
    for (size_t i = 0; anchors && i < plan->nanchors; i++) {
        ag_event ev = {0};
        ev.type = AG_EVENT_ANCHOR;
        ev.z = virtual_z(&S, anchors[i].z, 0);
        ev.b = (uint32_t)i;
        anchors[i].found = 0;
        anchors[i].face = -1;
        push(&S, &ev);
    }
    for (size_t L = 0; L < plan->nloops && S.st == AG_OK; L++) {
        const ag_plan_loop *lp = &plan->loops[L];
        size_t n = lp->n;
        ncorners += n;
        uint32_t e0 = (uint32_t)S.ne;
        uint32_t v0 = (uint32_t)S.shell->nverts;
        for (size_t i = 0; i < n; i++)
            vertex(&S, lp->xy[2 * i] - S.ox, lp->xy[2 * i + 1] - S.oy, 0);
        for (size_t i = 0; i < n; i++) {
            uint32_t ei = add_edge(&S);
            if (ei == NONE)
                break;
            sk_edge *e = &S.e[ei];
            size_t j = (i + 1) % n;
            double dx = lp->xy[2 * j] - lp->xy[2 * i], dy = lp->xy[2 * j + 1] - lp->xy[2 * i + 1];
            double len = hypot(dx, dy);
            e->nx = -dy / len;
            e->ny = dx / len;
            const ag_profile *p = &plan->profiles[lp->profile[i]];
            e->s = seg_slope(p, 0);
            e->c = e->nx * (lp->xy[2 * i] - S.ox) + e->ny * (lp->xy[2 * i + 1] - S.oy);
            e->loop = (int32_t)L;
            e->edge = (int32_t)i;
            e->profile = lp->profile[i];
            e->seg = 0;
            e->face = new_face(&S, e);
            seg(&S, e->face, v0 + (uint32_t)i, v0 + (uint32_t)j);
            seg(&S, floor_face, v0 + (uint32_t)j, v0 + (uint32_t)i);
        }
        for (size_t i = 0; i < n && S.st == AG_OK; i++)
            add_corner(&S, e0 + (uint32_t)((i + n - 1) % n), e0 + (uint32_t)i,
                       lp->xy[2 * i] - S.ox, lp->xy[2 * i + 1] - S.oy, 0, v0 + (uint32_t)i);
    }
    for (size_t i = 0; i < S.ntouched && S.st == AG_OK; i++)
        settle(&S, S.touched[i]);
    schedule_touched(&S);

    size_t max_events = opt && opt->max_events ? opt->max_events : 64 * ncorners + 10000;
    size_t handled = 0;
    double limit = plan->cap_height > 0 ? virtual_z(&S, plan->cap_height, 0) : INFINITY;
    scratch W;
    memset(&W, 0, sizeof W);
    ag_event *batch = NULL;
    size_t cap_batch = 0;
    uint32_t *uf = NULL;
    size_t cap_uf = 0;
    while (S.st == AG_OK) {
        ag_event ev;
        if (!ag_eventq_pop(&S.q, &ev))
            break;
        if (!event_valid(&S, &ev))
            continue;
        if (ev.z > limit)
            break;
        if (++handled > max_events) {
            ag_error_set(err, AG_ERR_INTERNAL, 0,
                         "the sweep did not finish after %zu events (height %.4f)", max_events,
                         S.zcur);
            fail(&S, AG_ERR_INTERNAL);
            break;
        }
        if (ev.type == AG_EVENT_ANCHOR) {
            /* only observes: the sweep height stays where the last event left it */
            compact_live(&S);
            locate_anchor(&S, &anchors[ev.b], ev.z);
            continue;
        }
        if (ev.z > S.zcur)
            S.zcur = ev.z;
        size_t nb = 0;
        if (!grow((void **)&batch, &cap_batch, 1, sizeof *batch)) {
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        batch[nb++] = ev;
        const ag_event *top;
        int is_dir = ev.type == AG_EVENT_DIRECTION;
        while ((top = ag_eventq_peek(&S.q)) && top->z <= ev.z + S.d1 &&
               top->type != AG_EVENT_ANCHOR && (top->type == AG_EVENT_DIRECTION) == is_dir) {
            ag_event nx;
            ag_eventq_pop(&S.q, &nx);
            if (!event_valid(&S, &nx))
                continue;
            if (!grow((void **)&batch, &cap_batch, nb + 1, sizeof *batch)) {
                fail(&S, AG_ERR_NOMEM);
                break;
            }
            batch[nb++] = nx;
        }
        if (is_dir) {
            int only_forced = 1;
            for (size_t i = 0; i < nb; i++)
                only_forced &= batch[i].a == FORCED_MARK;
            if (!only_forced)
                direction(&S, batch, nb);
            for (size_t i = 0; i < nb && S.st == AG_OK; i++)
                if (batch[i].a == OFFSET_MARK) {
                    S.stats.offsets++;
                    insert_sides(&S, batch[i].b);
                }
            for (size_t i = 0; i < nb; i++)
                if (batch[i].a == FLAT_MARK && batch[i].b == 0)
                    insert_steps(&S, batch[i].z);
            for (size_t i = 0; i < nb && S.st == AG_OK; i++)
                if (batch[i].a == FORCED_MARK)
                    forced_step(&S, batch[i].b, batch[i].z);
            for (size_t i = 0; i < nb && S.st == AG_OK; i++)
                if (batch[i].a == GAP_MARK)
                    insert_gap(&S, batch[i].b, batch[i].z);
            schedule_touched(&S);
            continue;
        }
        /* cluster in plan: union of events closer than delta2 (sorted by x) */
        qsort(batch, nb, sizeof *batch, cmp_event_x);
        if (!grow((void **)&uf, &cap_uf, nb, sizeof *uf)) {
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        for (size_t i = 0; i < nb; i++)
            uf[i] = (uint32_t)i;
        double r = 10 * S.d2;
        /* events a little apart in height (within delta1) are compared where their points
         * would be at one height: a fast corner (nearly parallel edges) moves its point
         * by its speed times the height difference (bounded: 0.2 mm at building scale) */
        double *sp = malloc(nb * sizeof *sp), maxsp = 0, zlo = INFINITY, zhi = -INFINITY;
        if (!sp) {
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        for (size_t i = 0; i < nb; i++) {
            sp[i] = event_speed(&S, &batch[i]);
            maxsp = fmax(maxsp, sp[i]);
            zlo = fmin(zlo, batch[i].z);
            zhi = fmax(zhi, batch[i].z);
        }
        double rmax = r + fmin(2 * maxsp * (zhi - zlo), 20 * S.d3);
        /* a window of 64 suffices: points of one cluster chain each other */
        for (size_t i = 0; i < nb; i++)
            for (size_t j = i + 1; j < nb && j < i + 64 && batch[j].x - batch[i].x <= rmax; j++) {
                double tol = r + fmin((sp[i] + sp[j]) * fabs(batch[j].z - batch[i].z), 20 * S.d3);
                if (fabs(batch[j].y - batch[i].y) <= tol &&
                    hypot(batch[j].x - batch[i].x, batch[j].y - batch[i].y) <= tol) {
                    uint32_t a = uf_find(uf, (uint32_t)i), b = uf_find(uf, (uint32_t)j);
                    if (a != b)
                        uf[a > b ? a : b] = a < b ? a : b;
                }
            }
        free(sp);
        /* handle groups lowest first: order events by (group's lowest z, group) */
        gsort *gs = malloc(nb * sizeof *gs);
        double *gz = malloc(nb * sizeof *gz);
        ag_event *grp = malloc(nb * sizeof *grp);
        if (!gs || !gz || !grp) {
            free(gs);
            free(gz);
            free(grp);
            fail(&S, AG_ERR_NOMEM);
            break;
        }
        for (size_t i = 0; i < nb; i++)
            gz[i] = INFINITY;
        for (size_t i = 0; i < nb; i++) {
            uint32_t rt = uf_find(uf, (uint32_t)i);
            if (batch[i].z < gz[rt])
                gz[rt] = batch[i].z;
        }
        for (size_t i = 0; i < nb; i++) {
            gs[i].root = uf_find(uf, (uint32_t)i);
            gs[i].z = gz[gs[i].root];
            gs[i].i = (uint32_t)i;
        }
        qsort(gs, nb, sizeof *gs, cmp_gsort);
        size_t first_new = S.ntouched;
        S.defer_settle = 1;
        for (size_t i = 0; i < nb && S.st == AG_OK;) {
            size_t j = i, ng = 0;
            while (j < nb && gs[j].root == gs[i].root)
                grp[ng++] = batch[gs[j++].i];
            intersection(&S, grp, ng, &W);
            i = j;
        }
        S.defer_settle = 0;
        for (size_t i = first_new; i < S.ntouched && S.st == AG_OK; i++)
            if (S.c[S.touched[i]].alive && !S.c[S.touched[i]].settled)
                settle(&S, S.touched[i]);
        free(gs);
        free(gz);
        free(grp);
        schedule_touched(&S);
    }
    if (S.st == AG_OK) {
        double zc = plan->cap_height > 0 ? limit : fmax(S.zcur, top_profile);
        compact_live(&S);
        if (S.nlive_e)
            cap(&S, zc);
        S.stats.top = real_z(&S, S.nlive_e ? zc : S.zcur);
    }
    free(batch);
    free(uf);
    free(W.C.arr);
    free(W.E.arr);
    free(W.splits.arr);
    free(W.rays);
    ag_status st = S.st;
    if (st == AG_OK)
        st = ag_shell_finish(S.shell, S.d1);
    ag_eventq_free(&S.q);
    free(S.e);
    free(S.c);
    free(S.live_c);
    free(S.live_e);
    free(S.touched);
    free(S.flat_h);
    if (stats)
        *stats = S.stats;
    if (st != AG_OK) {
        ag_shell_free(S.shell);
        if (!err || err->code == AG_OK)
            ag_error_set(err, st, 0, "%s", st == AG_ERR_NOMEM ? "out of memory" : "extrusion failed");
        return st;
    }
    *out = S.shell;
    return AG_OK;
}
