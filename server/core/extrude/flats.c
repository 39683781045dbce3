/* Horizontal faces rebuilt from their winding (see flats.h). Written here because core may
 * use no polygon library (GEOS and Clipper are outside its layer); the cutting is plain
 * (quadratic in the segments of one height, which are few: only heights where upward and
 * downward faces meet are taken) and every sign decision uses the exact predicates. */
#include "flats.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "predicates.h"

#define NONE UINT32_MAX
/* A height with more boundary segments than this is left as it was (and judged by the
 * shell check): the cutting compares every pair. */
#define LEVEL_MAX_SEGMENTS 4000

typedef struct {
    double x, y; /* relative to the level's origin */
    uint32_t v;  /* shell vertex, NONE for a crossing not yet added */
} lpt;

typedef struct {
    uint32_t a, b; /* level points */
    uint32_t seg;  /* shell segment */
    uint32_t face;
    int soup; /* 1: of a horizontal face (counted in the winding), 0: another face's edge */
} lseg;

typedef struct {
    double t;
    uint32_t p;
} lcut;

typedef struct {
    uint64_t key; /* min << 32 | max of the level points */
    int c;        /* +1 from min to max, -1 the other way */
} lnet;

typedef struct {
    uint32_t a, b;
    int c;
} lpiece;

typedef struct {
    uint32_t face, a, b; /* a, b: level points */
} lout;

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static int cmp_cut(const void *a, const void *b)
{
    double x = ((const lcut *)a)->t, y = ((const lcut *)b)->t;
    return x < y ? -1 : x > y;
}

static int cmp_net(const void *a, const void *b)
{
    uint64_t x = ((const lnet *)a)->key, y = ((const lnet *)b)->key;
    return x < y ? -1 : x > y;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The winding number, seen from above, of the pieces about the point a vanishing step
 * from piece `self`'s midpoint m in direction n (Sunday's crossing rule on a ray towards
 * +x, the step taken symbolically: ties in y and in side are decided by n). */
static int winding_beside(const lpt *P, const lpiece *E, size_t ne, size_t self, double nx,
                          double ny)
{
    const lpt *sa = &P[E[self].a], *sb = &P[E[self].b];
    double m[2] = {(sa->x + sb->x) / 2, (sa->y + sb->y) / 2};
    int w = 0;
    for (size_t k = 0; k < ne; k++) {
        const lpt *A = &P[E[k].a], *B = &P[E[k].b];
        int a_le = ny < 0 ? A->y < m[1] : A->y <= m[1];
        int b_le = ny < 0 ? B->y < m[1] : B->y <= m[1];
        if (a_le == b_le)
            continue;
        int side;
        if (k == self) {
            side = ag_pred_cross_sign(B->x - A->x, B->y - A->y, nx, ny);
        } else {
            double a[2] = {A->x, A->y}, b[2] = {B->x, B->y};
            double o = ag_pred_orient2d(a, b, m);
            side = o > 0 ? 1 : o < 0 ? -1 : ag_pred_cross_sign(B->x - A->x, B->y - A->y, nx, ny);
        }
        if (a_le && side > 0)
            w += E[k].c; /* upwards, the point on its left */
        else if (!a_le && side < 0)
            w -= E[k].c; /* downwards, the point on its right */
    }
    return w;
}

typedef struct {
    lpt *pts;
    size_t npts, cap_pts;
    lseg *segs;
    size_t nsegs, cap_segs;
    lcut *cuts;
    size_t ncuts, cap_cuts;
    uint32_t *cut_start; /* per segment, into cuts (after the count) */
    lnet *net;
    size_t nnet, cap_net;
    lpiece *pieces;
    size_t npieces, cap_pieces;
    lout *out;
    size_t nout, cap_out;
    uint32_t *ids;
    size_t cap_ids;
} level_buf;

static void level_free(level_buf *L)
{
    free(L->pts);
    free(L->segs);
    free(L->cuts);
    free(L->cut_start);
    free(L->net);
    free(L->pieces);
    free(L->out);
    free(L->ids);
}

static uint32_t point_of(const level_buf *L, uint32_t v, size_t nold)
{
    size_t lo = 0, hi = nold;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (L->pts[mid].v < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return (uint32_t)lo;
}

static ag_status push_cut(level_buf *L, double t, uint32_t p)
{
    if (ag_array_reserve((void **)&L->cuts, &L->cap_cuts, L->ncuts + 1, sizeof *L->cuts) != AG_OK)
        return AG_ERR_NOMEM;
    L->cuts[L->ncuts++] = (lcut){t, p};
    return AG_OK;
}

/* Rebuilds one height from the shell segments list[0..n) (of its horizontal faces and the
 * other faces' edges at that height); up and down: the faces that get the new pieces.
 * *done: 1 when rebuilt, 0 when left as it was. */
static ag_status rebuild_level(ag_shell *s, double tol, double z, const uint32_t *list, size_t n,
                               const uint8_t *soup_face, uint32_t up, uint32_t down,
                               int merge, level_buf *L, int *done)
{
    *done = 0;
    L->npts = L->nsegs = L->ncuts = L->nnet = L->npieces = L->nout = 0;
    if (n > LEVEL_MAX_SEGMENTS)
        return AG_OK;
    /* the level's points: its segments' vertices, sorted by id */
    if (ag_array_reserve((void **)&L->ids, &L->cap_ids, 2 * n, sizeof *L->ids) != AG_OK)
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < n; i++) {
        L->ids[2 * i] = s->segs[3 * list[i] + 1];
        L->ids[2 * i + 1] = s->segs[3 * list[i] + 2];
    }
    qsort(L->ids, 2 * n, sizeof *L->ids, cmp_u32);
    const double *o = &s->pos[3 * L->ids[0]];
    double ox = o[0], oy = o[1];
    for (size_t i = 0; i < 2 * n; i++) {
        if (i && L->ids[i] == L->ids[i - 1])
            continue;
        if (ag_array_reserve((void **)&L->pts, &L->cap_pts, L->npts + 1, sizeof *L->pts) != AG_OK)
            return AG_ERR_NOMEM;
        const double *p = &s->pos[3 * L->ids[i]];
        L->pts[L->npts++] = (lpt){p[0] - ox, p[1] - oy, L->ids[i]};
    }
    size_t nold = L->npts;
    if (ag_array_reserve((void **)&L->segs, &L->cap_segs, n, sizeof *L->segs) != AG_OK)
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < n; i++) {
        const uint32_t *g = &s->segs[3 * list[i]];
        L->segs[L->nsegs++] = (lseg){point_of(L, g[1], nold), point_of(L, g[2], nold), list[i],
                                     g[0], soup_face[g[0]]};
    }
    /* crossings of a horizontal face's edge with any other edge: new points (one point for
     * crossings within tol of each other or of an existing point) */
    for (size_t i = 0; i < L->nsegs; i++)
        for (size_t j = i + 1; j < L->nsegs; j++) {
            const lseg *u = &L->segs[i], *w = &L->segs[j];
            if (!merge || (!u->soup && !w->soup))
                continue; /* faces of one kind that cross overlap: nothing to rebuild */
            const lpt *A = &L->pts[u->a], *B = &L->pts[u->b], *C = &L->pts[w->a], *D = &L->pts[w->b];
            if (fmax(A->x, B->x) < fmin(C->x, D->x) - tol || fmax(C->x, D->x) < fmin(A->x, B->x) - tol ||
                fmax(A->y, B->y) < fmin(C->y, D->y) - tol || fmax(C->y, D->y) < fmin(A->y, B->y) - tol)
                continue;
            double a[2] = {A->x, A->y}, b[2] = {B->x, B->y}, c[2] = {C->x, C->y}, d[2] = {D->x, D->y};
            if (!ag_pred_segments_cross(a, b, c, d))
                continue;
            double ex = b[0] - a[0], ey = b[1] - a[1], fx = d[0] - c[0], fy = d[1] - c[1];
            double den = ex * fy - ey * fx;
            if (den == 0)
                continue;
            double t = ((c[0] - a[0]) * fy - (c[1] - a[1]) * fx) / den;
            double px = a[0] + t * ex, py = a[1] + t * ey;
            uint32_t hit = NONE;
            for (size_t k = 0; k < L->npts && hit == NONE; k++)
                if (hypot(L->pts[k].x - px, L->pts[k].y - py) <= tol)
                    hit = (uint32_t)k;
            if (hit != NONE)
                continue; /* an existing point: found below as a point on both edges */
            if (ag_array_reserve((void **)&L->pts, &L->cap_pts, L->npts + 1, sizeof *L->pts) != AG_OK)
                return AG_ERR_NOMEM;
            L->pts[L->npts++] = (lpt){px, py, NONE};
        }
    /* every point on an edge's inside cuts it */
    L->cut_start = realloc(L->cut_start, (L->nsegs + 1) * sizeof *L->cut_start);
    if (!L->cut_start)
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < L->nsegs; i++) {
        const lseg *u = &L->segs[i];
        const lpt *A = &L->pts[u->a], *B = &L->pts[u->b];
        double a[2] = {A->x, A->y}, b[2] = {B->x, B->y};
        double lx = fmin(a[0], b[0]) - tol, hx = fmax(a[0], b[0]) + tol;
        double ly = fmin(a[1], b[1]) - tol, hy = fmax(a[1], b[1]) + tol;
        double ex = b[0] - a[0], ey = b[1] - a[1], len2 = ex * ex + ey * ey;
        L->cut_start[i] = (uint32_t)L->ncuts;
        if (ag_array_reserve((void **)&L->cuts, &L->cap_cuts, L->ncuts + 2, sizeof *L->cuts) != AG_OK)
            return AG_ERR_NOMEM;
        L->cuts[L->ncuts++] = (lcut){0, u->a};
        for (size_t k = 0; k < L->npts; k++) {
            if (k == u->a || k == u->b)
                continue;
            const lpt *P = &L->pts[k];
            if (P->x < lx || P->x > hx || P->y < ly || P->y > hy)
                continue;
            double p[2] = {P->x, P->y};
            if (hypot(p[0] - a[0], p[1] - a[1]) <= tol || hypot(p[0] - b[0], p[1] - b[1]) <= tol)
                continue;
            if (ag_pred_segment_dist(p, a, b) > tol)
                continue;
            if (push_cut(L, ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2, (uint32_t)k) != AG_OK)
                return AG_ERR_NOMEM;
        }
        if (push_cut(L, 1, u->b) != AG_OK)
            return AG_ERR_NOMEM;
        qsort(L->cuts + L->cut_start[i] + 1, L->ncuts - L->cut_start[i] - 2, sizeof *L->cuts, cmp_cut);
    }
    L->cut_start[L->nsegs] = (uint32_t)L->ncuts;
    /* the horizontal faces' pieces, netted: u -> v cancels v -> u */
    for (size_t i = 0; i < L->nsegs && merge; i++) {
        if (!L->segs[i].soup)
            continue;
        for (uint32_t k = L->cut_start[i]; k + 1 < L->cut_start[i + 1]; k++) {
            uint32_t p = L->cuts[k].p, q = L->cuts[k + 1].p;
            if (p == q)
                continue;
            if (ag_array_reserve((void **)&L->net, &L->cap_net, L->nnet + 1, sizeof *L->net) != AG_OK)
                return AG_ERR_NOMEM;
            L->net[L->nnet++] = p < q ? (lnet){(uint64_t)p << 32 | q, 1}
                                      : (lnet){(uint64_t)q << 32 | p, -1};
        }
    }
    if (L->nnet) /* qsort must not be given a null array, even of no items */
        qsort(L->net, L->nnet, sizeof *L->net, cmp_net);
    for (size_t i = 0; i < L->nnet;) {
        size_t j = i;
        int c = 0;
        while (j < L->nnet && L->net[j].key == L->net[i].key)
            c += L->net[j++].c;
        if (c) {
            if (ag_array_reserve((void **)&L->pieces, &L->cap_pieces, L->npieces + 1,
                                 sizeof *L->pieces) != AG_OK)
                return AG_ERR_NOMEM;
            uint32_t p = (uint32_t)(L->net[i].key >> 32), q = (uint32_t)L->net[i].key;
            L->pieces[L->npieces++] = c > 0 ? (lpiece){p, q, c} : (lpiece){q, p, -c};
        }
        i = j;
    }
    /* each piece's winding either side: +1 on its left makes it the upward face's, -1 on
     * its right the downward face's; anything else leaves the level as it was */
    for (size_t i = 0; i < L->npieces; i++) {
        const lpt *A = &L->pts[L->pieces[i].a], *B = &L->pts[L->pieces[i].b];
        double dx = B->x - A->x, dy = B->y - A->y;
        int wl = winding_beside(L->pts, L->pieces, L->npieces, i, -dy, dx);
        int wr = winding_beside(L->pts, L->pieces, L->npieces, i, dy, -dx);
        if (wl - wr != L->pieces[i].c || wl < 0 || wl > 1 || wr < -1 || wr > 0)
            return AG_OK;
        for (int side = 0; side < 2; side++) {
            if (side == 0 ? wl != 1 : wr != -1)
                continue;
            if (ag_array_reserve((void **)&L->out, &L->cap_out, L->nout + 1, sizeof *L->out) != AG_OK)
                return AG_ERR_NOMEM;
            L->out[L->nout++] = (lout){side == 0 ? up : down, L->pieces[i].a, L->pieces[i].b};
        }
    }
    /* the other faces' edges (and without a merge every edge), cut */
    for (size_t i = 0; i < L->nsegs; i++) {
        if ((merge && L->segs[i].soup) || L->cut_start[i + 1] - L->cut_start[i] == 2)
            continue;
        for (uint32_t k = L->cut_start[i]; k + 1 < L->cut_start[i + 1]; k++) {
            uint32_t p = L->cuts[k].p, q = L->cuts[k + 1].p;
            if (p == q)
                continue;
            if (ag_array_reserve((void **)&L->out, &L->cap_out, L->nout + 1, sizeof *L->out) != AG_OK)
                return AG_ERR_NOMEM;
            L->out[L->nout++] = (lout){L->segs[i].face, p, q};
        }
    }
    /* commit: the crossings become vertices, the replaced segments are emptied */
    for (size_t k = nold; k < L->npts; k++)
        if (ag_shell_add_vertex(s, L->pts[k].x + ox, L->pts[k].y + oy, z, &L->pts[k].v) != AG_OK)
            return AG_ERR_NOMEM;
    for (size_t i = 0; i < L->nsegs; i++)
        if ((merge && L->segs[i].soup) || L->cut_start[i + 1] - L->cut_start[i] > 2) {
            uint32_t *g = &s->segs[3 * L->segs[i].seg];
            g[2] = g[1];
        }
    for (size_t i = 0; i < L->nout; i++)
        if (ag_shell_add_segment(s, L->out[i].face, L->pts[L->out[i].a].v,
                                 L->pts[L->out[i].b].v) != AG_OK)
            return AG_ERR_NOMEM;
    *done = 1;
    return AG_OK;
}

/* The level (lz ascending, each its lowest height) that height z belongs to, or NONE. */
static size_t level_of(const double *lz, size_t nl, double z, double tol)
{
    size_t lo = 0, hi = nl; /* the first level above z + tol */
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (lz[mid] <= z + tol)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo == 0 || z - lz[lo - 1] > 2 * tol)
        return NONE;
    return lo - 1;
}

ag_status ag_flats_rebuild(ag_shell *s, double tol)
{
    s->flat_levels = s->flat_rebuilt = s->flat_left = 0; if (getenv("AG_NOFLATS")) return AG_OK;
    size_t nf = s->nfaces, ns = s->nsegs;
    if (!nf || !ns)
        return AG_OK;
    ag_status st = AG_OK;
    uint8_t *hor = calloc(nf, 1); /* 0 no segment, 1 horizontal, 2 not */
    double *fz = malloc(nf * sizeof *fz), *area = calloc(nf, sizeof *area);
    uint32_t *first = malloc(nf * sizeof *first);
    double *lz = NULL;
    uint32_t *lup = NULL, *ldown = NULL, *lcount = NULL, *lstart = NULL, *list = NULL;
    uint8_t *soup = NULL, *both = NULL;
    level_buf L;
    memset(&L, 0, sizeof L);
    if (!hor || !fz || !area || !first) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (size_t i = 0; i < ns; i++) {
        const uint32_t *g = &s->segs[3 * i];
        if (g[1] == g[2])
            continue;
        uint32_t f = g[0];
        const double *a = &s->pos[3 * g[1]], *b = &s->pos[3 * g[2]];
        if (hor[f] == 0) {
            hor[f] = 1;
            fz[f] = a[2];
            first[f] = g[1];
        }
        /* within tol: a corner made by an event at the step's height (computed, not set
         * to it) lies a rounding off it */
        if (hor[f] == 1 && (fabs(a[2] - fz[f]) > tol || fabs(b[2] - fz[f]) > tol))
            hor[f] = 2;
        if (hor[f] == 1) {
            const double *o = &s->pos[3 * first[f]];
            area[f] += (a[0] - o[0]) * (b[1] - o[1]) - (b[0] - o[0]) * (a[1] - o[1]);
        }
    }
    /* heights with an upward and a downward face */
    size_t nh = 0;
    for (size_t f = 0; f < nf; f++)
        nh += hor[f] == 1;
    if (!nh)
        goto out;
    lz = malloc(nh * sizeof *lz);
    if (!lz) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    nh = 0;
    for (size_t f = 0; f < nf; f++)
        if (hor[f] == 1)
            lz[nh++] = fz[f];
    qsort(lz, nh, sizeof *lz, cmp_double);
    size_t nl = 0;
    for (size_t i = 0; i < nh; i++)
        if (!nl || lz[i] - lz[nl - 1] > tol)
            lz[nl++] = lz[i]; /* heights within tol of a level's lowest are that level */
    lup = malloc(nl * sizeof *lup);
    ldown = malloc(nl * sizeof *ldown);
    lcount = calloc(nl + 1, sizeof *lcount);
    lstart = calloc(nl + 1, sizeof *lstart);
    soup = calloc(nf, 1);
    if (!lup || !ldown || !lcount || !lstart || !soup) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (size_t l = 0; l < nl; l++)
        lup[l] = ldown[l] = NONE;
    for (size_t f = 0; f < nf; f++)
        if (hor[f] == 1) {
            size_t l = level_of(lz, nl, fz[f], tol);
            if (area[f] > 0 && lup[l] == NONE)
                lup[l] = (uint32_t)f;
            if (area[f] < 0 && ldown[l] == NONE)
                ldown[l] = (uint32_t)f;
            lcount[l]++;
        }
    /* a height with two horizontal faces or more is rebuilt (faces of one kind only may
     * leave corners of one on the other's edges); the upward or downward pieces go to a
     * face of the other kind or without area when it has none of its own */
    both = calloc(nl, 1);
    if (!both) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (size_t l = 0; l < nl; l++)
        both[l] = lup[l] != NONE && ldown[l] != NONE;
    for (size_t f = 0; f < nf; f++)
        if (hor[f] == 1) {
            size_t l = level_of(lz, nl, fz[f], tol);
            if (lup[l] == NONE && f != ldown[l])
                lup[l] = (uint32_t)f;
            else if (ldown[l] == NONE && f != lup[l])
                ldown[l] = (uint32_t)f;
        }
    size_t active = 0;
    for (size_t l = 0; l < nl; l++) {
        if (lcount[l] < 2)
            lup[l] = ldown[l] = NONE;
        active += lup[l] != NONE && ldown[l] != NONE;
        lcount[l] = 0;
    }
    s->flat_levels = active;
    if (!active)
        goto out;
    for (size_t f = 0; f < nf; f++)
        soup[f] = hor[f] == 1;
    /* the segments of each active height: its horizontal faces' and the others' lying in it */
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < ns; i++) {
            const uint32_t *g = &s->segs[3 * i];
            if (g[1] == g[2])
                continue;
            double za = s->pos[3 * g[1] + 2], zb = s->pos[3 * g[2] + 2];
            if (hor[g[0]] == 1 ? 0 : fabs(za - zb) > tol)
                continue;
            size_t l = level_of(lz, nl, hor[g[0]] == 1 ? fz[g[0]] : za, tol);
            if (l == NONE)
                continue;
            if (lup[l] == NONE || ldown[l] == NONE)
                continue;
            if (pass == 0)
                lcount[l + 1]++;
            else
                list[lstart[l]++] = (uint32_t)i;
        }
        if (pass == 0) {
            for (size_t l = 0; l < nl; l++)
                lcount[l + 1] += lcount[l];
            memcpy(lstart, lcount, (nl + 1) * sizeof *lstart);
            list = malloc((lcount[nl] ? lcount[nl] : 1) * sizeof *list);
            if (!list) {
                st = AG_ERR_NOMEM;
                goto out;
            }
        }
    }
    for (size_t l = 0; l < nl && st == AG_OK; l++) {
        if (lup[l] == NONE || ldown[l] == NONE)
            continue;
        int done = 0;
        st = rebuild_level(s, tol, lz[l], list + lcount[l], lcount[l + 1] - lcount[l], soup,
                           lup[l], ldown[l], both[l], &L, &done);
        if (done)
            s->flat_rebuilt++;
        else
            s->flat_left++;
    }
out:
    level_free(&L);
    free(hor);
    free(fz);
    free(area);
    free(first);
    free(lz);
    free(lup);
    free(ldown);
    free(lcount);
    free(lstart);
    free(list);
    free(soup);
    free(both);
    return st;
}
