/* The generalized intersection event (§4.4): the corners arriving at one point are
 * retired, edges passing through it are split, and the edges leaving the point are
 * paired around it into new corners. Corners of two parts growing into each other head-on
 * (eaves of wings set corner to corner) pair the other way round: the parts merge. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "../base/tolerance.h"

/* Rays in counter-clockwise order around the point, by angle. Ties between an outgoing
 * and an incoming ray (antiparallel edges through the point): the outgoing ray first, so
 * the thin region between them counts as inside and is zipped when their corner settles:
 * a ridge closing, or two parts of a growing plan meeting from outside and merging. Only
 * two edges that both stand still (walls of two parts touching along a line) keep the
 * outside between them: the incoming ray first. Two rays the same way (collinear edges, e.g. pieces of one line with different
 * profiles) by where their edges are a little higher (the chains' predicted positions,
 * §4.4): an edge leaving the point moves towards its inside, the left, so it turns
 * counter-clockwise by its slope; one arriving turns clockwise by its slope. */
static int cmp_ray(const void *a, const void *b)
{
    const sk_ray *x = a, *y = b;
    if (fabs(x->ang - y->ang) > AG_EXTRUDE_RAY_TIE)
        return x->ang < y->ang ? -1 : 1;
    if (x->out != y->out) {
        int out_first = x->s != 0 || y->s != 0;
        return (x->out == out_first) ? -1 : 1;
    }
    double tx = x->out ? x->s : -x->s, ty = y->out ? y->s : -y->s;
    if (tx != ty)
        return tx < ty ? -1 : 1;
    /* the same way along one line: a fixed order, so that handling the point again pairs
     * the same edges (and keeps the corners) instead of swapping them for ever */
    return x->edge < y->edge ? -1 : x->edge > y->edge;
}

static int near_l(sk *S, uint32_t k, double z, double lx, double ly, double spread)
{
    const sk_corner *c = &S->c[k];
    double x, y;
    ag__skel_cpos(c, z, &x, &y);
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

/* Pairs each outgoing ray with the next incoming one counter-clockwise (clockwise when cw)
 * around the point, nested pairs matched inside out: np pairs (in edge, out edge) into
 * pairs. The rays leave and arrive in equal numbers. */
static size_t pair_rays(const sk_ray *rays, size_t nrays, int cw, uint32_t *stack,
                        uint32_t *pairs, int *nested)
{
    long bal = 0, minbal = 0;
    size_t start = 0;
    for (size_t i = 0; i < nrays; i++) {
        bal += rays[cw ? nrays - 1 - i : i].out ? 1 : -1;
        if (bal < minbal) {
            minbal = bal;
            start = i + 1;
        }
    }
    size_t sp = 0, np = 0;
    *nested = 0;
    for (size_t j = 0; j < nrays; j++) {
        size_t k = (start + j) % nrays;
        const sk_ray *r = &rays[cw ? nrays - 1 - k : k];
        if (r->out) {
            if (sp)
                *nested = 1;
            stack[sp++] = r->edge;
        } else if (sp) {
            pairs[2 * np] = r->edge;
            pairs[2 * np + 1] = stack[--sp];
            np++;
        }
    }
    return np;
}

/* Does corner k, at the point now, move into corner i's inside just above it? Each of i's
 * edges e: k's distance into e's side grows at n_e . v_k - s_e (both start at the point). A
 * convex corner's inside is on the inner side of both edges, a reflex one's of either. */
static int moves_into(const sk *S, uint32_t i, uint32_t k)
{
    const sk_corner *ci = &S->c[i], *ck = &S->c[k];
    const sk_edge *a = &S->e[ci->in], *b = &S->e[ci->out];
    double ra = a->nx * ck->vx + a->ny * ck->vy - a->s;
    double rb = b->nx * ck->vx + b->ny * ck->vy - b->s;
    double turn = ag__skel_edx(a) * ag__skel_edy(b) - ag__skel_edy(a) * ag__skel_edx(b);
    const double eps = 1e3 * AG_EXTRUDE_MIN_RATE;
    return turn > 0 ? ra > eps && rb > eps : ra > eps || rb > eps;
}

/* Does a corner arriving at the point go on into another's inside (parts growing into each
 * other, which are to merge rather than pass through each other)? */
static int corners_run_into(const sk *S, const uint32_t *cs, size_t nc)
{
    for (size_t i = 0; i < nc; i++)
        for (size_t k = 0; k < nc; k++)
            if (i != k && moves_into(S, cs[i], cs[k]))
                return 1;
    return 0;
}

/* Does every pair make again one of the corners arriving at the point? */
static int pairs_remake_corners(const sk *S, const uint32_t *cs, size_t nc,
                                const uint32_t *pairs, size_t np)
{
    for (size_t p = 0; p < np; p++) {
        int found = 0;
        for (size_t i = 0; i < nc && !found; i++)
            found = S->c[cs[i]].in == pairs[2 * p] && S->c[cs[i]].out == pairs[2 * p + 1];
        if (!found)
            return 0;
    }
    return 1;
}

void ag__skel_intersection(sk *S, ag_event *evs, size_t n)
{
    sk_scratch *W = &S->W;
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
                    ag__skel_vpush(&W->C, ks[j]);
                }
        } else {
            sk_corner *c = &S->c[ev->a];
            sk_edge *f = &S->e[ev->b];
            if (!c->alive || !f->alive || f->ver != ev->ver)
                continue;
            if (c->stamp != mark) {
                c->stamp = mark;
                ag__skel_vpush(&W->C, ev->a);
            }
            ag__skel_vpush(&W->splits, ev->b);
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
                ag__skel_vpush(&W->C, ks[j]);
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
                ag__skel_vpush(&W->C, ks[j]);
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
                    ag__skel_vpush(&W->E, es[j]);
            }
    }
    apex(S, W->E.arr, W->E.n, spread, &lx, &ly, &z);
    uint32_t vl = ag__skel_vertex(S, lx, ly, z);
    size_t nrays = 0;
    size_t need = 2 * (W->E.n + W->splits.n) + 2;
    if (ag_array_reserve((void **)&W->rays, &W->cap_rays, need, sizeof(sk_ray)) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < W->E.n; i++) {
        sk_edge *e = &S->e[W->E.arr[i]];
        int st = S->c[e->start].stamp == mark, en = S->c[e->end].stamp == mark;
        double a = atan2(ag__skel_edy(e), ag__skel_edx(e));
        if (st && en) {
            ag__skel_kill_edge(S, W->E.arr[i]);
        } else if (st) {
            W->rays[nrays++] = (sk_ray){a, W->E.arr[i], 1, e->s};
        } else if (en) {
            W->rays[nrays++] = (sk_ray){a > 0 ? a - M_PI : a + M_PI, W->E.arr[i], 0, e->s};
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
        ag__skel_cpos(&S->c[f->start], z, &ax, &ay);
        ag__skel_cpos(&S->c[f->end], z, &bx, &by);
        double dx = ag__skel_edx(f), dy = ag__skel_edy(f);
        double t = dx * (lx - ax) + dy * (ly - ay), len = dx * (bx - ax) + dy * (by - ay);
        double off = fabs(f->nx * lx + f->ny * ly - (f->c + f->s * z));
        if (t < -S->d3 || t > len + S->d3 || off > S->d3 + spread * (1 + fabs(f->s)))
            continue;
        uint32_t f2 = ag__skel_add_edge(S);
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
        W->rays[nrays++] = (sk_ray){a > 0 ? a - M_PI : a + M_PI, fi, 0, S->e[fi].s};
        W->rays[nrays++] = (sk_ray){a, f2, 1, S->e[f2].s};
    }
    if (!nrays) {
        for (size_t i = 0; i < W->C.n; i++)
            ag__skel_retire(S, W->C.arr[i], vl);
        return;
    }
    qsort(W->rays, nrays, sizeof(sk_ray), cmp_ray);
    /* a tie across the cut at -pi: the last rays belong before the first ones */
    for (size_t turn = 0; turn < nrays && nrays >= 2 &&
                          W->rays[nrays - 1].ang - 2 * M_PI >= W->rays[0].ang - AG_EXTRUDE_RAY_TIE;
         turn++) {
        sk_ray r = W->rays[nrays - 1];
        r.ang -= 2 * M_PI;
        if (cmp_ray(&r, &W->rays[0]) >= 0)
            break;
        memmove(&W->rays[1], &W->rays[0], (nrays - 1) * sizeof(sk_ray));
        W->rays[0] = r;
    }
    int nout = 0;
    for (size_t i = 0; i < nrays; i++)
        nout += W->rays[i].out;
    if (2 * nout != (int)nrays) {
        ag_error_set(S->err, AG_ERR_INTERNAL, 0,
                     "inconsistent intersection at (%.6f, %.6f, %.6f): %d edges leave, %d arrive",
                     lx + S->ox, ly + S->oy, z, nout, (int)nrays - nout);
        ag__skel_fail(S, AG_ERR_INTERNAL);
        return;
    }
    uint32_t *stack = malloc(nrays * sizeof *stack);
    uint32_t *pairs = malloc(nrays * sizeof *pairs);
    uint8_t *keep = calloc(W->C.n + 1, 1);
    if (!stack || !pairs || !keep) {
        free(stack);
        free(pairs);
        free(keep);
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    int nested = 0;
    size_t np = pair_rays(W->rays, nrays, 0, stack, pairs, &nested);
    /* Corners of parts growing into each other head-on (each arriving corner paired again
     * with its own edges, one of them going on into another's inside): counter-clockwise
     * pairing would let them pass through each other. The parts merge: seen from the
     * outside, which is what shrinks there, the pairing turns the other way. */
    if (W->C.n >= 2 && np == W->C.n && pairs_remake_corners(S, W->C.arr, W->C.n, pairs, np) &&
        corners_run_into(S, W->C.arr, W->C.n))
        np = pair_rays(W->rays, nrays, 1, stack, pairs, &nested);
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
            ag__skel_retire(S, W->C.arr[i], vl);
        else
            ag__skel_schedule_corner_after(S, W->C.arr[i], z + S->d1);
    size_t first_new = S->ntouched;
    for (size_t p = 0; p < np; p++)
        if (pairs[2 * p] != NONE)
            ag__skel_add_corner(S, pairs[2 * p], pairs[2 * p + 1], lx, ly, z, vl);
    size_t last_new = S->ntouched;
    free(stack);
    free(pairs);
    free(keep);
    for (size_t i = first_new; i < last_new && S->st == AG_OK; i++) {
        if (!ag__skel_settle_or_defer(S, S->touched[i], S->defer_settle) &&
            !ag__skel_vpush(&S->deferred, S->touched[i]))
            ag__skel_fail(S, AG_ERR_NOMEM);
    }
}
