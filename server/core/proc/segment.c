#include "segment.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/radix.h"
#include "../base/tolerance.h"
#include "../base/uf.h"
#include "weld.h"

ag_status ag_segment_validate(const ag_mesh *m, ag_error *err)
{
    if (!m || m->ntris == 0)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the mesh has no triangles");
    for (size_t v = 0; v < m->nverts; v++)
        for (int a = 0; a < 3; a++)
            if (!isfinite(m->pos[3 * v + a]))
                return ag_error_set(err, AG_ERR_INVALID, (long)v + 1,
                                    "vertex %zu has a non-finite coordinate", v + 1);
    for (size_t t = 0; t < m->ntris; t++) {
        for (int k = 0; k < 3; k++)
            if (m->tri[3 * t + k] >= m->nverts)
                return ag_error_set(err, AG_ERR_INVALID, (long)t + 1,
                                    "triangle %zu uses vertex %u of %zu", t + 1,
                                    m->tri[3 * t + k] + 1, m->nverts);
        if (m->tri_component[t] >= m->ncomponents)
            return ag_error_set(err, AG_ERR_INVALID, (long)t + 1,
                                "triangle %zu names component %u of %zu", t + 1,
                                m->tri_component[t], m->ncomponents);
    }
    for (size_t c = 0; c < m->ncomponents; c++)
        if (m->component_group[c] >= (int32_t)m->ngroups)
            return ag_error_set(err, AG_ERR_INVALID, (long)c + 1,
                                "component %zu names group %d of %zu", c + 1,
                                m->component_group[c], m->ngroups);
    return AG_OK;
}

/* Records sorted by key with ag_radix_sort; val is a triangle, and the records are filled
 * in ascending triangle order, so equal keys stay in triangle order. */
typedef ag_radix_item keyed;

static void tri_normal(const ag_mesh *m, size_t t, double n[3], double *area2)
{
    const double *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                 *c = m->pos + 3 * m->tri[3 * t + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    *area2 = l;
    if (l > 0)
        for (int k = 0; k < 3; k++)
            n[k] /= l;
}

/* Planar region growing over edge-adjacent triangles: piece[t] = region index. */
static ag_status planar_regions(const ag_mesh *m, const uint32_t *wid, double cosmax,
                                double plane_tol, uint32_t *piece, size_t *nregions)
{
    size_t n = m->ntris;
    keyed *e = malloc(3 * n * sizeof *e);
    uint32_t *queue = malloc(n * sizeof *queue);
    if (!e || !queue) {
        free(e);
        free(queue);
        return AG_ERR_NOMEM;
    }
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = wid[m->tri[3 * t + k]], b = wid[m->tri[3 * t + (k + 1) % 3]];
            if (a > b) {
                uint64_t s = a;
                a = b;
                b = s;
            }
            e[3 * t + k].key = a << 32 | b;
            e[3 * t + k].val = (uint32_t)t;
        }
    if (ag_radix_sort(e, 3 * n)) {
        free(e);
        free(queue);
        return AG_ERR_NOMEM;
    }
    /* per triangle, positions of its three edges in the sorted array */
    uint32_t *at = malloc(3 * n * sizeof *at);
    uint8_t *seen = calloc(3 * n, 1);
    if (!at || !seen) {
        free(e);
        free(queue);
        free(at);
        free(seen);
        return AG_ERR_NOMEM;
    }
    for (size_t i = 0; i < 3 * n; i++) {
        uint32_t t = e[i].val;
        int k = 0;
        while (seen[3 * t + k])
            k++;
        seen[3 * t + k] = 1;
        at[3 * t + k] = (uint32_t)i;
    }
    for (size_t t = 0; t < n; t++)
        piece[t] = UINT32_MAX;
    size_t r = 0;
    for (size_t s = 0; s < n; s++) {
        if (piece[s] != UINT32_MAX)
            continue;
        double ns[3], a2;
        tri_normal(m, s, ns, &a2);
        int flat = a2 > 0;
        const double *ps = m->pos + 3 * m->tri[3 * s];
        size_t qh = 0, qt = 0;
        queue[qt++] = (uint32_t)s;
        piece[s] = (uint32_t)r;
        while (qh < qt) {
            uint32_t t = queue[qh++];
            for (int k = 0; k < 3; k++) {
                size_t i = at[3 * t + k];
                size_t lo = i, hi = i;
                while (lo > 0 && e[lo - 1].key == e[i].key)
                    lo--;
                while (hi + 1 < 3 * n && e[hi + 1].key == e[i].key)
                    hi++;
                for (size_t j = lo; j <= hi; j++) {
                    uint32_t u = e[j].val;
                    if (piece[u] != UINT32_MAX)
                        continue;
                    double nu[3], au;
                    tri_normal(m, u, nu, &au);
                    if (flat && au > 0) {
                        if (nu[0] * ns[0] + nu[1] * ns[1] + nu[2] * ns[2] < cosmax)
                            continue;
                        int off = 0;
                        for (int c = 0; c < 3 && !off; c++) {
                            const double *p = m->pos + 3 * m->tri[3 * u + c];
                            double d = (p[0] - ps[0]) * ns[0] + (p[1] - ps[1]) * ns[1] +
                                       (p[2] - ps[2]) * ns[2];
                            off = fabs(d) > plane_tol;
                        }
                        if (off)
                            continue;
                    }
                    piece[u] = (uint32_t)r;
                    queue[qt++] = u;
                }
            }
        }
        r++;
    }
    free(e);
    free(queue);
    free(at);
    free(seen);
    *nregions = r;
    return AG_OK;
}

ag_status ag_segment_run(const ag_mesh *in, const ag_segment_options *opt, ag_mesh **out,
                         ag_segment_info *info, ag_error *err)
{
    ag_segment_options o = opt ? *opt : (ag_segment_options){0};
    if (o.weld <= 0)
        o.weld = AG_PROC_WELD;
    if (o.planar_degrees <= 0)
        o.planar_degrees = AG_PROC_PLANAR_DEGREES;
    if (o.split_min_pieces == 0)
        o.split_min_pieces = AG_PROC_SPLIT_MIN_PIECES;
    ag_segment_info inf = {0};
    *out = NULL;
    ag_status st = ag_segment_validate(in, err);
    if (st)
        return st;
    if (in->ntris >= UINT32_MAX / 4)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "too many triangles");

    size_t n = in->ntris, nc = in->ncomponents;
    ag_box bb = ag_mesh_bounds(in);
    double diag = ag_box_diagonal(&bb);
    double cell = o.weld * (diag > 0 ? diag : 1.0);

    uint32_t *wid = malloc((in->nverts + 1) * sizeof *wid);
    ag_uf uf = {0};
    uint32_t *newc = NULL; /* per triangle: its new component */
    uint32_t *piece = malloc(n * sizeof *piece);
    keyed *kv = malloc(n * sizeof *kv); /* twin keys, one per piece */
    size_t *ctris = calloc(nc + 1, sizeof *ctris);
    uint8_t *split = calloc(nc + 1, 1);
    ag_mesh *m = ag_mesh_create();
    size_t nw = 0;
    st = AG_ERR_NOMEM;
    if (ag_uf_init(&uf, n, 0) || !wid || !piece || !kv || !ctris || !split || !m)
        goto done;
    if ((st = ag__weld(in->pos, in->nverts, cell, wid, &nw)))
        goto done;
    st = AG_ERR_NOMEM; /* what every failure up to the new mesh is */

    /* connected pieces inside each component: its triangles that share a welded vertex. A
     * welded vertex keeps the first component and triangle on it; the corners of other
     * components on it (a vertex two components share, rare) are sorted by (component,
     * vertex) instead, so the pieces cost O(n) and a sort of those corners only */
    {
        uint32_t *owner = malloc((nw + 1) * sizeof *owner), *first = malloc((nw + 1) * sizeof *first);
        keyed *shared = NULL;
        size_t nshared = 0, cap_shared = 0;
        if (!owner || !first) {
            free(owner);
            free(first);
            goto done;
        }
        for (size_t w = 0; w < nw; w++)
            owner[w] = UINT32_MAX;
        int fail = 0;
        for (size_t t = 0; t < n && !fail; t++) {
            uint32_t c = in->tri_component[t];
            for (int k = 0; k < 3; k++) {
                uint32_t w = wid[in->tri[3 * t + k]];
                if (owner[w] == UINT32_MAX) {
                    owner[w] = c;
                    first[w] = (uint32_t)t;
                } else if (owner[w] == c) {
                    ag_uf_union(&uf, (uint32_t)t, first[w]);
                } else if (AG_ARRAY_RESERVE(shared, cap_shared, nshared + 1)) {
                    fail = 1;
                    break;
                } else {
                    shared[nshared].key = (uint64_t)c << 32 | w;
                    shared[nshared++].val = (uint32_t)t;
                }
            }
        }
        free(owner);
        free(first);
        if (fail || ag_radix_sort(shared, nshared)) {
            free(shared);
            goto done;
        }
        for (size_t i = 1; i < nshared; i++)
            if (shared[i].key == shared[i - 1].key)
                ag_uf_union(&uf, shared[i].val, shared[i - 1].val);
        free(shared);
    }
    for (size_t t = 0; t < n; t++)
        piece[t] = ag_uf_find(&uf, (uint32_t)t); /* root: a triangle of the piece */
    ag_uf_free(&uf);
    if (!(newc = malloc((n + 1) * sizeof *newc)))
        goto done;

    /* per piece: triangle count and box, to find twins */
    size_t ngroups_used = 0;
    {
        uint8_t *gused = calloc(in->ngroups + 1, 1);
        if (!gused)
            goto done;
        for (size_t t = 0; t < n; t++) {
            int32_t g = in->component_group[in->tri_component[t]];
            if (g >= 0 && !gused[g]) {
                gused[g] = 1;
                ngroups_used++;
            }
            ctris[in->tri_component[t]]++;
        }
        free(gused);
    }
    {
        /* roots are triangles: per root its dense piece index, per piece its stats */
        uint32_t *pidx = malloc((n + 1) * sizeof *pidx);
        size_t np = 0;
        for (size_t t = 0; pidx && t < n; t++)
            if (piece[t] == t)
                pidx[t] = (uint32_t)np++;
        uint32_t *pcount = calloc(np + 1, sizeof *pcount);
        ag_box *pbox = malloc((np + 1) * sizeof *pbox);
        size_t *npieces = calloc(nc, sizeof *npieces);
        if (!pidx || !pcount || !pbox || !npieces) {
            free(pidx);
            free(pcount);
            free(pbox);
            free(npieces);
            goto done;
        }
        for (size_t t = 0; t < n; t++) {
            uint32_t r = pidx[piece[t]];
            if (pcount[r]++ == 0) {
                npieces[in->tri_component[t]]++;
                pbox[r] = ag_box_empty();
            }
            for (int k = 0; k < 3; k++)
                ag_box_extend_point(&pbox[r], in->pos + 3 * in->tri[3 * t + k]);
        }
        /* twin keys: component, triangle count, quantized box size */
        size_t nk = 0;
        double q = AG_PROC_TWIN_STEP * (diag > 0 ? diag : 1.0);
        for (size_t t = 0; t < n; t++)
            if (piece[t] == t) {
                uint32_t r = pidx[t];
                uint64_t h = ag__mix64(in->tri_component[t] * 31ULL + pcount[r]);
                for (int a = 0; a < 3; a++)
                    h = ag__mix64(h ^ (uint64_t)(int64_t)floor(ag_box_extent(&pbox[r], a) / q +
                                                                0.5));
                kv[nk].key = h;
                kv[nk++].val = (uint32_t)t;
            }
        size_t *twin_tris = calloc(nc, sizeof *twin_tris);
        if (!twin_tris || ag_radix_sort(kv, nk)) {
            free(twin_tris);
            free(pidx);
            free(pcount);
            free(pbox);
            free(npieces);
            goto done;
        }
        for (size_t i = 0; i < nk; i++) {
            int tw = (i > 0 && kv[i - 1].key == kv[i].key) ||
                     (i + 1 < nk && kv[i + 1].key == kv[i].key);
            if (tw)
                twin_tris[in->tri_component[kv[i].val]] += pcount[pidx[kv[i].val]];
        }
        for (size_t c = 0; c < nc; c++) {
            if (npieces[c] < 2 || o.keep_groups)
                continue;
            int32_t g = in->component_group[c];
            if (g < 0 || ngroups_used <= 1 ||
                (npieces[c] >= o.split_min_pieces && 2 * twin_tris[c] >= ctris[c])) {
                split[c] = 1;
                if (g >= 0)
                    inf.groups_split++;
            }
        }
        free(twin_tris);
        free(pidx);
        free(pcount);
        free(pbox);
        free(npieces);
    }

    /* new component of every triangle: (old component, piece when split) in first-use order */
    {
        uint32_t *first = malloc(n * sizeof *first); /* root/old comp → new comp */
        uint32_t *cfirst = malloc(nc * sizeof *cfirst);
        if (!first || !cfirst) {
            free(first);
            free(cfirst);
            goto done;
        }
        for (size_t t = 0; t < n; t++)
            first[t] = UINT32_MAX;
        for (size_t c = 0; c < nc; c++)
            cfirst[c] = UINT32_MAX;
        size_t next = 0;
        for (size_t t = 0; t < n; t++) {
            uint32_t c = in->tri_component[t];
            uint32_t *slot = split[c] ? &first[piece[t]] : &cfirst[c];
            if (*slot == UINT32_MAX)
                *slot = (uint32_t)next++;
            newc[t] = *slot;
        }
        /* group of each new component */
        int32_t *cg = malloc((next + 1) * sizeof *cg);
        if (!cg) {
            free(first);
            free(cfirst);
            goto done;
        }
        for (size_t t = 0; t < n; t++)
            cg[newc[t]] = in->component_group[in->tri_component[t]];
        free(first);
        free(cfirst);

        int one_piece = 1;
        for (size_t t = 1; t < n && one_piece; t++)
            one_piece = piece[t] == piece[0];
        if (next == 1 && n > 1 && one_piece) {
            size_t nr = 0;
            double cosmax = cos(o.planar_degrees * M_PI / 180.0);
            st = planar_regions(in, wid, cosmax, AG_PROC_PLANE_DISTANCE * (diag > 0 ? diag : 1.0),
                                newc, &nr);
            if (st) {
                free(cg);
                goto done;
            }
            if (nr > 1) {
                int32_t g0 = cg[0];
                free(cg);
                cg = malloc(nr * sizeof *cg);
                if (!cg) {
                    st = AG_ERR_NOMEM;
                    goto done;
                }
                for (size_t r = 0; r < nr; r++)
                    cg[r] = g0;
                inf.planar_fallback = 1;
            }
            next = nr;
        }
        st = ag_mesh_reserve(m, in->nverts, n);
        for (size_t i = 0; !st && i < in->ngroups; i++)
            st = ag_mesh_add_group(m, in->group_names[i], NULL);
        for (size_t v = 0; !st && v < in->nverts; v++)
            st = ag_mesh_add_vertex(m, in->pos[3 * v], in->pos[3 * v + 1], in->pos[3 * v + 2]);
        for (size_t c = 0; !st && c < next; c++)
            st = ag_mesh_add_component(m, cg[c], NULL);
        for (size_t t = 0; !st && t < n; t++)
            st = ag_mesh_add_triangle(m, in->tri[3 * t], in->tri[3 * t + 1], in->tri[3 * t + 2],
                                      newc[t]);
        free(cg);
        if (st) {
            st = ag_error_set(err, st, 0, "out of memory while segmenting");
            goto done;
        }
    }
    inf.components = m->ncomponents;
    *out = m;
    m = NULL;
    st = AG_OK;
done:
    if (st == AG_ERR_NOMEM && (!err || err->code != AG_ERR_NOMEM))
        ag_error_set(err, st, 0, "out of memory while segmenting");
    ag_mesh_free(m);
    free(wid);
    ag_uf_free(&uf);
    free(newc);
    free(piece);
    free(kv);
    free(ctris);
    free(split);
    if (info)
        *info = inf;
    return st;
}
