#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"

/* A triangle spanning more cells than this is kept aside and looked at by every query. */
#define MAX_CELLS_PER_TRIANGLE 64
/* Pieces a cover examines at most per triangle of A, plus a floor (the default budget). */
#define BUDGET_PER_TRIANGLE 64
#define BUDGET_FLOOR 4096
/* Pieces are cut at most this many times (a 10 km triangle against a micrometre tolerance
 * stops there; what is left is counted as not covered). */
#define MAX_DEPTH 24
/* A triangle of B within this share of the tolerance of all of a piece's corners ends the
 * search for the best one (the bound stays certified, at most this much looser). */
#define GOOD_ENOUGH (1.0 / 16)

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

double ag_surface_point_triangle(const double p[3], const double *a, const double *b,
                                 const double *c)
{
    /* the closest point by Voronoi regions (Ericson, Real-Time Collision Detection 5.1.5) */
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(q, a, sizeof q);
        goto done;
    }
    double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(q, b, sizeof q);
        goto done;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + v * ab[k];
        goto done;
    }
    double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(q, c, sizeof q);
        goto done;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + w * ac[k];
        goto done;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            q[k] = b[k] + w * (c[k] - b[k]);
        goto done;
    }
    {
        double den = va + vb + vc;
        if (!(fabs(den) > 0)) { /* a degenerate triangle: its longest edge */
            double best = INFINITY;
            const double *e[3][2] = {{a, b}, {b, c}, {c, a}};
            for (int i = 0; i < 3; i++) {
                double u[3], w[3];
                for (int k = 0; k < 3; k++) {
                    u[k] = e[i][1][k] - e[i][0][k];
                    w[k] = p[k] - e[i][0][k];
                }
                double uu = dot3(u, u), t = uu > 0 ? fmin(fmax(dot3(w, u) / uu, 0), 1) : 0;
                double d = 0;
                for (int k = 0; k < 3; k++) {
                    double x = w[k] - t * u[k];
                    d += x * x;
                }
                if (d < best)
                    best = d;
            }
            return sqrt(best);
        }
        double v = vb / den, w = vc / den;
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + ab[k] * v + ac[k] * w;
    }
done:;
    double d = 0;
    for (int k = 0; k < 3; k++)
        d += (p[k] - q[k]) * (p[k] - q[k]);
    return sqrt(d);
}

void ag_surface_free(ag_surface *s)
{
    if (!s)
        return;
    free(s->start);
    free(s->items);
    free(s->big);
    free(s->stamp);
    free(s->tbox);
    memset(s, 0, sizeof *s);
}

static void cell_range(const ag_surface *s, const ag_box *b, double pad, int64_t lo[3],
                       int64_t hi[3])
{
    for (int a = 0; a < 3; a++) {
        double l = floor((b->min[a] - pad - s->box.min[a]) / s->cell);
        double h = floor((b->max[a] + pad - s->box.min[a]) / s->cell);
        lo[a] = l < 0 ? 0 : l >= (double)s->dims[a] ? s->dims[a] : (int64_t)l;
        hi[a] = h < 0 ? -1 : h >= (double)s->dims[a] ? s->dims[a] - 1 : (int64_t)h;
    }
}

static ag_box tri_box(const double *t)
{
    ag_box b = ag_box_empty();
    for (int v = 0; v < 3; v++)
        ag_box_extend_point(&b, t + 3 * v);
    return b;
}

ag_status ag_surface_init(ag_surface *s, const double *tri, size_t n)
{
    memset(s, 0, sizeof *s);
    s->tri = tri;
    s->n = n;
    if (n >= UINT32_MAX)
        return AG_ERR_TOO_LARGE;
    s->box = ag_box_empty();
    double area = 0;
    for (size_t i = 0; i < n; i++) {
        const double *t = tri + 9 * i;
        for (int v = 0; v < 3; v++)
            ag_box_extend_point(&s->box, t + 3 * v);
        double u[3], w[3];
        for (int k = 0; k < 3; k++) {
            u[k] = t[3 + k] - t[k];
            w[k] = t[6 + k] - t[k];
        }
        double c[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                       u[0] * w[1] - u[1] * w[0]};
        area += 0.5 * sqrt(dot3(c, c));
    }
    if (!(s->stamp = calloc(n + 1, sizeof *s->stamp)) ||
        !(s->tbox = malloc((6 * n + 1) * sizeof *s->tbox)))
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < n; i++) {
        ag_box b = tri_box(tri + 9 * i);
        memcpy(s->tbox + 6 * i, b.min, 3 * sizeof(double));
        memcpy(s->tbox + 6 * i + 3, b.max, 3 * sizeof(double));
    }
    double ext = 0;
    for (int a = 0; a < 3 && n; a++)
        ext = fmax(ext, ag_box_extent(&s->box, a));
    /* cells about two triangles across, no finer than the extent / 256 and no more than
     * 4 n + 64 of them */
    double cell = fmax(2 * sqrt(2 * area / (n ? (double)n : 1)), ext / 256);
    if (!(cell > 0))
        cell = ext > 0 ? ext : 1;
    for (;;) {
        double cells = 1;
        for (int a = 0; a < 3; a++)
            cells *= floor((n ? ag_box_extent(&s->box, a) : 0) / cell) + 1;
        if (cells <= 4.0 * (double)n + 64)
            break;
        cell *= 1.5;
    }
    s->cell = cell;
    size_t ncells = 1;
    for (int a = 0; a < 3; a++) {
        s->dims[a] = n ? (int64_t)floor(ag_box_extent(&s->box, a) / cell) + 1 : 0;
        ncells *= (size_t)s->dims[a];
    }
    if (!n)
        ncells = 0;
    s->start = calloc(ncells + 2, sizeof *s->start);
    uint8_t *isbig = calloc(n + 1, 1);
    if (!s->start || !isbig) {
        free(isbig);
        return AG_ERR_NOMEM;
    }
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < n; i++) {
            if (isbig[i])
                continue;
            ag_box b = tri_box(tri + 9 * i);
            int64_t lo[3], hi[3];
            cell_range(s, &b, 0, lo, hi);
            double span = (double)(hi[0] - lo[0] + 1) * (double)(hi[1] - lo[1] + 1) *
                          (double)(hi[2] - lo[2] + 1);
            if (pass == 0 && span > MAX_CELLS_PER_TRIANGLE) {
                isbig[i] = 1;
                s->nbig++;
                continue;
            }
            for (int64_t z = lo[2]; z <= hi[2]; z++)
                for (int64_t y = lo[1]; y <= hi[1]; y++)
                    for (int64_t x = lo[0]; x <= hi[0]; x++) {
                        size_t c = (size_t)((z * s->dims[1] + y) * s->dims[0] + x);
                        if (pass == 0)
                            s->start[c + 1]++;
                        else
                            s->items[s->start[c]++] = (uint32_t)i;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < ncells; c++)
                s->start[c + 1] += s->start[c];
            total = ncells ? s->start[ncells] : 0;
            s->items = malloc((total + 1) * sizeof *s->items);
            s->big = malloc((s->nbig + 1) * sizeof *s->big);
            if (!s->items || !s->big) {
                free(isbig);
                return AG_ERR_NOMEM;
            }
            size_t k = 0;
            for (size_t i = 0; i < n; i++)
                if (isbig[i])
                    s->big[k++] = (uint32_t)i;
        }
    }
    /* the fill advanced every start by its cell's count: shift back */
    for (size_t c = ncells; c > 0; c--)
        s->start[c] = s->start[c - 1];
    s->start[0] = 0;
    free(isbig);
    return AG_OK;
}

typedef struct {
    ag_surface *s;
    uint32_t *cand;
    size_t ncand, cap;
    int nomem;
} query;

/* Whether a triangle's box (min, max) lies farther than pad from box b on some axis: then
 * every point of b is farther than pad from the triangle, so it can neither cover a piece in
 * b nor be the closest within pad to one of its points. */
static int box_apart(const double *tb, const ag_box *b, double pad)
{
    for (int a = 0; a < 3; a++)
        if (tb[a] > b->max[a] + pad || tb[3 + a] < b->min[a] - pad)
            return 1;
    return 0;
}

/* The triangles of B that may lie within pad of box b, each once. */
static void gather(query *q, const ag_box *b, double pad)
{
    ag_surface *s = q->s;
    q->ncand = 0;
    if (++s->query == 0) { /* the stamps wrapped: start afresh */
        memset(s->stamp, 0, (s->n + 1) * sizeof *s->stamp);
        s->query = 1;
    }
    for (size_t i = 0; i < s->nbig; i++) {
        if (box_apart(s->tbox + 6 * (size_t)s->big[i], b, pad))
            continue;
        if (AG_ARRAY_RESERVE(q->cand, q->cap, q->ncand + 1)) {
            q->nomem = 1;
            return;
        }
        q->cand[q->ncand++] = s->big[i];
    }
    if (!s->n)
        return;
    int64_t lo[3], hi[3];
    cell_range(s, b, pad, lo, hi);
    for (int64_t z = lo[2]; z <= hi[2]; z++)
        for (int64_t y = lo[1]; y <= hi[1]; y++)
            for (int64_t x = lo[0]; x <= hi[0]; x++) {
                size_t c = (size_t)((z * s->dims[1] + y) * s->dims[0] + x);
                for (uint32_t k = s->start[c]; k < s->start[c + 1]; k++) {
                    uint32_t t = s->items[k];
                    if (s->stamp[t] == s->query)
                        continue;
                    s->stamp[t] = s->query;
                    if (box_apart(s->tbox + 6 * (size_t)t, b, pad))
                        continue;
                    if (AG_ARRAY_RESERVE(q->cand, q->cap, q->ncand + 1)) {
                        q->nomem = 1;
                        return;
                    }
                    q->cand[q->ncand++] = t;
                }
            }
}


/* ---- covering a piece by several triangles (another triangulation of its surface) ----
 *
 * The distance to one triangle t is convex, so over any convex polygon Q it is largest at
 * Q's corners. A piece of A is clipped to the prism over each triangle of B (widened by
 * CLIP_WIDEN of the tolerance so that neighbouring prisms overlap): where those corners are
 * within tol of t, that part is proven and cut away; what is left goes on as pieces of its
 * own. A surface triangulated otherwise is so proven in a few clips instead of being cut
 * down to the tolerance's size along every edge of B. */
#define CLIP_MAXV 32  /* corners of a clipped polygon at most */
#define CLIP_MAXP 48  /* polygons left at most */
#define CLIP_WIDEN (1.0 / 64)
#define CLIP_MAX_LEFT 0 /* polygons left for which a clip still counts (else the piece is cut) */

typedef struct {
    double v[CLIP_MAXV][3];
    int n;
} cpoly;

/* in ∩ {m·x >= off} into out; -1 when it has too many corners. */
static int clip_keep(const cpoly *in, const double m[3], double off, cpoly *out)
{
    out->n = 0;
    for (int i = 0; i < in->n; i++) {
        const double *a = in->v[i], *b = in->v[(i + 1) % in->n];
        double sa = dot3(m, a) - off, sb = dot3(m, b) - off;
        if (sa >= 0) {
            if (out->n >= CLIP_MAXV)
                return -1;
            memcpy(out->v[out->n++], a, 3 * sizeof(double));
        }
        if ((sa >= 0) != (sb >= 0)) {
            if (out->n >= CLIP_MAXV)
                return -1;
            double t = sa / (sa - sb);
            for (int k = 0; k < 3; k++)
                out->v[out->n][k] = a[k] + t * (b[k] - a[k]);
            out->n++;
        }
    }
    return 0;
}

/* Proves what it can of triangle P on the triangles cand of B: *bound gets the largest
 * distance over the proven parts, left[] the convex polygons not proven. Returns the number
 * of polygons left, or -1 when nothing was proven (or the polygons outgrew their limits).
 * work: room for 2 CLIP_MAXP polygons. */
static int clip_cover(const ag_surface *b, const uint32_t *cand, size_t ncand, const double *P,
                      double tol, double *bound, cpoly *work, cpoly *left)
{
    cpoly *cur = work, *nxt = work + CLIP_MAXP;
    int ncur = 1, proven = 0;
    double eps = tol * CLIP_WIDEN;
    cur[0].n = 3;
    memcpy(cur[0].v, P, 9 * sizeof(double));
    *bound = 0;
    for (size_t k = 0; k < ncand && ncur > 0; k++) {
        const double *t = b->tri + 9 * (size_t)cand[k];
        double e1[3], e2[3], n[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = t[3 + a] - t[a];
            e2[a] = t[6 + a] - t[a];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double nn = sqrt(dot3(n, n));
        if (!(nn > 0))
            continue;
        /* inward side normals: n × edge, for the edges in order */
        double m[3][3], off[3];
        int ok = 1;
        for (int i = 0; i < 3 && ok; i++) {
            const double *p = t + 3 * i, *q = t + 3 * ((i + 1) % 3);
            double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            m[i][0] = n[1] * e[2] - n[2] * e[1];
            m[i][1] = n[2] * e[0] - n[0] * e[2];
            m[i][2] = n[0] * e[1] - n[1] * e[0];
            double l = sqrt(dot3(m[i], m[i]));
            ok = l > 0;
            for (int a = 0; a < 3 && ok; a++)
                m[i][a] /= l;
            off[i] = dot3(m[i], p) - eps;
        }
        if (!ok)
            continue;
        int nnxt = 0;
        for (int j = 0; j < ncur; j++) {
            cpoly q, r;
            q = cur[j];
            int inside = 1;
            for (int i = 0; i < 3 && inside; i++) {
                if (clip_keep(&q, m[i], off[i], &r) < 0)
                    return -1;
                q = r;
                inside = q.n >= 3;
            }
            double d = 0;
            for (int v = 0; inside && v < q.n && d <= tol; v++)
                d = fmax(d, ag_surface_point_triangle(q.v[v], t, t + 3, t + 6));
            if (!inside || d > tol) {
                if (nnxt >= CLIP_MAXP)
                    return -1;
                nxt[nnxt++] = cur[j];
                continue;
            }
            proven = 1;
            *bound = fmax(*bound, d);
            /* what lies outside the prism: outside side 0; inside 0, outside 1; ... */
            cpoly rest = cur[j];
            for (int i = 0; i < 3 && rest.n >= 3; i++) {
                double mi[3] = {-m[i][0], -m[i][1], -m[i][2]};
                if (clip_keep(&rest, mi, -off[i], &r) < 0)
                    return -1;
                if (r.n >= 3) {
                    if (nnxt >= CLIP_MAXP)
                        return -1;
                    nxt[nnxt++] = r;
                }
                if (clip_keep(&rest, m[i], off[i], &r) < 0)
                    return -1;
                rest = r;
            }
        }
        cpoly *sw = cur;
        cur = nxt;
        nxt = sw;
        ncur = nnxt;
    }
    if (!proven)
        return -1;
    for (int j = 0; j < ncur; j++)
        left[j] = cur[j];
    return ncur;
}

typedef struct {
    double p[9];
    int depth;
} piece;

void ag_surface_cover(ag_surface *b, const double *a, size_t na, double tol, size_t budget,
                      int stop_early, ag_surface_cover_result *out)
{
    memset(out, 0, sizeof *out);
    if (!(tol > 0))
        tol = AG_PROC_TINY;
    if (!budget)
        budget = BUDGET_PER_TRIANGLE * na + BUDGET_FLOOR;
    query q = {.s = b};
    piece *stack = NULL;
    cpoly *clipbuf = NULL; /* clip_cover's polygons, made when first needed */
    size_t cap = 0;
    size_t used = 0;
    for (size_t i = 0; i < na; i++) {
        size_t top = 0;
        if (AG_ARRAY_RESERVE(stack, cap, 1)) {
            out->uncovered += na - i;
            break;
        }
        memcpy(stack[0].p, a + 9 * i, sizeof stack[0].p);
        stack[0].depth = 0;
        top = 1;
        int failed = 0;
        while (top && !failed) {
            piece P = stack[--top];
            if (used++ >= budget) {
                out->exhausted = 1;
                failed = 1;
                break;
            }
            ag_box pb = ag_box_empty();
            for (int v = 0; v < 3; v++)
                ag_box_extend_point(&pb, P.p + 3 * v);
            gather(&q, &pb, tol);
            if (q.nomem) {
                failed = 1;
                break;
            }
            /* the triangle that covers the piece best; a close enough one ends the search
             * (its bound is as honest as the best's) */
            double best = INFINITY, vmin[3] = {INFINITY, INFINITY, INFINITY};
            for (size_t k = 0; k < q.ncand && !(best <= tol * GOOD_ENOUGH); k++) {
                const double *t = b->tri + 9 * (size_t)q.cand[k];
                double m = 0;
                for (int v = 0; v < 3 && m < best; v++) {
                    double d = ag_surface_point_triangle(P.p + 3 * v, t, t + 3, t + 6);
                    if (d > m)
                        m = d;
                }
                if (m < best)
                    best = m;
            }
            /* not covered by one triangle: each corner's distance, for witnesses */
            for (size_t k = 0; best > tol && k < q.ncand; k++) {
                const double *t = b->tri + 9 * (size_t)q.cand[k];
                for (int v = 0; v < 3; v++) {
                    double d = ag_surface_point_triangle(P.p + 3 * v, t, t + 3, t + 6);
                    if (d < vmin[v])
                        vmin[v] = d;
                }
            }
            if (best <= tol)
                for (int v = 0; v < 3; v++)
                    vmin[v] = 0; /* within best of B: no witness, lower unchanged */
            for (int v = 0; v < 3; v++) {
                double d = fmin(vmin[v], tol); /* past tol: farther than tol, a witness */
                if (vmin[v] > tol)
                    d = tol;
                if (d > out->lower)
                    out->lower = d;
                if (vmin[v] > tol) {
                    failed = 1;
                }
            }
            if (failed)
                break;
            if (best <= tol) {
                if (best > out->upper)
                    out->upper = best;
                continue;
            }
            /* no single triangle covers the piece: several may (another triangulation) */
            if (!clipbuf && !(clipbuf = malloc(3 * CLIP_MAXP * sizeof *clipbuf))) {
                failed = 1;
                break;
            }
            {
                cpoly *left = clipbuf + 2 * CLIP_MAXP;
                double bound;
                int nleft = clip_cover(b, q.cand, q.ncand, P.p, tol, &bound, clipbuf, left);
                /* wholly proven, or proven but for a few slivers: those go on as pieces;
                 * otherwise the piece is cut as before (its quarters are clipped again) */
                if (nleft >= 0 && nleft <= CLIP_MAX_LEFT) {
                    if (bound > out->upper)
                        out->upper = bound;
                    size_t more = 0;
                    for (int j = 0; j < nleft; j++)
                        more += (size_t)(left[j].n - 2);
                    if (AG_ARRAY_RESERVE(stack, cap, top + more)) {
                        failed = 1;
                        break;
                    }
                    for (int j = 0; j < nleft; j++)
                        for (int v = 1; v + 1 < left[j].n; v++) {
                            piece *Q = &stack[top++];
                            memcpy(Q->p, left[j].v[0], 3 * sizeof(double));
                            memcpy(Q->p + 3, left[j].v[v], 3 * sizeof(double));
                            memcpy(Q->p + 6, left[j].v[v + 1], 3 * sizeof(double));
                            Q->depth = P.depth + 1;
                        }
                    continue;
                }
            }
            /* nor several: the bound from its centre, else cut it */
            double c[3], r = 0, L = 0;
            for (int k = 0; k < 3; k++)
                c[k] = (P.p[k] + P.p[3 + k] + P.p[6 + k]) / 3;
            for (int v = 0; v < 3; v++) {
                double d = 0, e = 0;
                for (int k = 0; k < 3; k++) {
                    d += (P.p[3 * v + k] - c[k]) * (P.p[3 * v + k] - c[k]);
                    double x = P.p[3 * ((v + 1) % 3) + k] - P.p[3 * v + k];
                    e += x * x;
                }
                r = fmax(r, sqrt(d));
                L = fmax(L, sqrt(e));
            }
            double dc = INFINITY;
            for (size_t k = 0; k < q.ncand; k++) {
                const double *t = b->tri + 9 * (size_t)q.cand[k];
                double d = ag_surface_point_triangle(c, t, t + 3, t + 6);
                if (d < dc)
                    dc = d;
            }
            if (dc + r <= tol) {
                if (dc + r > out->upper)
                    out->upper = dc + r;
                continue;
            }
            if (L <= tol || P.depth >= MAX_DEPTH) {
                failed = 1; /* as fine as it gets and still not proven */
                break;
            }
            if (AG_ARRAY_RESERVE(stack, cap, top + 4)) {
                failed = 1;
                break;
            }
            double m[9];
            for (int v = 0; v < 3; v++)
                for (int k = 0; k < 3; k++)
                    m[3 * v + k] = 0.5 * (P.p[3 * v + k] + P.p[3 * ((v + 1) % 3) + k]);
            /* corners 0, 1, 2; midpoints m0 (0-1), m1 (1-2), m2 (2-0) */
            const double *sub[4][3] = {{P.p, m, m + 6},
                                       {m, P.p + 3, m + 3},
                                       {m + 6, m + 3, P.p + 6},
                                       {m, m + 3, m + 6}};
            for (int s = 0; s < 4; s++) {
                piece *Q = &stack[top++];
                for (int v = 0; v < 3; v++)
                    memcpy(Q->p + 3 * v, sub[s][v], 3 * sizeof(double));
                Q->depth = P.depth + 1;
            }
        }
        if (failed) {
            out->uncovered++;
            if (stop_early || out->exhausted) {
                if (out->exhausted)
                    out->uncovered += na - i - 1;
                break;
            }
        }
    }
    free(stack);
    free(clipbuf);
    free(q.cand);
}
