#include "shell.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/search.h"
#include "flats.h"
#include "keysort.h"
#include "weld_points.h"
#include "predicates.h"
#include "../base/tolerance.h"

#define NONE UINT32_MAX

ag_shell *ag_shell_create(void)
{
    return calloc(1, sizeof(ag_shell));
}

void ag_shell_free(ag_shell *s)
{
    if (!s)
        return;
    free(s->pos);
    free(s->faces);
    free(s->loop_start);
    free(s->idx);
    free(s->he_twin);
    free(s->he_next);
    free(s->he_face);
    free(s->segs);
    free(s);
}

ag_status ag_shell_add_vertex(ag_shell *s, double x, double y, double z, uint32_t *id)
{
    if (ag_array_reserve((void **)&s->pos, &s->cap_verts, s->nverts + 1, 3 * sizeof(double)) != AG_OK)
        return AG_ERR_NOMEM;
    double *p = &s->pos[3 * s->nverts];
    p[0] = x;
    p[1] = y;
    p[2] = z;
    *id = (uint32_t)s->nverts++;
    return AG_OK;
}

ag_status ag_shell_add_face(ag_shell *s, const ag_shell_face *f, uint32_t *id)
{
    if (ag_array_reserve((void **)&s->faces, &s->cap_faces, s->nfaces + 1, sizeof(ag_shell_face)) != AG_OK)
        return AG_ERR_NOMEM;
    s->faces[s->nfaces] = *f;
    s->faces[s->nfaces].first_loop = 0;
    s->faces[s->nfaces].nloops = 0;
    *id = (uint32_t)s->nfaces++;
    return AG_OK;
}

ag_status ag_shell_add_segment(ag_shell *s, uint32_t face, uint32_t from, uint32_t to)
{
    if (from == to)
        return AG_OK;
    if (ag_array_reserve((void **)&s->segs, &s->cap_segs, s->nsegs + 1, 3 * sizeof(uint32_t)) != AG_OK)
        return AG_ERR_NOMEM;
    uint32_t *g = &s->segs[3 * s->nsegs++];
    g[0] = face;
    g[1] = from;
    g[2] = to;
    return AG_OK;
}

/* --- welding --------------------------------------------------------------------------- */

static ag_status weld(ag_shell *s, double tol, uint32_t *map)
{
    size_t n = s->nverts;
    ag_keyed *order = malloc((n ? n : 1) * sizeof *order);
    if (!order)
        return AG_ERR_NOMEM;
    for (size_t i = 0; i < n; i++) {
        map[i] = (uint32_t)i;
        order[i] = (ag_keyed){ag_keysort_double(s->pos[3 * i]), (uint32_t)i};
    }
    ag_status st = ag_weld_points(s->pos, order, n, tol, map);
    free(order);
    return st;
}

/* --- linking ---------------------------------------------------------------------------- */

/* A directed segment or half-edge by its key from << 32 | to (val: its index). */
typedef ag_keyed seg_key;

/* Newell normal (not normalised) of face f's loops, computed relative to the face's first
 * corner: shells lie at their plan's real coordinates (RD, UTM: millions of metres), where
 * sums of coordinates would drown the face's own size. */
static void face_normal(const ag_shell *s, size_t f, double *n)
{
    n[0] = n[1] = n[2] = 0;
    const ag_shell_face *fc = &s->faces[f];
    uint32_t nl = fc->nloops & 0x7fffffffu;
    if (!nl)
        return;
    const double *o = &s->pos[3 * s->idx[s->loop_start[fc->first_loop]]];
    for (uint32_t l = fc->first_loop; l < fc->first_loop + nl; l++) {
        uint32_t a = s->loop_start[l], b = s->loop_start[l + 1];
        for (uint32_t i = a; i < b; i++) {
            const double *P = &s->pos[3 * s->idx[i]];
            const double *Q = &s->pos[3 * s->idx[i + 1 < b ? i + 1 : a]];
            double p[3] = {P[0] - o[0], P[1] - o[1], P[2] - o[2]};
            double q[3] = {Q[0] - o[0], Q[1] - o[1], Q[2] - o[2]};
            n[0] += (p[1] - q[1]) * (p[2] + q[2]);
            n[1] += (p[2] - q[2]) * (p[0] + q[0]);
            n[2] += (p[0] - q[0]) * (p[1] + q[1]);
        }
    }
}

typedef struct {
    double ang;
    uint32_t he;
} radial;

static int cmp_radial(const void *a, const void *b)
{
    double x = ((const radial *)a)->ang, y = ((const radial *)b)->ang;
    return x < y ? -1 : x > y;
}

/* An edge with k > 1 half-edges each way (solids that touch along an edge, e.g. a
 * terrace and a soffit meeting at one line): the faces are ordered around the edge and
 * each is paired with its neighbour across the solid's inside, as the two sides of one
 * solid. Left unpaired (and reported) unless the directions alternate around the edge. */
static void pair_radial(ag_shell *s, const seg_key *hk, size_t lo, size_t n, const double *fn)
{
    radial r[64];
    if (n > 64)
        return;
    uint32_t u = (uint32_t)(hk[lo].key >> 32), v = (uint32_t)hk[lo].key;
    const double *pu = &s->pos[3 * u], *pv = &s->pos[3 * v];
    double a[3] = {pv[0] - pu[0], pv[1] - pu[1], pv[2] - pu[2]};
    double al = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(al > 0))
        return;
    for (int k = 0; k < 3; k++)
        a[k] /= al;
    /* a basis (b1, b2) across the edge */
    double t[3] = {fabs(a[0]) < 0.9 ? 1 : 0, fabs(a[0]) < 0.9 ? 0 : 1, 0};
    double b1[3] = {a[1] * t[2] - a[2] * t[1], a[2] * t[0] - a[0] * t[2], a[0] * t[1] - a[1] * t[0]};
    double bl = sqrt(b1[0] * b1[0] + b1[1] * b1[1] + b1[2] * b1[2]);
    for (int k = 0; k < 3; k++)
        b1[k] /= bl;
    double b2[3] = {a[1] * b1[2] - a[2] * b1[1], a[2] * b1[0] - a[0] * b1[2], a[0] * b1[1] - a[1] * b1[0]};
    for (size_t i = 0; i < n; i++) {
        uint32_t h = hk[lo + i].val;
        const double *nf = &fn[3 * s->he_face[h]];
        /* into the face from the edge: n x direction of the half-edge */
        double sg = s->idx[h] == u ? 1 : -1;
        double w[3] = {sg * (nf[1] * a[2] - nf[2] * a[1]), sg * (nf[2] * a[0] - nf[0] * a[2]),
                       sg * (nf[0] * a[1] - nf[1] * a[0])};
        r[i].ang = atan2(w[0] * b2[0] + w[1] * b2[1] + w[2] * b2[2],
                         w[0] * b1[0] + w[1] * b1[1] + w[2] * b1[2]);
        r[i].he = h;
    }
    qsort(r, n, sizeof *r, cmp_radial);
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        if ((s->idx[r[i].he] == u) == (s->idx[r[j].he] == u))
            return; /* two faces in a row the same way: no consistent pairing */
    }
    /* turning from face i towards i + 1 (counter-clockwise about a) enters the inside
     * when it goes against face i's outward normal: then i and i + 1 are one solid's */
    const double *n0 = &fn[3 * s->he_face[r[0].he]];
    double sg0 = s->idx[r[0].he] == u ? 1 : -1;
    double w0[3] = {sg0 * (n0[1] * a[2] - n0[2] * a[1]), sg0 * (n0[2] * a[0] - n0[0] * a[2]),
                    sg0 * (n0[0] * a[1] - n0[1] * a[0])};
    double turn[3] = {a[1] * w0[2] - a[2] * w0[1], a[2] * w0[0] - a[0] * w0[2],
                      a[0] * w0[1] - a[1] * w0[0]};
    size_t off = turn[0] * n0[0] + turn[1] * n0[1] + turn[2] * n0[2] < 0 ? 0 : 1;
    for (size_t i = 0; i < n; i += 2) {
        uint32_t x = r[(i + off) % n].he, y = r[(i + off + 1) % n].he;
        s->he_twin[x] = y;
        s->he_twin[y] = x;
    }
}

/* Newell normal (not normalised) of a face from its k segments g[3 * ord[i]] (in any order:
 * the sum goes edge by edge), relative to its first segment's start. */
static void face_segments_normal(const ag_shell *s, const uint32_t *g, const uint32_t *ord,
                                 uint32_t k, double *n)
{
    n[0] = n[1] = n[2] = 0;
    if (!k)
        return;
    const double *o = &s->pos[3 * g[3 * ord[0] + 1]];
    for (uint32_t i = 0; i < k; i++) {
        const double *P = &s->pos[3 * g[3 * ord[i] + 1]], *Q = &s->pos[3 * g[3 * ord[i] + 2]];
        double p[3] = {P[0] - o[0], P[1] - o[1], P[2] - o[2]};
        double q[3] = {Q[0] - o[0], Q[1] - o[1], Q[2] - o[2]};
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
}

/* Of the unused segments leaving the end of segment cur (keys[lo..] with that from-vertex),
 * the one turning furthest left about the face normal n. */
static uint32_t sharpest_left(const ag_shell *s, const uint32_t *g, const seg_key *keys,
                              uint32_t lo, uint32_t k, const uint8_t *dead, uint32_t cur,
                              const double *n)
{
    const double *A = &s->pos[3 * g[3 * cur + 1]], *B = &s->pos[3 * g[3 * cur + 2]];
    double din[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
    uint32_t to = g[3 * cur + 2], best = NONE;
    double best_ang = -INFINITY;
    for (uint32_t j = lo; j < k && (keys[j].key >> 32) == to; j++) {
        uint32_t sg = keys[j].val;
        if (dead[sg])
            continue;
        const double *C = &s->pos[3 * g[3 * sg + 2]];
        double d[3] = {C[0] - B[0], C[1] - B[1], C[2] - B[2]};
        double c[3] = {din[1] * d[2] - din[2] * d[1], din[2] * d[0] - din[0] * d[2],
                       din[0] * d[1] - din[1] * d[0]};
        double ang = atan2(c[0] * n[0] + c[1] * n[1] + c[2] * n[2],
                           (din[0] * d[0] + din[1] * d[1] + din[2] * d[2]) *
                               sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
        if (ang > best_ang) {
            best_ang = ang;
            best = sg;
        }
    }
    return best;
}

ag_status ag_shell_finish(ag_shell *s, double weld_tol)
{
    uint32_t *map = malloc((s->nverts ? s->nverts : 1) * sizeof *map);
    if (!map)
        return AG_ERR_NOMEM;
    ag_status st = weld(s, weld_tol, map);
    if (st != AG_OK) {
        free(map);
        return st;
    }
    for (size_t i = 0; i < s->nsegs; i++) {
        s->segs[3 * i + 1] = map[s->segs[3 * i + 1]];
        s->segs[3 * i + 2] = map[s->segs[3 * i + 2]];
    }
    free(map);
    /* terrace and soffit faces at one height: the difference of the plans (flats.h) */
    st = ag_flats_rebuild(s, weld_tol);
    if (st != AG_OK)
        return st;
    size_t ns = s->nsegs;
    uint32_t *g = s->segs;
    /* sort segments by face, then cancel zero-length and in-face opposite pairs */
    uint32_t *ord = malloc((ns ? ns : 1) * sizeof *ord);
    uint8_t *dead = calloc(ns ? ns : 1, 1);
    seg_key *keys = malloc((ns ? ns : 1) * sizeof *keys);
    seg_key *sorttmp = malloc((ns ? ns : 1) * sizeof *sorttmp);
    uint32_t *fstart = calloc(s->nfaces + 1, sizeof *fstart);
    if (!ord || !dead || !keys || !sorttmp || !fstart) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (size_t i = 0; i < ns; i++)
        fstart[g[3 * i] + 1]++;
    for (size_t f = 0; f < s->nfaces; f++)
        fstart[f + 1] += fstart[f];
    {
        uint32_t *fill = malloc((s->nfaces + 1) * sizeof *fill);
        if (!fill) {
            st = AG_ERR_NOMEM;
            goto out;
        }
        memcpy(fill, fstart, (s->nfaces + 1) * sizeof *fill);
        for (size_t i = 0; i < ns; i++)
            ord[fill[g[3 * i]]++] = (uint32_t)i;
        free(fill);
    }
    for (size_t i = 0; i < ns; i++)
        if (g[3 * i + 1] == g[3 * i + 2])
            dead[i] = 1;
    free(s->loop_start);
    free(s->idx);
    s->loop_start = malloc((ns + s->nfaces + 1) * sizeof(uint32_t));
    s->idx = malloc((ns ? ns : 1) * sizeof(uint32_t));
    if (!s->loop_start || !s->idx) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    s->nloops = 0;
    s->open_segments = 0;
    size_t nidx = 0;
    for (size_t f = 0; f < s->nfaces; f++) {
        uint32_t a = fstart[f], b = fstart[f + 1], k = b - a;
        for (uint32_t i = 0; i < k; i++) {
            uint32_t sg = ord[a + i];
            keys[i].key = (uint64_t)g[3 * sg + 1] << 32 | g[3 * sg + 2];
            keys[i].val = sg;
        }
        ag_keysort(keys, k, sorttmp);
        /* cancel u->v against v->u within the face (zero-width slits) */
        for (uint32_t i = 0; i < k; i++) {
            uint32_t sg = keys[i].val;
            if (dead[sg])
                continue;
            uint64_t rev = (uint64_t)g[3 * sg + 2] << 32 | g[3 * sg + 1];
            uint32_t lo = (uint32_t)ag_search_lower_u64(&keys->key, k, sizeof *keys, rev);
            for (uint32_t j = lo; j < k && keys[j].key == rev; j++)
                if (!dead[keys[j].val]) {
                    dead[keys[j].val] = 1;
                    dead[sg] = 1;
                    break;
                }
        }
        /* link: keys sorted by from-vertex; walk from each unused segment */
        double fn1[3];
        int have_n = 0;
        s->faces[f].first_loop = (uint32_t)s->nloops;
        for (uint32_t i = 0; i < k; i++) {
            uint32_t sg = keys[i].val;
            if (dead[sg])
                continue;
            uint32_t start = g[3 * sg + 1], cur = sg;
            size_t begin = nidx;
            int closed = 0;
            for (;;) {
                dead[cur] = 1;
                s->idx[nidx++] = g[3 * cur + 1];
                uint32_t to = g[3 * cur + 2];
                if (to == start) {
                    closed = 1;
                    break;
                }
                uint64_t want = (uint64_t)to << 32;
                uint32_t lo = (uint32_t)ag_search_lower_u64(&keys->key, k, sizeof *keys, want);
                uint32_t next = NONE, nfound = 0;
                for (uint32_t j = lo; j < k && (keys[j].key >> 32) == to; j++)
                    if (!dead[keys[j].val]) {
                        if (!nfound++)
                            next = keys[j].val;
                        else
                            break;
                    }
                if (nfound > 1) {
                    /* the face touches itself at this corner: the sharpest left turn keeps
                     * the loops apart (one figure-eight loop triangulates across itself) */
                    if (!have_n) {
                        face_segments_normal(s, g, ord + a, k, fn1);
                        have_n = 1;
                    }
                    next = sharpest_left(s, g, keys, lo, k, dead, cur, fn1);
                }
                if (next == NONE)
                    break;
                cur = next;
            }
            if (closed && nidx - begin >= 3) {
                s->loop_start[s->nloops++] = (uint32_t)begin;
            } else {
                s->open_segments += nidx - begin;
                nidx = begin;
                s->faces[f].nloops |= 0x80000000u; /* mark: open boundary */
            }
        }
        uint32_t open = s->faces[f].nloops & 0x80000000u;
        s->faces[f].nloops = (uint32_t)(s->nloops - s->faces[f].first_loop) | open;
    }
    s->loop_start[s->nloops] = (uint32_t)nidx;
    /* half-edges */
    s->nhalf = nidx;
    free(s->he_twin);
    free(s->he_next);
    free(s->he_face);
    s->he_twin = malloc((nidx ? nidx : 1) * sizeof(uint32_t));
    s->he_next = malloc((nidx ? nidx : 1) * sizeof(uint32_t));
    s->he_face = malloc((nidx ? nidx : 1) * sizeof(uint32_t));
    seg_key *hk = malloc((nidx ? nidx : 1) * sizeof *hk);
    if (!s->he_twin || !s->he_next || !s->he_face || !hk) {
        free(hk);
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (size_t f = 0; f < s->nfaces; f++) {
        uint32_t nl = s->faces[f].nloops & 0x7fffffffu;
        for (uint32_t l = s->faces[f].first_loop; l < s->faces[f].first_loop + nl; l++) {
            uint32_t a = s->loop_start[l], b = s->loop_start[l + 1];
            for (uint32_t i = a; i < b; i++) {
                s->he_next[i] = i + 1 < b ? i + 1 : a;
                s->he_face[i] = (uint32_t)f;
                s->he_twin[i] = NONE;
            }
        }
    }
    for (size_t i = 0; i < nidx; i++) {
        hk[i].key = (uint64_t)s->idx[i] << 32 | s->idx[s->he_next[i]];
        hk[i].val = (uint32_t)i;
    }
    st = ag_keysort(hk, nidx, NULL);
    if (st != AG_OK) {
        free(hk);
        goto out;
    }
    for (size_t i = 0; i < nidx; i++) {
        uint32_t h = (uint32_t)i;
        uint64_t rev = (uint64_t)s->idx[s->he_next[h]] << 32 | s->idx[h];
        size_t lo = ag_search_lower_u64(&hk->key, nidx, sizeof *hk, rev);
        /* exactly one opposite half-edge: twin; more than one: paired around the edge below */
        if (lo < nidx && hk[lo].key == rev && (lo + 1 >= nidx || hk[lo + 1].key != rev))
            s->he_twin[h] = hk[lo].val;
    }
    /* edges used k > 1 times each way */
    double *fn = NULL;
    for (size_t i = 0; i < nidx;) {
        size_t j = i;
        while (j < nidx && hk[j].key == hk[i].key)
            j++;
        uint64_t key = hk[i].key, rev = (key << 32) | (key >> 32);
        if (j - i > 1 && key < rev) {
            size_t lo = ag_search_lower_u64(&hk->key, nidx, sizeof *hk, rev);
            size_t m = lo;
            while (m < nidx && hk[m].key == rev)
                m++;
            if (m - lo == j - i) {
                if (!fn) {
                    fn = malloc((s->nfaces ? s->nfaces : 1) * 3 * sizeof *fn);
                    if (!fn) {
                        free(hk);
                        st = AG_ERR_NOMEM;
                        goto out;
                    }
                    for (size_t f = 0; f < s->nfaces; f++)
                        face_normal(s, f, &fn[3 * f]);
                }
                /* both directions' half-edges, contiguous in a scratch copy */
                seg_key both[64];
                size_t nb = 0;
                for (size_t q = i; q < j && nb < 64; q++)
                    both[nb++] = hk[q];
                for (size_t q = lo; q < m && nb < 64; q++)
                    both[nb++] = hk[q];
                if (nb == 2 * (j - i))
                    pair_radial(s, both, 0, nb, fn);
            }
        }
        i = j;
    }
    free(fn);
    free(hk);
out:
    free(ord);
    free(dead);
    free(keys);
    free(sorttmp);
    free(fstart);
    return st;
}

size_t ag_shell_check(const ag_shell *s, ag_shell_problem *out, size_t max)
{
    size_t nbad = 0;
    /* duplicate directed edges */
    seg_key *hk = malloc((s->nhalf ? s->nhalf : 1) * sizeof *hk);
    uint8_t *dup = calloc(s->nhalf ? s->nhalf : 1, 1);
    if (hk && dup) {
        for (size_t i = 0; i < s->nhalf; i++) {
            hk[i].key = (uint64_t)s->idx[i] << 32 | s->idx[s->he_next[i]];
            hk[i].val = (uint32_t)i;
        }
        if (ag_keysort(hk, s->nhalf, NULL) == AG_OK)
            for (size_t i = 1; i < s->nhalf; i++)
                if (hk[i].key == hk[i - 1].key)
                    dup[hk[i].val] = dup[hk[i - 1].val] = 1;
    }
    for (size_t f = 0; f < s->nfaces; f++) {
        const ag_shell_face *fc = &s->faces[f];
        char why[112] = "";
        if (fc->nloops & 0x80000000u)
            snprintf(why, sizeof why, "face boundary does not close into a loop");
        uint32_t nl = fc->nloops & 0x7fffffffu;
        for (uint32_t l = fc->first_loop; l < fc->first_loop + nl && !why[0]; l++)
            for (uint32_t h = s->loop_start[l]; h < s->loop_start[l + 1]; h++) {
                uint32_t u = s->idx[h], v = s->idx[s->he_next[h]];
                if (dup && dup[h] && s->he_twin[h] == NONE) {
                    snprintf(why, sizeof why,
                             "edge %u-%u is used twice in the same direction (not 2-manifold)",
                             u, v);
                    break;
                }
                if (s->he_twin[h] == NONE) {
                    snprintf(why, sizeof why,
                             "edge %u-%u has no opposite edge (the shell is open there)", u, v);
                    break;
                }
            }
        if (!why[0] && nl) {
            /* planarity: every corner within a fraction of the face's diameter of its
             * Newell plane (relative to its first corner: shells lie at real coordinates) */
            double n[3];
            face_normal(s, f, n);
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            const double *o = &s->pos[3 * s->idx[s->loop_start[fc->first_loop]]];
            double c[3] = {0, 0, 0}, cnt = 0, lo = INFINITY, hi = -INFINITY, size = 0, mag = 0;
            for (uint32_t l = fc->first_loop; l < fc->first_loop + nl; l++)
                for (uint32_t i = s->loop_start[l]; i < s->loop_start[l + 1]; i++) {
                    const double *p = &s->pos[3 * s->idx[i]];
                    for (int k = 0; k < 3; k++) {
                        c[k] += p[k] - o[k];
                        mag = fmax(mag, fabs(p[k]));
                    }
                    cnt++;
                }
            if (len > 0) {
                for (int k = 0; k < 3; k++)
                    c[k] /= cnt;
                for (uint32_t l = fc->first_loop; l < fc->first_loop + nl; l++)
                    for (uint32_t i = s->loop_start[l]; i < s->loop_start[l + 1]; i++) {
                        const double *p = &s->pos[3 * s->idx[i]];
                        double q[3] = {p[0] - o[0] - c[0], p[1] - o[1] - c[1], p[2] - o[2] - c[2]};
                        double d = (q[0] * n[0] + q[1] * n[1] + q[2] * n[2]) / len;
                        lo = fmin(lo, d);
                        hi = fmax(hi, d);
                        size = fmax(size, sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]));
                    }
                double allowed = AG_EXTRUDE_PLANAR_REL * 2 * size + AG_EXTRUDE_PLANAR_ABS +
                                 AG_EXTRUDE_COORD_ULPS * DBL_EPSILON * mag;
                if (hi - lo > allowed)
                    snprintf(why, sizeof why, "face is not planar (corners %.3g m off its plane, "
                             "%.3g m allowed for its size)", hi - lo, allowed);
            }
        }
        if (why[0]) {
            if (nbad < max) {
                out[nbad].face = (int32_t)f;
                memcpy(out[nbad].reason, why, sizeof why);
            }
            nbad++;
        }
    }
    free(hk);
    free(dup);
    return nbad;
}

double ag_shell_volume(const ag_shell *s)
{
    /* divergence theorem over fan triangles of every loop, relative to the first vertex
     * (a closed shell's volume does not depend on the origin; its precision does) */
    if (!s->nloops)
        return 0;
    const double *o = &s->pos[3 * s->idx[0]];
    long double v = 0;
    for (size_t l = 0; l < s->nloops; l++) {
        uint32_t a = s->loop_start[l], b = s->loop_start[l + 1];
        const double *P0 = &s->pos[3 * s->idx[a]];
        long double p0[3] = {(long double)P0[0] - o[0], (long double)P0[1] - o[1],
                             (long double)P0[2] - o[2]};
        for (uint32_t i = a + 1; i + 1 < b; i++) {
            const double *P1 = &s->pos[3 * s->idx[i]], *P2 = &s->pos[3 * s->idx[i + 1]];
            long double p1[3] = {(long double)P1[0] - o[0], (long double)P1[1] - o[1],
                                 (long double)P1[2] - o[2]};
            long double p2[3] = {(long double)P2[0] - o[0], (long double)P2[1] - o[1],
                                 (long double)P2[2] - o[2]};
            v += p0[0] * (p1[1] * p2[2] - p1[2] * p2[1]) - p0[1] * (p1[0] * p2[2] - p1[2] * p2[0]) +
                 p0[2] * (p1[0] * p2[1] - p1[1] * p2[0]);
        }
    }
    return (double)(v / 6);
}

/* --- triangulation ---------------------------------------------------------------------- */

typedef struct {
    double x, y;
    uint32_t v; /* shell vertex */
} tri_pt;

static double cross3(const tri_pt *a, const tri_pt *b, const tri_pt *c)
{
    return (b->x - a->x) * (c->y - a->y) - (b->y - a->y) * (c->x - a->x);
}

static double loop_area(const tri_pt *p, size_t n)
{
    double a = 0;
    for (size_t i = 0, j = n - 1; i < n; j = i++)
        a += p[j].x * p[i].y - p[i].x * p[j].y;
    return a / 2;
}

static int seg_cross(const tri_pt *a, const tri_pt *b, const tri_pt *c, const tri_pt *d)
{
    double p1[2] = {a->x, a->y}, p2[2] = {b->x, b->y}, p3[2] = {c->x, c->y}, p4[2] = {d->x, d->y};
    return ag_pred_segments_touch(p1, p2, p3, p4);
}

/* Ear clipping of one simple polygon (CCW) into m. Falls back to clipping the most convex corner when no clean ear is found,
 * so it always terminates. */
static ag_status ear_clip(tri_pt *p, size_t n, ag_mesh *m, uint32_t base, uint32_t comp,
                          size_t *ntris)
{
    if (n < 3)
        return AG_OK;
    uint32_t *prev = malloc(n * sizeof *prev), *next = malloc(n * sizeof *next);
    if (!prev || !next) {
        free(prev);
        free(next);
        return AG_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) {
        prev[i] = (uint32_t)(i ? i - 1 : n - 1);
        next[i] = (uint32_t)(i + 1 < n ? i + 1 : 0);
    }
    double ext = 0;
    for (size_t i = 0; i < n; i++)
        ext = fmax(ext, fmax(fabs(p[i].x - p[0].x), fabs(p[i].y - p[0].y)));
    double eps = AG_EXTRUDE_EAR_FLAT * ext * ext;
    size_t left = n;
    uint32_t cur = 0;
    size_t misses = 0;
    ag_status st = AG_OK;
    while (left > 3) {
        uint32_t a = prev[cur], b = cur, c = next[cur];
        double cr = cross3(&p[a], &p[b], &p[c]);
        int ear = cr > eps;
        if (ear) {
            for (uint32_t k = next[c]; k != a; k = next[k]) {
                if (p[k].v == p[a].v || p[k].v == p[b].v || p[k].v == p[c].v)
                    continue;
                /* only reflex or flat corners can lie inside an ear */
                if (cross3(&p[prev[k]], &p[k], &p[next[k]]) > eps)
                    continue;
                if (cross3(&p[a], &p[b], &p[k]) >= -eps && cross3(&p[b], &p[c], &p[k]) >= -eps &&
                    cross3(&p[c], &p[a], &p[k]) >= -eps) {
                    ear = 0;
                    break;
                }
            }
        }
        if (!ear && misses > left) {
            /* no clean ear: take the most convex corner to guarantee progress */
            uint32_t best = cur;
            double bc = -INFINITY;
            uint32_t k = cur;
            for (size_t i = 0; i < left; i++, k = next[k]) {
                double v = cross3(&p[prev[k]], &p[k], &p[next[k]]);
                if (v > bc) {
                    bc = v;
                    best = k;
                }
            }
            cur = best;
            a = prev[cur];
            b = cur;
            c = next[cur];
            ear = 1;
        }
        if (ear) {
            st = ag_mesh_add_triangle(m, base + p[a].v, base + p[b].v, base + p[c].v, comp);
            if (st != AG_OK)
                break;
            (*ntris)++;
            next[a] = c;
            prev[c] = a;
            left--;
            cur = c;
            misses = 0;
        } else {
            cur = next[cur];
            misses++;
        }
    }
    if (st == AG_OK && left == 3) {
        uint32_t a = prev[cur], b = cur, c = next[cur];
        st = ag_mesh_add_triangle(m, base + p[a].v, base + p[b].v, base + p[c].v, comp);
        if (st == AG_OK)
            (*ntris)++;
    }
    free(prev);
    free(next);
    return st;
}

/* Appends hole h into polygon *poly (size *n) through a bridge to a visible corner. */
static ag_status bridge_hole(tri_pt **poly, size_t *n, const tri_pt *h, size_t hn,
                             const size_t *all_n, size_t nall_loops, const tri_pt *const *loops)
{
    size_t mi = 0;
    for (size_t i = 1; i < hn; i++)
        if (h[i].x > h[mi].x)
            mi = i;
    const tri_pt *M = &h[mi];
    tri_pt *P = *poly;
    /* candidates by distance; first whose bridge crosses nothing */
    size_t best = SIZE_MAX;
    double bestd = INFINITY;
    for (int pass = 0; pass < 2 && best == SIZE_MAX; pass++) {
        for (size_t i = 0; i < *n; i++) {
            double d = (P[i].x - M->x) * (P[i].x - M->x) + (P[i].y - M->y) * (P[i].y - M->y);
            if (d >= bestd)
                continue;
            if (pass == 0) {
                int ok = 1;
                for (size_t j = 0; j < *n && ok; j++) {
                    size_t j2 = (j + 1) % *n;
                    if (P[j].v == P[i].v || P[j2].v == P[i].v)
                        continue;
                    if (seg_cross(M, &P[i], &P[j], &P[j2]))
                        ok = 0;
                }
                for (size_t L = 0; L < nall_loops && ok; L++)
                    for (size_t j = 0; j < all_n[L] && ok; j++) {
                        const tri_pt *q = loops[L];
                        size_t j2 = (j + 1) % all_n[L];
                        if (q[j].v == M->v || q[j2].v == M->v || q[j].v == P[i].v ||
                            q[j2].v == P[i].v)
                            continue;
                        if (seg_cross(M, &P[i], &q[j], &q[j2]))
                            ok = 0;
                    }
                if (!ok)
                    continue;
            }
            bestd = d;
            best = i;
        }
    }
    tri_pt *np = malloc((*n + hn + 2) * sizeof *np);
    if (!np)
        return AG_ERR_NOMEM;
    size_t k = 0;
    for (size_t i = 0; i <= best; i++)
        np[k++] = P[i];
    for (size_t i = 0; i <= hn; i++)
        np[k++] = h[(mi + i) % hn];
    for (size_t i = best; i < *n; i++)
        np[k++] = P[i];
    free(P);
    *poly = np;
    *n = k;
    return AG_OK;
}

/* A hole that shares a corner with the polygon (touching it at a point, as OGC allows) is
 * spliced in at that corner: the polygon runs around the hole and back to the shared
 * corner, a zero-length bridge. Returns 1 when spliced, 0 when they share no corner. */
static int splice_hole(tri_pt **poly, size_t *n, const tri_pt *h, size_t hn, ag_status *st)
{
    tri_pt *P = *poly;
    for (size_t i = 0; i < *n; i++)
        for (size_t k = 0; k < hn; k++) {
            if (P[i].v != h[k].v)
                continue;
            tri_pt *np = malloc((*n + hn) * sizeof *np);
            if (!np) {
                *st = AG_ERR_NOMEM;
                return 1;
            }
            size_t m = 0;
            for (size_t a = 0; a <= i; a++)
                np[m++] = P[a];
            for (size_t b = 1; b < hn; b++)
                np[m++] = h[(k + b) % hn];
            for (size_t a = i; a < *n; a++)
                np[m++] = P[a];
            free(P);
            *poly = np;
            *n = m;
            return 1;
        }
    return 0;
}

static int cmp_hole_x(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x > y ? -1 : x < y;
}

static ag_status triangulate_face(const ag_shell *s, size_t f, ag_mesh *m, uint32_t base,
                                  uint32_t comp, size_t *ntris)
{
    const ag_shell_face *fc = &s->faces[f];
    uint32_t nl = fc->nloops & 0x7fffffffu;
    if (!nl)
        return AG_OK;
    /* Newell normal over all loops; the projection relative to the face's first corner */
    double nn[3];
    face_normal(s, f, nn);
    double nx = nn[0], ny = nn[1], nz = nn[2];
    const double *org = &s->pos[3 * s->idx[s->loop_start[fc->first_loop]]];
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    if (!(len > AG_EXTRUDE_NO_AREA))
        return AG_OK; /* no area */
    nx /= len;
    ny /= len;
    nz /= len;
    double ux, uy, uz;
    if (fabs(nx) < 0.9) {
        ux = 0;
        uy = -nz;
        uz = ny; /* n x (1,0,0) */
    } else {
        ux = nz;
        uy = 0;
        uz = -nx; /* n x (0,1,0) */
    }
    double ul = sqrt(ux * ux + uy * uy + uz * uz);
    ux /= ul;
    uy /= ul;
    uz /= ul;
    double vx = ny * uz - nz * uy, vy = nz * ux - nx * uz, vz = nx * uy - ny * ux;
    tri_pt **loops = calloc(nl, sizeof *loops);
    size_t *ln = calloc(nl, sizeof *ln);
    double *areas = calloc(nl, sizeof *areas);
    ag_status st = AG_OK;
    if (!loops || !ln || !areas) {
        st = AG_ERR_NOMEM;
        goto out;
    }
    for (uint32_t i = 0; i < nl; i++) {
        uint32_t l = fc->first_loop + i, a = s->loop_start[l], b = s->loop_start[l + 1];
        ln[i] = b - a;
        loops[i] = malloc(ln[i] * sizeof(tri_pt));
        if (!loops[i]) {
            st = AG_ERR_NOMEM;
            goto out;
        }
        for (uint32_t k = a; k < b; k++) {
            const double *p = &s->pos[3 * s->idx[k]];
            /* u, v basis with u x v = n: loops CCW about n have positive area */
            double q[3] = {p[0] - org[0], p[1] - org[1], p[2] - org[2]};
            loops[i][k - a].x = q[0] * ux + q[1] * uy + q[2] * uz;
            loops[i][k - a].y = q[0] * vx + q[1] * vy + q[2] * vz;
            loops[i][k - a].v = s->idx[k];
        }
        areas[i] = loop_area(loops[i], ln[i]);
    }
    for (uint32_t i = 0; i < nl; i++) {
        if (areas[i] <= 0)
            continue;
        size_t n = ln[i];
        tri_pt *poly = malloc(n * sizeof *poly);
        if (!poly) {
            st = AG_ERR_NOMEM;
            goto out;
        }
        memcpy(poly, loops[i], n * sizeof *poly);
        /* holes inside this outer loop, right-most first */
        double *hx = malloc(2 * nl * sizeof(double));
        size_t nh = 0;
        if (!hx) {
            free(poly);
            st = AG_ERR_NOMEM;
            goto out;
        }
        double *oxy = malloc(2 * n * sizeof(double));
        if (!oxy) {
            free(hx);
            free(poly);
            st = AG_ERR_NOMEM;
            goto out;
        }
        for (size_t k = 0; k < n; k++) {
            oxy[2 * k] = loops[i][k].x;
            oxy[2 * k + 1] = loops[i][k].y;
        }
        for (uint32_t j = 0; j < nl; j++) {
            if (areas[j] >= 0)
                continue;
            /* test a hole corner that is not on the outer loop */
            int inside = 0;
            for (size_t k = 0; k < ln[j]; k++) {
                inside = ag_pred_point_in_polygon(oxy, n, loops[j][k].x, loops[j][k].y);
                if (inside)
                    break;
            }
            if (!inside)
                continue;
            double mx = -INFINITY;
            for (size_t k = 0; k < ln[j]; k++)
                mx = fmax(mx, loops[j][k].x);
            hx[2 * nh] = mx;
            hx[2 * nh + 1] = j;
            nh++;
        }
        free(oxy);
        qsort(hx, nh, 2 * sizeof(double), cmp_hole_x);
        for (size_t h = 0; h < nh && st == AG_OK; h++) {
            uint32_t j = (uint32_t)hx[2 * h + 1];
            if (!splice_hole(&poly, &n, loops[j], ln[j], &st))
                st = bridge_hole(&poly, &n, loops[j], ln[j], ln, nl, (const tri_pt *const *)loops);
        }
        free(hx);
        if (st == AG_OK)
            st = ear_clip(poly, n, m, base, comp, ntris);
        free(poly);
        if (st != AG_OK)
            goto out;
    }
out:
    if (loops)
        for (uint32_t i = 0; i < nl; i++)
            free(loops[i]);
    free(loops);
    free(ln);
    free(areas);
    return st;
}

ag_status ag_shell_to_mesh(const ag_shell *s, ag_mesh *m, uint32_t component, size_t *ntris)
{
    size_t count = 0;
    uint32_t base = (uint32_t)m->nverts;
    for (size_t i = 0; i < s->nverts; i++) {
        ag_status st = ag_mesh_add_vertex(m, s->pos[3 * i], s->pos[3 * i + 1], s->pos[3 * i + 2]);
        if (st != AG_OK)
            return st;
    }
    for (size_t f = 0; f < s->nfaces; f++) {
        ag_status st = triangulate_face(s, f, m, base, component, &count);
        if (st != AG_OK)
            return st;
    }
    if (ntris)
        *ntris = count;
    return AG_OK;
}
