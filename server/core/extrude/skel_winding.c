/* The post inter-chain repair (§4.4): when the chains left by the intersections of one
 * height no longer form a valid plan a little higher up (two of them cross), the active
 * plan's region boundaries are recomputed by the winding rule. The live edges are taken at
 * a probe height just above the current one, cut where they cross, and every piece is kept
 * only when the region on its left has winding number 1 and the one on its right 0 (it
 * bounds a region of positive winding); the kept pieces are linked into new corners at the
 * crossings, the other pieces end at the current height. The new plan is again one of
 * simple loops. Only crossings that already touch at the current height, at a corner, are
 * this height's doing; the edges of the others (older overlaps, refused at their own
 * height) are kept whole and the rest is repaired around them, as long as no edge has
 * both kinds and nothing nests in such an overlap. Only pieces of no extent at the
 * current height can be removed there without a hole: a plan whose removed pieces are
 * not all such, or that has touching or overlapping pieces at the probe height, is left
 * as it is and counted as refused (the building's check judges the result). Parts of a growing plan (overhangs) that meet from outside are
 * united the same way. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "../base/tolerance.h"
#include "predicates.h"

/* The repair looks at every pair of live edges: plans larger than this are left as they are. */
#define WINDING_MAX_EDGES 4096

typedef struct {
    uint32_t i, j;   /* indices into the live edges */
    double ti, tj;   /* parameters along them at the probe height */
    double x, y;     /* the point at the current height */
    uint32_t vert;
} wcross;

typedef struct {
    uint32_t x;      /* crossing */
    double t;
} wcut;

typedef struct {
    uint32_t edge;   /* the live edge */
    size_t first;    /* its cuts in cuts[first .. first + n) */
    size_t n;
} wedge;

/* Probe height above z: far enough for the chains around one point to have parted, well
 * below anything the tolerances of the next events resolve, and below the next event in
 * the queue (halfway to it): chains elsewhere that meet a little higher (the same level
 * jittered apart) are not crossings of this height. */
static double probe_height(const sk *S, double z)
{
    double zp = z + AG_EXTRUDE_WINDING_PROBE * S->d1;
    const ag_event *next = ag_eventq_peek(&S->q);
    if (next && next->z > z && next->z < zp)
        zp = z + (next->z - z) / 2;
    return zp;
}

static void seg_at(const sk *S, uint32_t e, double z, double *a, double *b)
{
    ag__skel_cpos(&S->c[S->e[e].start], z, &a[0], &a[1]);
    ag__skel_cpos(&S->c[S->e[e].end], z, &b[0], &b[1]);
}

static int edge_ready(const sk *S, uint32_t e)
{
    const sk_edge *f = &S->e[e];
    return f->alive && f->start != NONE && f->end != NONE && S->c[f->start].alive &&
           S->c[f->end].alive && S->c[f->start].settled && S->c[f->end].settled;
}

static double seg_seg_dist(const double *a, const double *b, const double *c, const double *d)
{
    if (ag_pred_segments_touch(a, b, c, d))
        return 0;
    return fmin(fmin(ag_pred_segment_dist(a, c, d), ag_pred_segment_dist(b, c, d)),
                fmin(ag_pred_segment_dist(c, a, b), ag_pred_segment_dist(d, a, b)));
}

/* The point where the lines of edges e and f are at height z; 0 when they are parallel. */
static int lines_meet(const sk *S, uint32_t e, uint32_t f, double z, double *x, double *y)
{
    const sk_edge *a = &S->e[e], *b = &S->e[f];
    double det = a->nx * b->ny - a->ny * b->nx;
    if (fabs(det) <= AG_EXTRUDE_PARALLEL)
        return 0;
    double ca = a->c + a->s * z, cb = b->c + b->s * z;
    *x = (ca * b->ny - cb * a->ny) / det;
    *y = (a->nx * cb - b->nx * ca) / det;
    return 1;
}

/* Is p, at the current height, at an end of segment ab or cd? Chains that cross just above
 * an intersection's point part from that point, where they have their corners; a crossing
 * away from every corner is older than this height (a missed event) and not repaired. */
static int at_an_end(const double *p, const double *a, const double *b, const double *c,
                     const double *d, double tol)
{
    return hypot(p[0] - a[0], p[1] - a[1]) <= tol || hypot(p[0] - b[0], p[1] - b[1]) <= tol ||
           hypot(p[0] - c[0], p[1] - c[1]) <= tol || hypot(p[0] - d[0], p[1] - d[1]) <= tol;
}

/* Do edges e and f cross at the probe height while touching at the current one? */
static int chains_cross(const sk *S, uint32_t e, uint32_t f, double z, double zp)
{
    const sk_edge *E = &S->e[e], *F = &S->e[f];
    if (e == f || E->start == F->end || E->end == F->start || E->start == F->start ||
        E->end == F->end)
        return 0;
    double a[2], b[2], c[2], d[2], tol = AG_EXTRUDE_NEAR_POINTS * S->d2;
    seg_at(S, e, z, a, b);
    seg_at(S, f, z, c, d);
    /* boxes apart at the current height: no touch (the cheap test first) */
    if (fmin(a[0], b[0]) > fmax(c[0], d[0]) + tol || fmin(c[0], d[0]) > fmax(a[0], b[0]) + tol ||
        fmin(a[1], b[1]) > fmax(c[1], d[1]) + tol || fmin(c[1], d[1]) > fmax(a[1], b[1]) + tol)
        return 0;
    if (seg_seg_dist(a, b, c, d) > tol)
        return 0;
    double p[2];
    if (!lines_meet(S, e, f, z, &p[0], &p[1]) || !at_an_end(p, a, b, c, d, tol + (zp - z)))
        return 0;
    seg_at(S, e, zp, a, b);
    seg_at(S, f, zp, c, d);
    return ag_pred_segments_cross(a, b, c, d);
}

/* Winding number of p about the live edges at height zp (loops counter-clockwise around
 * their inside: +1 inside one loop). Exact in its decisions. */
static long winding(const sk *S, const double *segs, size_t n, const double *p)
{
    long w = 0;
    for (size_t i = 0; i < n; i++) {
        const double *a = &segs[4 * i], *b = &segs[4 * i + 2];
        if (a[1] <= p[1]) {
            if (b[1] > p[1] && ag_pred_orient2d(a, b, p) > 0)
                w++;
        } else if (b[1] <= p[1] && ag_pred_orient2d(a, b, p) < 0) {
            w--;
        }
    }
    (void)S;
    return w;
}

static int cmp_cut(const void *x, const void *y)
{
    const wcut *a = x, *b = y;
    return a->t < b->t ? -1 : a->t > b->t;
}

/* One vertex per point of the current height (the pieces' ends at one point share it). */
typedef struct {
    double *xy;
    uint32_t *v;
    size_t n, cap;
} wverts;

static uint32_t vertex_at(sk *S, wverts *V, double x, double y, double z)
{
    for (size_t i = 0; i < V->n; i++)
        if (hypot(V->xy[2 * i] - x, V->xy[2 * i + 1] - y) <= S->d2)
            return V->v[i];
    size_t cap = V->cap;
    if (ag_array_reserve((void **)&V->xy, &cap, V->n + 1, 2 * sizeof *V->xy) != AG_OK ||
        ag_array_reserve((void **)&V->v, &V->cap, V->n + 1, sizeof *V->v) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return 0;
    }
    V->xy[2 * V->n] = x;
    V->xy[2 * V->n + 1] = y;
    V->v[V->n] = ag__skel_vertex(S, x, y, z);
    return V->v[V->n++];
}

/* The repair itself over all live edges; 1 when the plan was rebuilt, 0 when refused
 * (nothing changed). */
static int rebuild(sk *S, double z, double zp)
{
    size_t n = S->nlive_e;
    if (n > WINDING_MAX_EDGES)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!edge_ready(S, S->live_e[i]))
            return 0;
    int ok = 0;
    double *segs = malloc(4 * n * sizeof *segs);
    wcross *X = NULL;
    wcut *cuts = NULL;
    wedge *W = calloc(n, sizeof *W);
    uint8_t *keep = NULL, *foreign = calloc(n ? n : 1, 1);
    size_t nforeign = 0;
    uint32_t *piece_id = NULL, *cpair = NULL;
    size_t nx = 0, capx = 0, ncuts = 0, npieces = 0;
    wverts V = {0};
    if (!segs || !W || !foreign)
        goto nomem;
    for (size_t i = 0; i < n; i++)
        seg_at(S, S->live_e[i], zp, &segs[4 * i], &segs[4 * i + 2]);
    /* crossings at the probe height; any other contact is a degeneracy not handled here */
    for (size_t i = 0; i < n; i++) {
        const double *a = &segs[4 * i], *b = &segs[4 * i + 2];
        const sk_edge *E = &S->e[S->live_e[i]];
        for (size_t j = i + 1; j < n; j++) {
            const double *c = &segs[4 * j], *d = &segs[4 * j + 2];
            const sk_edge *F = &S->e[S->live_e[j]];
            if (!ag_pred_segments_touch(a, b, c, d))
                continue;
            int adjacent = E->end == F->start || F->end == E->start;
            if (adjacent && !(E->end == F->start && F->end == E->start)) {
                /* neighbours meet at their corner only, unless collinear and folding back */
                const double *far_e = E->end == F->start ? a : b;
                const double *far_f = E->end == F->start ? d : c;
                const double *mid = E->end == F->start ? b : a;
                if (ag_pred_orient2d(far_e, mid, far_f) != 0 ||
                    (mid[0] - far_e[0]) * (far_f[0] - mid[0]) +
                            (mid[1] - far_e[1]) * (far_f[1] - mid[1]) > 0)
                    continue;
                goto refuse;
            }
            if (adjacent || !ag_pred_segments_cross(a, b, c, d))
                goto refuse; /* a two-edge loop, or a touch / overlap at the probe height */
            if (ag_array_reserve((void **)&X, &capx, nx + 1, sizeof *X) != AG_OK)
                goto nomem;
            /* parameters of the crossing along both (double: only for ordering) */
            double rx = b[0] - a[0], ry = b[1] - a[1], sx = d[0] - c[0], sy = d[1] - c[1];
            double den = rx * sy - ry * sx;
            double ti = ((c[0] - a[0]) * sy - (c[1] - a[1]) * sx) / den;
            double tj = ((c[0] - a[0]) * ry - (c[1] - a[1]) * rx) / den;
            wcross *w = &X[nx++];
            w->i = (uint32_t)i;
            w->j = (uint32_t)j;
            w->ti = ti;
            w->tj = tj;
            /* where it is at the current height: it must be there already (touching) */
            double pz[2], sa[2], sb[2], sc[2], sd[2];
            if (!lines_meet(S, S->live_e[i], S->live_e[j], z, &w->x, &w->y))
                goto refuse;
            pz[0] = w->x;
            pz[1] = w->y;
            seg_at(S, S->live_e[i], z, sa, sb);
            seg_at(S, S->live_e[j], z, sc, sd);
            double tol = AG_EXTRUDE_NEAR_POINTS * S->d2 + (zp - z);
            if (ag_pred_segment_dist(pz, sa, sb) > tol || ag_pred_segment_dist(pz, sc, sd) > tol ||
                !at_an_end(pz, sa, sb, sc, sd, tol)) {
                /* not this height's doing (an overlap left at a lower height, refused
                 * there): its two edges stay as they are, and the rest is repaired
                 * around them if it can be */
                nx--;
                foreign[i] = foreign[j] = 1;
                nforeign++;
            }
        }
    }
    for (size_t q = 0; q < nx; q++)
        if (foreign[X[q].i] || foreign[X[q].j])
            goto refuse; /* an edge crossed both at this height and by an older overlap */
    ag__skel_work(S, n * n / 16 + 1);
    if (!nx || S->st != AG_OK)
        goto refuse;
    /* each edge's cuts, in order along it */
    cuts = malloc(2 * nx * sizeof *cuts);
    if (!cuts)
        goto nomem;
    for (size_t q = 0; q < nx; q++) {
        W[X[q].i].n++;
        W[X[q].j].n++;
    }
    for (size_t i = 0; i < n; i++) {
        W[i].edge = S->live_e[i];
        W[i].first = ncuts;
        ncuts += W[i].n;
        W[i].n = 0;
    }
    for (size_t q = 0; q < nx; q++) {
        cuts[W[X[q].i].first + W[X[q].i].n++] = (wcut){(uint32_t)q, X[q].ti};
        cuts[W[X[q].j].first + W[X[q].j].n++] = (wcut){(uint32_t)q, X[q].tj};
    }
    for (size_t i = 0; i < n; i++) {
        qsort(&cuts[W[i].first], W[i].n, sizeof *cuts, cmp_cut);
        for (size_t k = 1; k < W[i].n; k++)
            if (!(cuts[W[i].first + k].t > cuts[W[i].first + k - 1].t))
                goto refuse; /* three edges through one point at the probe height */
    }
    /* pieces: edge i has n_i + 1 of them; piece p of edge i is number first + i + p */
    npieces = ncuts + n;
    keep = malloc(npieces);
    piece_id = malloc(npieces * sizeof *piece_id);
    if (!keep || !piece_id)
        goto nomem;
    for (size_t i = 0; i < n; i++) {
        const sk_edge *E = &S->e[W[i].edge];
        const double *a = &segs[4 * i], *b = &segs[4 * i + 2];
        double len = hypot(b[0] - a[0], b[1] - a[1]);
        for (size_t p = 0; p <= W[i].n; p++) {
            double t0 = p ? cuts[W[i].first + p - 1].t : 0;
            double t1 = p < W[i].n ? cuts[W[i].first + p].t : 1;
            double tm = (t0 + t1) / 2, plen = (t1 - t0) * len;
            /* a point just left of the piece's middle, closer than anything else */
            double off = fmin(AG_EXTRUDE_WINDING_SIDE * plen, S->d2);
            double pt[2] = {a[0] + tm * (b[0] - a[0]) + off * E->nx,
                            a[1] + tm * (b[1] - a[1]) + off * E->ny};
            double pr[2] = {pt[0] - 2 * off * E->nx, pt[1] - 2 * off * E->ny};
            if (foreign[i]) {
                keep[W[i].first + i + p] = 1; /* whole, uncut: an older overlap's */
                continue;
            }
            long wl = winding(S, segs, n, pt), wr = winding(S, segs, n, pr);
            if (wl != wr + 1)
                goto refuse; /* the side points were not on the two sides of this piece only */
            /* beside an older overlap only plain boundaries (1 | 0) and this height's
             * crossings (2 | 1 inside them) are decided: nothing nested in the overlap */
            if (nforeign && (wl > 2 || wr < 0))
                goto refuse;
            keep[W[i].first + i + p] = wl >= 1 && wr <= 0;
        }
    }
    ag__skel_work(S, npieces * n / 16 + 1);
    /* the corners: an original corner keeps both its pieces or neither; a crossing pairs
     * the kept piece arriving with the kept piece leaving (both pairs when all four are) */
    for (size_t i = 0; i < n; i++) {
        uint32_t k = S->e[W[i].edge].end;
        uint32_t f = S->c[k].out;
        size_t j = 0;
        while (j < n && W[j].edge != f)
            j++;
        if (j == n)
            goto refuse;
        if (keep[W[i].first + i + W[i].n] != keep[W[j].first + j])
            goto refuse;
    }
    /* what is removed must have no extent at this height: chains that overlap already (an
     * older overlap, not this height's doing) would leave a hole where they are cut */
    for (size_t i = 0; i < n; i++)
        for (size_t p = 0; p <= W[i].n; p++) {
            if (keep[W[i].first + i + p])
                continue;
            double a[2], b[2], pa[2], pb[2];
            seg_at(S, W[i].edge, z, a, b);
            if (p) {
                const wcross *c = &X[cuts[W[i].first + p - 1].x];
                pa[0] = c->x, pa[1] = c->y;
            } else {
                pa[0] = a[0], pa[1] = a[1];
            }
            if (p < W[i].n) {
                const wcross *c = &X[cuts[W[i].first + p].x];
                pb[0] = c->x, pb[1] = c->y;
            } else {
                pb[0] = b[0], pb[1] = b[1];
            }
            if (hypot(pb[0] - pa[0], pb[1] - pa[1]) > AG_EXTRUDE_NEAR_POINTS * S->d2)
                goto refuse;
        }
    cpair = malloc(4 * nx * sizeof *cpair);
    if (!cpair)
        goto nomem;
    for (size_t q = 0; q < nx; q++) {
        size_t i = X[q].i, j = X[q].j, pi = 0, pj = 0;
        while (cuts[W[i].first + pi].x != q)
            pi++;
        while (cuts[W[j].first + pj].x != q)
            pj++;
        size_t ib = W[i].first + i + pi, ia = ib + 1, jb = W[j].first + j + pj, ja = jb + 1;
        int nin = keep[ib] + keep[jb], nout = keep[ia] + keep[ja];
        if (nin != nout)
            goto refuse;
        for (int r = 0; r < 4; r++)
            cpair[4 * q + r] = NONE;
        if (nin == 2) {
            cpair[0 + 4 * q] = (uint32_t)ib;
            cpair[1 + 4 * q] = (uint32_t)ja;
            cpair[2 + 4 * q] = (uint32_t)jb;
            cpair[3 + 4 * q] = (uint32_t)ia;
        } else if (nin == 1) {
            cpair[0 + 4 * q] = (uint32_t)(keep[ib] ? ib : jb);
            cpair[1 + 4 * q] = (uint32_t)(keep[ia] ? ia : ja);
        }
    }
    /* --- nothing changed so far: now the plan is rebuilt ------------------------------- */
    ok = 1;
    for (size_t i = 0; i < n && S->st == AG_OK; i++) {
        uint32_t e = W[i].edge;
        piece_id[W[i].first + i] = e;
        if (!W[i].n)
            continue;
        uint32_t end = S->e[e].end;
        for (size_t p = 1; p <= W[i].n; p++) {
            uint32_t g = ag__skel_add_edge(S);
            if (g == NONE)
                break;
            S->e[g] = S->e[e];
            S->e[g].ver = 0;
            S->e[g].alive = 1;
            S->e[g].start = NONE;
            S->e[g].end = NONE;
            piece_id[W[i].first + i + p] = g;
        }
        if (S->st != AG_OK)
            break;
        S->e[e].end = NONE;
        S->e[e].ver++;
        uint32_t last = piece_id[W[i].first + i + W[i].n];
        S->e[last].end = end;
        S->c[end].in = last;
    }
    if (S->st != AG_OK)
        goto done;
    for (size_t q = 0; q < nx; q++)
        X[q].vert = vertex_at(S, &V, X[q].x, X[q].y, z);
    /* original corners whose pieces both go: they stop here */
    for (size_t i = 0; i < n && S->st == AG_OK; i++) {
        size_t last = W[i].first + i + W[i].n;
        if (keep[last])
            continue;
        uint32_t k = S->e[piece_id[last]].end;
        double x, y;
        ag__skel_cpos(&S->c[k], z, &x, &y);
        ag__skel_retire(S, k, vertex_at(S, &V, x, y, z));
    }
    /* dropped pieces end at this height: their faces are closed along them */
    for (size_t i = 0; i < n && S->st == AG_OK; i++) {
        const sk_edge *E = &S->e[W[i].edge];
        for (size_t p = 0; p <= W[i].n; p++) {
            size_t pc = W[i].first + i + p;
            if (keep[pc])
                continue;
            S->stats.winding_pieces_dropped++;
            uint32_t vs, ve;
            if (p) {
                vs = X[cuts[W[i].first + p - 1].x].vert;
            } else {
                double x, y;
                ag__skel_cpos(&S->c[E->start], z, &x, &y);
                vs = vertex_at(S, &V, x, y, z);
            }
            if (p < W[i].n) {
                ve = X[cuts[W[i].first + p].x].vert;
            } else {
                double x, y;
                uint32_t k = S->e[piece_id[W[i].first + i + W[i].n]].end;
                ag__skel_cpos(&S->c[k], z, &x, &y);
                ve = vertex_at(S, &V, x, y, z);
            }
            if (vs != ve)
                ag__skel_seg(S, E->face, ve, vs);
        }
    }
    /* new corners at the crossings, then the dropped pieces' edges go (the pieces are
     * live edges already: ag__skel_add_edge lists them) */
    for (size_t q = 0; q < nx && S->st == AG_OK; q++)
        for (int r = 0; r < 4; r += 2)
            if (cpair[4 * q + r] != NONE) {
                uint32_t k = ag__skel_add_corner(S, piece_id[cpair[4 * q + r]],
                                                 piece_id[cpair[4 * q + r + 1]], X[q].x, X[q].y,
                                                 z, X[q].vert);
                if (k != NONE)
                    ag__skel_settle(S, k);
            }
    for (size_t i = 0; i < n && S->st == AG_OK; i++)
        for (size_t p = 0; p <= W[i].n; p++)
            if (!keep[W[i].first + i + p])
                ag__skel_kill_edge(S, piece_id[W[i].first + i + p]);
    goto done;
nomem:
    ag__skel_fail(S, AG_ERR_NOMEM);
refuse:
    ok = 0;
done:
    free(segs);
    free(X);
    free(cuts);
    free(W);
    free(keep);
    free(foreign);
    free(piece_id);
    free(cpair);
    free(V.xy);
    free(V.v);
    return ok;
}

int ag__skel_winding_repair(sk *S)
{
    size_t nmade = S->made.n;
    S->made.n = 0;
    if (S->st != AG_OK || S->no_winding_repair || !nmade)
        return 0;
    ag__skel_compact_live(S);
    double z = S->zcur, zp = probe_height(S, z);
    /* the check: do the edges of the corners made at this height cross any live edge just
     * above? */
    int crossing = 0;
    for (size_t t = 0; t < nmade && !crossing; t++) {
        const sk_corner *c = &S->c[S->made.arr[t]];
        if (!c->alive || !c->settled)
            continue;
        uint32_t es[2] = {c->in, c->out};
        for (int j = 0; j < 2 && !crossing; j++) {
            if (!edge_ready(S, es[j]))
                continue;
            for (size_t q = 0; q < S->nlive_e; q++)
                if (edge_ready(S, S->live_e[q]) && chains_cross(S, es[j], S->live_e[q], z, zp)) {
                    crossing = 1;
                    break;
                }
        }
        ag__skel_work(S, S->nlive_e);
    }
    if (!crossing)
        return 0;
    S->stats.winding_invalid++;
    int rebuilt = rebuild(S, z, zp);
    if (rebuilt)
        S->stats.winding_repairs++;
    else
        S->stats.winding_refused++;
    S->made.n = 0; /* the rebuild's own corners are not checked again */
    return rebuilt;
}
