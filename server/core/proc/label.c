#include "label.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"
#include "../base/search.h"
#include "../base/tolerance.h"
#include "gframe.h"
#include "surface.h"
#include "weld.h"

/* Orientation of a component: the 4-fold direction of its faces' horizontal normals,
 * weighted by area times their horizontal part, when it is clear: the weighted directions
 * agree at least this much (1: all faces square to one frame; a cylinder's facets give about
 * 0), and at least this share of the area is not horizontal. Otherwise the axes are its
 * frame. Below ORIENT_SNAP radians it is the axes' frame exactly. */
#define ORIENT_MIN_AGREEMENT 0.5
#define ORIENT_MIN_VERTICAL 0.05
#define ORIENT_SNAP 1e-9
/* Surfaces are compared only when their areas agree this closely (relative; areas_close). */
#define AREA_SLACK 0.02
/* Surface comparisons one component may make (against exemplars and under turns) before it
 * is taken as new: many different shapes with equal boxes and areas cost linear time, and
 * such a component only shares less. */
#define MAX_SURFACE_CHECKS 64

void ag_label_rotate(int k, double *x, double *y)
{
    double a = *x, b = *y;
    switch (k & 3) {
    case 1: *x = -b; *y = a; break;
    case 2: *x = -a; *y = -b; break;
    case 3: *x = b; *y = -a; break;
    default: break;
    }
}

static void centroid(const double *t, double c[3])
{
    for (int a = 0; a < 3; a++)
        c[a] = (t[a] + t[3 + a] + t[6 + a]) / 3.0;
}

static double tri_dist(const double *x, const double *y, int shift)
{
    double m = 0;
    for (int v = 0; v < 3; v++) {
        const double *p = x + 3 * v, *q = y + 3 * ((v + shift) % 3);
        double d = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                   (p[2] - q[2]) * (p[2] - q[2]);
        if (d > m)
            m = d;
    }
    return sqrt(m);
}

/* Soups with at most this many pairs, and a of at most SMALL_A triangles, are matched by
 * comparing every pair (a window of a few dozen triangles): cheaper than building a cell
 * index for them. */
#define SMALL_PAIRS 4096
#define SMALL_A 128

/* The cell of 2 tol holding a triangle's centroid. */
static void centroid_cell(const double *t, double cell, int64_t k[3])
{
    double c[3];
    centroid(t, c);
    for (int q = 0; q < 3; q++)
        k[q] = (int64_t)floor(c[q] / cell);
}

/* The choice of a partner for one triangle of b: the nearest within tol of the triangles of a
 * whose centroid cell is next to b's, then the first in the order of a scan of those 27
 * cells, then in a's order. */
typedef struct {
    double d;
    size_t i; /* SIZE_MAX: none yet */
    int rank; /* the cell's place in the scan */
} choice;

static void offer(choice *c, const double *tb, const int64_t kb[3], const double *ta,
                  const int64_t ka[3], size_t i, double tol)
{
    int rank = 0;
    for (int q = 0; q < 3; q++) {
        int64_t off = ka[q] - kb[q];
        if (off < -1 || off > 1)
            return; /* outside the 27 cells */
        rank = 3 * rank + (int)(off + 1);
    }
    double d = INFINITY;
    for (int sh = 0; sh < 3; sh++)
        d = fmin(d, tri_dist(tb, ta, sh));
    if (d <= tol && (d < c->d || (d == c->d && (rank < c->rank || (rank == c->rank && i < c->i))))) {
        c->d = d;
        c->i = i;
        c->rank = rank;
    }
}

/* Takes c's partner; 0 when there is none (one more miss). */
static int settle(const choice *c, uint8_t *used, double *worst, size_t *miss)
{
    if (c->i == SIZE_MAX) {
        (*miss)++;
        return 0;
    }
    used[c->i] = 1;
    if (c->d > *worst)
        *worst = c->d;
    return 1;
}

/* match_soups below SMALL_PAIRS: every pair, with the same choice (the nearest within tol
 * among the triangles of a whose centroid cell is next to b's, then the first in cell order,
 * then in a's order). */
static double match_small(const double *a, size_t na, const double *b, size_t nb, double tol,
                          double cell, size_t *unmatched, int stop_at_miss)
{
    uint8_t used[SMALL_A];
    int64_t ka[3 * SMALL_A];
    size_t miss = 0;
    double worst = 0;
    memset(used, 0, na);
    for (size_t i = 0; i < na; i++)
        centroid_cell(a + 9 * i, cell, ka + 3 * i);
    for (size_t j = 0; j < nb; j++) {
        const double *tb = b + 9 * j;
        int64_t kb[3];
        centroid_cell(tb, cell, kb);
        choice c = {INFINITY, SIZE_MAX, 27};
        for (size_t i = 0; i < na; i++)
            if (!used[i])
                offer(&c, tb, kb, a + 9 * i, ka + 3 * i, i, tol);
        if (!settle(&c, used, &worst, &miss) && stop_at_miss)
            break;
    }
    if (unmatched)
        *unmatched = miss;
    return worst;
}

/* ag_label_match_triangles; with stop_at_miss it returns at the first triangle of b without
 * a partner (*unmatched then 1): a comparison that only asks whether all match stops there
 * instead of probing every other triangle. */
static double match_soups(const double *a, size_t na, const double *b, size_t nb, double tol,
                          size_t *unmatched, int stop_at_miss)
{
    size_t miss = 0;
    double worst = 0;
    if (tol <= 0)
        tol = AG_PROC_TINY;
    /* the same order is the common case (copies): one pass, no table */
    if (na == nb) {
        size_t i = 0;
        for (; i < na; i++) {
            double d = INFINITY;
            for (int sh = 0; sh < 3 && !(d <= tol); sh++)
                d = fmin(d, tri_dist(b + 9 * i, a + 9 * i, sh));
            if (!(d <= tol))
                break;
            if (d > worst)
                worst = d;
        }
        if (i == na) {
            if (unmatched)
                *unmatched = 0;
            return worst;
        }
        worst = 0;
    }
    /* A match within tol has its centroid within tol of b's on every axis. a's triangles
     * are registered in the cells of size >= 4 r that [c - r, c + r] meets (r: tol, a
     * little more for the centroids' rounding; at most 2 cells per axis), so one look-up of
     * b's own cell finds every candidate. The choice among candidates is that of a scan of
     * the 27 cells of size 2 tol around b's centroid, in cell order, then triangle order:
     * the nearest, the first of that scan on a tie. */
    double cell = 2 * tol, amax = 0;
    if (na <= SMALL_A && (uint64_t)na * nb <= SMALL_PAIRS)
        return match_small(a, na, b, nb, tol, cell, unmatched, stop_at_miss);
    for (size_t i = 0; i < 9 * na; i++)
        amax = fmax(amax, fabs(a[i]));
    double r = 1.01 * tol + 16 * DBL_EPSILON * (amax + 1), icell = 4 * r;
    ag_radix_item *ha = NULL;
    size_t nh = 0, cap_h = 0;
    int64_t *acell = malloc((3 * na + 1) * sizeof *acell); /* a's cells of size 2 tol */
    uint8_t *used = calloc(na + 1, 1);
    if (!acell || !used || AG_ARRAY_RESERVE(ha, cap_h, 2 * na + 1)) {
        free(ha);
        free(acell);
        free(used);
        return -1;
    }
    for (size_t i = 0; i < na; i++) {
        double c[3];
        centroid(a + 9 * i, c);
        int64_t lo[3], hi[3];
        for (int q = 0; q < 3; q++) {
            acell[3 * i + q] = (int64_t)floor(c[q] / cell);
            lo[q] = (int64_t)floor((c[q] - r) / icell);
            hi[q] = (int64_t)floor((c[q] + r) / icell);
        }
        for (int64_t x = lo[0]; x <= hi[0]; x++)
            for (int64_t y = lo[1]; y <= hi[1]; y++)
                for (int64_t z = lo[2]; z <= hi[2]; z++) {
                    if (AG_ARRAY_RESERVE(ha, cap_h, nh + 1)) {
                        free(ha);
                        free(acell);
                        free(used);
                        return -1;
                    }
                    ha[nh].key = ag__cell_hash(x, y, z);
                    ha[nh++].val = (uint32_t)i;
                }
    }
    ag_radix_index cells;
    if (ag_radix_sort(ha, nh) || ag_radix_index_build(&cells, ha, nh)) {
        free(ha);
        free(acell);
        free(used);
        return -1;
    }
    for (size_t j = 0; j < nb; j++) {
        const double *tb = b + 9 * j;
        double c[3];
        centroid(tb, c);
        int64_t k[3] = {(int64_t)floor(c[0] / cell), (int64_t)floor(c[1] / cell),
                        (int64_t)floor(c[2] / cell)};
        uint64_t h = ag__cell_hash((int64_t)floor(c[0] / icell), (int64_t)floor(c[1] / icell),
                                   (int64_t)floor(c[2] / icell));
        choice ch = {INFINITY, SIZE_MAX, 27};
        for (size_t e = ag_radix_index_find(&cells, h); e < nh && ha[e].key == h; e++) {
            uint32_t i = ha[e].val;
            if (!used[i])
                offer(&ch, tb, k, a + 9 * (size_t)i, acell + 3 * (size_t)i, i, tol);
        }
        if (!settle(&ch, used, &worst, &miss) && stop_at_miss)
            break;
    }
    ag_radix_index_free(&cells);
    free(ha);
    free(acell);
    free(used);
    if (unmatched)
        *unmatched = miss;
    return worst;
}

double ag_label_match_triangles(const double *a, size_t na, const double *b, size_t nb,
                                double tol, size_t *unmatched)
{
    return match_soups(a, na, b, nb, tol, unmatched, 0);
}

int ag_label_soups_match(const double *a, size_t na, const double *b, size_t nb, double tol,
                         double *worst)
{
    size_t miss = 0;
    double w = match_soups(a, na, b, nb, tol, &miss, 1);
    if (w < 0)
        return -1;
    *worst = w;
    return miss == 0;
}

/* The surfaces of soups a and b, each on the other. */
static int surfaces_match(const double *a, size_t na, const double *b, size_t nb, double tol,
                          double *deviation)
{
    ag_surface sa, sb;
    ag_surface_cover_result ab, ba;
    if (ag_surface_init(&sb, b, nb)) {
        ag_surface_free(&sb);
        return -1;
    }
    ag_surface_cover(&sb, a, na, tol, 0, 1, &ab);
    ag_surface_free(&sb);
    if (ab.uncovered)
        return 0;
    if (ag_surface_init(&sa, a, na)) {
        ag_surface_free(&sa);
        return -1;
    }
    ag_surface_cover(&sa, b, nb, tol, 0, 1, &ba);
    ag_surface_free(&sa);
    if (ba.uncovered)
        return 0;
    *deviation = fmax(ab.upper, ba.upper);
    return 1;
}

int ag_label_same_surface(const double *a, size_t na, const double *b, size_t nb, double tol,
                          double *deviation)
{
    if (na == nb) {
        int same = ag_label_soups_match(a, na, b, nb, tol, deviation);
        if (same)
            return same;
    }
    return surfaces_match(a, na, b, nb, tol, deviation);
}

void ag_labels_free(ag_labels *l)
{
    if (!l)
        return;
    free(l->box);
    free(l->ntris);
    free(l->label);
    free(l->rot);
    free(l->mirror);
    free(l->turn);
    free(l->tri_start);
    free(l->tris);
    free(l->exemplar);
    free(l->count);
    free(l->variant);
    free(l->vrot);
    free(l->variant_exemplar);
    free(l->variant_count);
    free(l->variant_label);
    free(l->variant_deviation);
    free(l);
}

/* A component's own frame: turned by -phi about its box centre, its oriented box there has
 * extents ext and its centre lies at oc (relative to the box centre, in the turned frame). */
typedef struct {
    double phi;
    double oc[2];
    double ext[3];
} frame;

static const double *vertex(const ag_mesh *m, uint32_t t, int v)
{
    return m->pos + 3 * (size_t)m->tri[3 * (size_t)t + v];
}

static void frame_of(const ag_mesh *m, const ag_labels *L, uint32_t c, int oriented, frame *f)
{
    double sx = 0, sy = 0, wh = 0, wall = 0;
    if (oriented)
        for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++) {
            const double *p = vertex(m, L->tris[s], 0), *q = vertex(m, L->tris[s], 1),
                         *r = vertex(m, L->tris[s], 2);
            double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            double v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
            double nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2],
                   nz = u[0] * v[1] - u[1] * v[0];
            double h = sqrt(nx * nx + ny * ny);
            wall += sqrt(nx * nx + ny * ny + nz * nz);
            if (!(h > 0))
                continue;
            /* cos and sin of 4 alpha from the unit direction (nx, ny) / h */
            double c1 = nx / h, s1 = ny / h;
            double c2 = c1 * c1 - s1 * s1, s2 = 2 * c1 * s1;
            sx += h * (c2 * c2 - s2 * s2);
            sy += h * (2 * c2 * s2);
            wh += h;
        }
    f->phi = 0;
    if (wh > 0 && wh >= ORIENT_MIN_VERTICAL * wall &&
        sqrt(sx * sx + sy * sy) >= ORIENT_MIN_AGREEMENT * wh) {
        f->phi = atan2(sy, sx) / 4;
        if (fabs(f->phi) < ORIENT_SNAP)
            f->phi = 0;
    }
    double ctr[3];
    ag_box_centre(&L->box[c], ctr);
    if (f->phi == 0) {
        f->oc[0] = f->oc[1] = 0;
        ag_box_extents(&L->box[c], f->ext);
        return;
    }
    double cs = cos(f->phi), sn = sin(f->phi);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++)
        for (int v = 0; v < 3; v++) {
            const double *p = vertex(m, L->tris[s], v);
            double x = p[0] - ctr[0], y = p[1] - ctr[1];
            double xr = cs * x + sn * y, yr = -sn * x + cs * y;
            lo[0] = fmin(lo[0], xr);
            hi[0] = fmax(hi[0], xr);
            lo[1] = fmin(lo[1], yr);
            hi[1] = fmax(hi[1], yr);
        }
    for (int a = 0; a < 2; a++) {
        f->oc[a] = 0.5 * (lo[a] + hi[a]);
        f->ext[a] = hi[a] - lo[a];
    }
    f->ext[2] = ag_box_extent(&L->box[c], 2);
}

/* Component c in its own frame, centred on its oriented box, mirrored (x -> -x, winding
 * reversed so it still faces out) and turned by k quarter turns. */
static void oriented_soup(const ag_mesh *m, const ag_labels *L, const frame *f, uint32_t c, int k,
                          int mirror, double *out)
{
    double ctr[3];
    ag_box_centre(&L->box[c], ctr);
    double cs = cos(f->phi), sn = sin(f->phi);
    size_t o = 0;
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++)
        for (int v = 0; v < 3; v++) {
            const double *p = vertex(m, L->tris[s], mirror && v ? 3 - v : v);
            double x = p[0] - ctr[0], y = p[1] - ctr[1];
            double xr = cs * x + sn * y - f->oc[0], yr = -sn * x + cs * y - f->oc[1];
            if (f->phi == 0) { /* exactly the box frame */
                xr = x;
                yr = y;
            }
            if (mirror)
                xr = -xr;
            ag_label_rotate(k, &xr, &yr);
            out[o++] = xr;
            out[o++] = yr;
            out[o++] = p[2] - ctr[2];
        }
}

/* Component c's triangles relative to its box centre. */
static void box_soup(const ag_mesh *m, const ag_labels *L, uint32_t c, double *out)
{
    double ctr[3];
    ag_box_centre(&L->box[c], ctr);
    size_t o = 0;
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++)
        for (int v = 0; v < 3; v++) {
            const double *p = vertex(m, L->tris[s], v);
            for (int a = 0; a < 3; a++)
                out[o++] = p[a] - ctr[a];
        }
}

/* The terminal of e (its triangles in its box) placed on c's box with k quarter turns as
 * derivation places it (gframe.h), relative to c's box centre. */
static void placed_soup(const ag_mesh *m, const ag_labels *L, uint32_t e, uint32_t c, int k,
                        double *out)
{
    double S[3], ctr[3];
    ag_box_extents(&L->box[e], S);
    ag_box_centre(&L->box[c], ctr);
    ag_box B = L->box[c];
    for (int a = 0; a < 3; a++) {
        B.min[a] -= ctr[a];
        B.max[a] -= ctr[a];
    }
    ag_gframe G = ag_gframe_place(&ag_gframe_identity, S, k, &B);
    size_t o = 0;
    for (uint32_t s = L->tri_start[e]; s < L->tri_start[e + 1]; s++)
        for (int v = 0; v < 3; v++) {
            const double *p = vertex(m, L->tris[s], v);
            double x[3] = {p[0] - L->box[e].min[0], p[1] - L->box[e].min[1],
                           p[2] - L->box[e].min[2]};
            ag_gframe_apply(&G, x, out + o);
            o += 3;
        }
}

static int extents_match(const double *de, const double *dc, int k, double tol)
{
    double x = de[0], y = de[1];
    if (k & 1) {
        x = de[1];
        y = de[0];
    }
    return fabs(x - dc[0]) <= tol && fabs(y - dc[1]) <= tol && fabs(de[2] - dc[2]) <= tol;
}

typedef struct {
    uint64_t key;
    int32_t head; /* first class in the bucket */
} bucket;

typedef struct {
    const ag_mesh *m;
    ag_labels *L;
    const frame *F;
    double *sa, *sb;
    double *area; /* per component: its surface area */
    double *ldev; /* per component: the label match's bound when it matched its exemplar's
                     triangle list in the box frames, unmirrored (else -1): variant_pass's
                     shortcut */
    int no_rotation;
    int nomem;
    double turn_move; /* AG_PROC_LABEL_TURN_MOVE in the model's unit */
    int64_t sa_of; /* label_pass: the (exemplar, turn) whose oriented soup sa holds, -1 */
    unsigned checks_left; /* surface comparisons the current component may still make */
} lctx;

/* A necessary-looking condition before surfaces are compared: the areas agree within
 * AREA_SLACK. Two surfaces within a few millimetres of each other could differ more (a
 * folded sliver), so this may miss such a match, never make one: what matches is still
 * proven by the comparison. It keeps the comparison for what is likely to match. */
static int areas_close(const lctx *x, uint32_t e, uint32_t c)
{
    double a = x->area[e], b = x->area[c];
    return fabs(a - b) <= AREA_SLACK * fmax(a, b);
}

/* Compares candidate c (its soup in sb) with the soup in sa; 1 when they match. fast: the
 * triangle lists only; else the surfaces only. */
static int compare(lctx *x, size_t na, size_t nb, double tol, int fast, double *dev)
{
    if (fast) {
        if (na != nb)
            return 0;
        int same = ag_label_soups_match(x->sa, na, x->sb, nb, tol, dev);
        if (same < 0)
            x->nomem = 1;
        return same > 0;
    }
    if (!x->checks_left)
        return 0; /* past the budget: no match, never a wrong one */
    x->checks_left--;
    x->L->surface_checks++;
    int r = surfaces_match(x->sa, na, x->sb, nb, tol, dev);
    if (r < 0)
        x->nomem = 1;
    return r > 0;
}

/* Whether c's orientation is close enough to e's, beyond quarter turns, for one label: the
 * turn between them moves c's plan corners by at most AG_PROC_LABEL_TURN_MOVE (move, in the
 * model's unit). */
static int turn_close(const frame *e, const frame *c, double move)
{
    double d = fmod(fabs(c->phi - e->phi), M_PI / 2);
    if (d > M_PI / 4)
        d = M_PI / 2 - d;
    return 0.5 * hypot(c->ext[0], c->ext[1]) * d <= move;
}

/* Labels: every component against the exemplars of the labels in its bucket and the
 * neighbouring ones, in its own frame. */
static long label_pass(lctx *x, const uint32_t *comps, size_t n, double tol)
{
    ag_labels *L = x->L;
    const frame *F = x->F;
    size_t cap;
    if (ag_array_hash_size(n, &cap))
        return -1;
    bucket *bk = calloc(cap, sizeof *bk);
    int32_t *next_in_bucket = malloc((n + 1) * sizeof *next_in_bucket);
    if (!bk || !next_in_bucket) {
        free(bk);
        free(next_in_bucket);
        return -1;
    }
    for (size_t i = 0; i < cap; i++)
        bk[i].head = -1;
    long ncls = 0;
    x->sa_of = -1;
    /* buckets: the oriented box's height and sorted plan sizes in cells of 4 tol, so a match
     * within tol is always in a neighbouring cell */
    double q = 4 * tol > 0 ? 4 * tol : AG_PROC_TINY;
    int nk = x->no_rotation ? 1 : 8;
    for (size_t i = 0; i < n && !x->nomem; i++) {
        uint32_t c = comps[i];
        x->checks_left = MAX_SURFACE_CHECKS;
        const double *dc = F[c].ext;
        int64_t kb[3] = {(int64_t)floor(dc[2] / q), (int64_t)floor(fmin(dc[0], dc[1]) / q),
                         (int64_t)floor(fmax(dc[0], dc[1]) / q)};
        int found = -1, fk = 0, have_cb = 0, ffast = 0;
        double fdev = 0;
        for (int fast = 1; fast >= 0 && found < 0 && !x->nomem; fast--)
            for (int nb = 0; nb < 27 && found < 0 && !x->nomem; nb++) {
                int64_t k0 = kb[0] + nb % 3 - 1, k1 = kb[1] + nb / 3 % 3 - 1,
                        k2 = kb[2] + nb / 9 - 1;
                uint64_t key = ag__cell_hash(k0, k1, k2);
                size_t h = key & (cap - 1);
                while (bk[h].head >= 0 && bk[h].key != key)
                    h = (h + 1) & (cap - 1);
                for (int32_t l = bk[h].head; l >= 0 && found < 0 && !x->nomem;
                     l = next_in_bucket[l]) {
                    uint32_t e = L->exemplar[l];
                    if (fast ? L->ntris[e] != L->ntris[c] : !areas_close(x, e, c))
                        continue;
                    if (!turn_close(&F[e], &F[c], x->turn_move))
                        continue;
                    for (int k = 0; k < nk && found < 0; k++) {
                        if (!extents_match(F[e].ext, dc, k, tol))
                            continue;
                        if (!have_cb) {
                            oriented_soup(x->m, L, &F[c], c, 0, 0, x->sb);
                            have_cb = 1;
                        }
                        /* the soups of one exemplar repeat for the members that follow
                         * it (the inputs are const in the comparisons) */
                        if (x->sa_of != (int64_t)e * 8 + k) {
                            oriented_soup(x->m, L, &F[e], e, k & 3, k >> 2, x->sa);
                            x->sa_of = (int64_t)e * 8 + k;
                        }
                        double dev;
                        if (compare(x, L->ntris[e], L->ntris[c], tol, fast, &dev)) {
                            found = l;
                            fk = k;
                            fdev = dev;
                            ffast = fast;
                        }
                    }
                }
            }
        x->ldev[c] = -1;
        if (found >= 0) {
            uint32_t e = L->exemplar[found];
            if (ffast && !(fk >> 2) && F[c].phi == 0 && F[e].phi == 0)
                x->ldev[c] = fdev;
            L->label[c] = found;
            L->rot[c] = (uint8_t)(fk & 3);
            L->mirror[c] = (uint8_t)(fk >> 2);
            L->turn[c] = F[c].phi - F[e].phi + (fk & 3) * (M_PI / 2);
            L->count[found]++;
            continue;
        }
        int32_t l = (int32_t)ncls++;
        L->exemplar[l] = c;
        L->count[l] = 1;
        L->label[c] = l;
        L->rot[c] = 0;
        L->mirror[c] = 0;
        L->turn[c] = 0;
        uint64_t key = ag__cell_hash(kb[0], kb[1], kb[2]);
        size_t h = key & (cap - 1);
        while (bk[h].head >= 0 && bk[h].key != key)
            h = (h + 1) & (cap - 1);
        bk[h].key = key;
        next_in_bucket[l] = bk[h].head;
        bk[h].head = l;
    }
    free(bk);
    free(next_in_bucket);
    return x->nomem ? -1 : ncls;
}

/* Variants: within each label, every member against the exemplars of its label's variants,
 * the exemplar's terminal placed on the member's box as derivation would place it. */
static long variant_pass(lctx *x, const uint32_t *comps, size_t n, double tol, int surfaces)
{
    ag_labels *L = x->L;
    /* per label, its variants as a list (newest first) */
    int32_t *head = malloc((L->nlabels + 1) * sizeof *head);
    int32_t *next = malloc((n + 1) * sizeof *next);
    if (!head || !next) {
        free(head);
        free(next);
        return -1;
    }
    for (size_t l = 0; l < L->nlabels; l++)
        head[l] = -1;
    long nv = 0;
    int nk = x->no_rotation ? 1 : 4;
    for (size_t i = 0; i < n && !x->nomem; i++) {
        uint32_t c = comps[i];
        x->checks_left = MAX_SURFACE_CHECKS;
        int32_t l = L->label[c];
        double dc[3];
        ag_box_extents(&L->box[c], dc);
        int found = -1, fk = 0, have_cb = 0;
        double fdev = 0;
        if (x->ldev[c] >= 0) {
            /* matched its label's exemplar by triangle lists in the box frames: placing the
             * exemplar's terminal on c's box differs from that match by the scaling to c's
             * extents, at most half the extents' difference per axis */
            uint32_t e = L->exemplar[l];
            int32_t v0 = L->variant[e];
            int k = L->rot[c];
            double de[3];
            ag_box_extents(&L->box[e], de);
            double ex = (k & 1) ? de[1] : de[0], ey = (k & 1) ? de[0] : de[1];
            double bound = x->ldev[c] + 0.5 * sqrt((dc[0] - ex) * (dc[0] - ex) +
                                                   (dc[1] - ey) * (dc[1] - ey) +
                                                   (dc[2] - de[2]) * (dc[2] - de[2]));
            if (v0 >= 0 && L->variant_exemplar[v0] == e && bound <= tol) {
                found = v0;
                fk = k;
                fdev = bound;
            }
        }
        for (int fast = 1; fast >= (surfaces ? 0 : 1) && found < 0 && !x->nomem; fast--)
            for (int32_t v = head[l]; v >= 0 && found < 0 && !x->nomem; v = next[v]) {
                uint32_t e = L->variant_exemplar[v];
                if (fast ? L->ntris[e] != L->ntris[c] : !areas_close(x, e, c))
                    continue;
                double de[3];
                ag_box_extents(&L->box[e], de);
                for (int k = 0; k < nk && found < 0; k++) {
                    if (!extents_match(de, dc, k, tol))
                        continue;
                    if (!have_cb) {
                        box_soup(x->m, L, c, x->sb);
                        have_cb = 1;
                    }
                    placed_soup(x->m, L, e, c, k, x->sa);
                    double dev;
                    if (compare(x, L->ntris[e], L->ntris[c], tol, fast, &dev)) {
                        found = v;
                        fk = k;
                        fdev = dev;
                    }
                }
            }
        if (found >= 0) {
            L->variant[c] = found;
            L->vrot[c] = (uint8_t)fk;
            L->variant_count[found]++;
            if (fdev > L->variant_deviation[found])
                L->variant_deviation[found] = fdev;
            continue;
        }
        int32_t v = (int32_t)nv++;
        L->variant_exemplar[v] = c;
        L->variant_count[v] = 1;
        L->variant_label[v] = l;
        L->variant_deviation[v] = 0;
        L->variant[c] = v;
        L->vrot[c] = 0;
        next[v] = head[l];
        head[l] = v;
    }
    free(head);
    free(next);
    return x->nomem ? -1 : nv;
}

ag_status ag_label_components(const ag_mesh *m, const ag_label_options *opt, ag_labels **out,
                              ag_error *err)
{
    ag_label_options o = opt ? *opt : (ag_label_options){0};
    int capped = o.tolerance <= 0;
    if (o.tolerance <= 0)
        o.tolerance = AG_PROC_LABEL_TOLERANCE;
    if (o.exact <= 0)
        o.exact = AG_PROC_LABEL_EXACT;
    if (o.exact > o.tolerance)
        o.exact = o.tolerance;
    *out = NULL;
    size_t nc = m->ncomponents;
    ag_labels *L = calloc(1, sizeof *L);
    if (!L)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while labeling");
    L->ncomponents = nc;
    L->box = malloc((nc + 1) * sizeof *L->box);
    L->ntris = calloc(nc + 1, sizeof *L->ntris);
    L->label = malloc((nc + 1) * sizeof *L->label);
    L->rot = calloc(nc + 1, 1);
    L->mirror = calloc(nc + 1, 1);
    L->turn = calloc(nc + 1, sizeof *L->turn);
    L->tri_start = calloc(nc + 2, sizeof *L->tri_start);
    L->tris = malloc((m->ntris + 1) * sizeof *L->tris);
    L->exemplar = malloc((nc + 1) * sizeof *L->exemplar);
    L->count = calloc(nc + 1, sizeof *L->count);
    L->variant = malloc((nc + 1) * sizeof *L->variant);
    L->vrot = calloc(nc + 1, 1);
    L->variant_exemplar = malloc((nc + 1) * sizeof *L->variant_exemplar);
    L->variant_count = calloc(nc + 1, sizeof *L->variant_count);
    L->variant_label = malloc((nc + 1) * sizeof *L->variant_label);
    L->variant_deviation = calloc(nc + 1, sizeof *L->variant_deviation);
    frame *F = malloc((nc + 1) * sizeof *F);
    uint32_t *list = malloc((nc + 1) * sizeof *list);
    lctx x = {.m = m, .L = L, .F = F, .no_rotation = o.no_rotation};
    size_t maxt = 0;
    if (!L->box || !L->ntris || !L->label || !L->rot || !L->mirror || !L->turn ||
        !L->tri_start || !L->tris || !L->exemplar || !L->count || !L->variant || !L->vrot ||
        !L->variant_exemplar || !L->variant_count || !L->variant_label ||
        !L->variant_deviation || !F || !list)
        goto fail;

    ag_box all = ag_mesh_bounds(m);
    L->diagonal = ag_box_diagonal(&all);
    if (!(L->diagonal > 0))
        L->diagonal = 0;
    for (size_t c = 0; c < nc; c++)
        L->box[c] = ag_box_empty();
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t c = m->tri_component[t];
        L->ntris[c]++;
        for (int v = 0; v < 3; v++)
            ag_box_extend_point(&L->box[c], m->pos + 3 * m->tri[3 * t + v]);
    }
    for (size_t c = 0; c < nc; c++) {
        L->tri_start[c + 1] = L->tri_start[c] + L->ntris[c];
        if (L->ntris[c] > maxt)
            maxt = L->ntris[c];
    }
    /* the tolerances meant in metres are taken in the file's unit, so a model exported in
     * millimetres gets the labels of the same model in metres */
    if (o.metres_per_unit > 0)
        L->units = ag_units_given(o.metres_per_unit);
    else if (ag_units_decide(&all, L->box, nc, &L->units) < 0)
        goto fail;
    double scale = L->diagonal > 0 ? L->diagonal : 1.0;
    L->tol = o.tolerance * scale;
    if (capped && L->tol > AG_PROC_LABEL_TOLERANCE_MAX / L->units.metres_per_unit)
        L->tol = AG_PROC_LABEL_TOLERANCE_MAX / L->units.metres_per_unit;
    L->exact_copies = o.exact_copies != 0;
    L->exact = fmin(o.exact * scale, L->tol);
    L->share = o.exact_copies ? L->exact : L->tol;
    x.turn_move = AG_PROC_LABEL_TURN_MOVE / L->units.metres_per_unit;

    {
        uint32_t *fill = malloc((nc + 1) * sizeof *fill);
        if (!fill)
            goto fail;
        memcpy(fill, L->tri_start, nc * sizeof *fill);
        for (size_t t = 0; t < m->ntris; t++)
            L->tris[fill[m->tri_component[t]]++] = (uint32_t)t;
        free(fill);
    }
    x.sa = malloc((9 * maxt + 1) * sizeof *x.sa);
    x.sb = malloc((9 * maxt + 1) * sizeof *x.sb);
    x.area = calloc(nc + 1, sizeof *x.area);
    x.ldev = malloc((nc + 1) * sizeof *x.ldev);
    if (!x.sa || !x.sb || !x.area || !x.ldev)
        goto fail;
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p = m->pos + 3 * (size_t)m->tri[3 * t], *q = m->pos + 3 * (size_t)m->tri[3 * t + 1],
                     *r = m->pos + 3 * (size_t)m->tri[3 * t + 2];
        double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        double nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2],
               nz = u[0] * v[1] - u[1] * v[0];
        x.area[m->tri_component[t]] += 0.5 * sqrt(nx * nx + ny * ny + nz * nz);
    }

    size_t n = 0;
    for (size_t c = 0; c < nc; c++) {
        L->label[c] = L->variant[c] = -1;
        if (L->ntris[c]) {
            list[n++] = (uint32_t)c;
            frame_of(m, L, (uint32_t)c, !o.no_rotation, &F[c]);
        }
    }
    long nl = label_pass(&x, list, n, L->tol);
    if (nl < 0)
        goto fail;
    L->nlabels = (size_t)nl;
    long nv = variant_pass(&x, list, n, L->share, !o.exact_copies);
    if (nv < 0)
        goto fail;
    L->nvariants = (size_t)nv;
    free(x.sa);
    free(x.sb);
    free(x.area);
    free(x.ldev);
    free(F);
    free(list);
    *out = L;
    return AG_OK;
fail:
    free(x.sa);
    free(x.sb);
    free(x.area);
    free(x.ldev);
    free(F);
    free(list);
    ag_labels_free(L);
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory while labeling");
}

ag_status ag_labels_name_groups(ag_mesh *m, const ag_labels *L)
{
    int32_t *group_of = malloc((L->nlabels + 1) * sizeof *group_of);
    if (!group_of)
        return AG_ERR_NOMEM;
    for (size_t l = 0; l < L->nlabels; l++)
        group_of[l] = -1;
    for (size_t g = 0; g < m->ngroups; g++)
        free(m->group_names[g]);
    m->ngroups = 0;
    ag_status st = AG_OK;
    for (size_t c = 0; c < m->ncomponents && st == AG_OK; c++) {
        int32_t lab = c < L->ncomponents ? L->label[c] : -1;
        if (lab < 0 || (size_t)lab >= L->nlabels) {
            m->component_group[c] = -1;
            continue;
        }
        if (group_of[lab] < 0) {
            char name[32];
            size_t gi;
            snprintf(name, sizeof name, "L%d", lab + 1);
            if ((st = ag_mesh_add_group(m, name, &gi)) == AG_OK)
                group_of[lab] = (int32_t)gi;
        }
        m->component_group[c] = group_of[lab];
    }
    free(group_of);
    return st;
}
