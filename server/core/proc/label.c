#include "label.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/search.h"
#include "../base/tolerance.h"
#include "weld.h"

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

typedef struct {
    uint64_t h;
    uint32_t i;
} hidx;

static int cmp_hidx(const void *a, const void *b)
{
    const hidx *x = a, *y = b;
    if (x->h != y->h)
        return x->h < y->h ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
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

double ag_label_match_triangles(const double *a, size_t na, const double *b, size_t nb,
                                double tol, size_t *unmatched)
{
    size_t miss = 0;
    double worst = 0;
    if (tol <= 0)
        tol = AG_PROC_TINY;
    double cell = 2 * tol; /* a match within tol lies in a neighbouring cell */
    hidx *ha = malloc((na + 1) * sizeof *ha);
    uint8_t *used = calloc(na + 1, 1);
    if (!ha || !used) {
        free(ha);
        free(used);
        return -1;
    }
    for (size_t i = 0; i < na; i++) {
        double c[3];
        centroid(a + 9 * i, c);
        ha[i].h = ag__cell_hash((int64_t)floor(c[0] / cell), (int64_t)floor(c[1] / cell),
                                (int64_t)floor(c[2] / cell));
        ha[i].i = (uint32_t)i;
    }
    qsort(ha, na, sizeof *ha, cmp_hidx);
    for (size_t j = 0; j < nb; j++) {
        const double *tb = b + 9 * j;
        double c[3];
        centroid(tb, c);
        int64_t k0 = (int64_t)floor(c[0] / cell), k1 = (int64_t)floor(c[1] / cell),
                k2 = (int64_t)floor(c[2] / cell);
        double best = INFINITY;
        size_t besti = SIZE_MAX;
        for (int dx = -1; dx <= 1; dx++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dz = -1; dz <= 1; dz++) {
                    uint64_t h = ag__cell_hash(k0 + dx, k1 + dy, k2 + dz);
                    size_t lo = ag_search_lower_u64(&ha[0].h, na, sizeof *ha, h);
                    for (size_t s = lo; s < na && ha[s].h == h; s++) {
                        uint32_t i = ha[s].i;
                        if (used[i])
                            continue;
                        for (int sh = 0; sh < 3; sh++) {
                            double d = tri_dist(tb, a + 9 * (size_t)i, sh);
                            if (d <= tol && d < best) {
                                best = d;
                                besti = i;
                            }
                        }
                    }
                }
        if (besti == SIZE_MAX) {
            miss++;
            continue;
        }
        used[besti] = 1;
        if (best > worst)
            worst = best;
    }
    free(ha);
    free(used);
    if (unmatched)
        *unmatched = miss;
    return worst;
}

void ag_labels_free(ag_labels *l)
{
    if (!l)
        return;
    free(l->box);
    free(l->ntris);
    free(l->label);
    free(l->rot);
    free(l->tri_start);
    free(l->tris);
    free(l->exemplar);
    free(l->count);
    free(l->variant);
    free(l->vrot);
    free(l->variant_exemplar);
    free(l->variant_count);
    free(l->variant_label);
    free(l);
}

/* Triangle soup of component c, centred on its box centre, rotated by k. */
static void soup(const ag_mesh *m, const ag_labels *L, uint32_t c, int k, double *out)
{
    double ctr[3];
    ag_box_centre(&L->box[c], ctr);
    size_t o = 0;
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++) {
        uint32_t t = L->tris[s];
        for (int v = 0; v < 3; v++) {
            const double *p = m->pos + 3 * m->tri[3 * t + v];
            double x = p[0] - ctr[0], y = p[1] - ctr[1];
            ag_label_rotate(k, &x, &y);
            out[o++] = x;
            out[o++] = y;
            out[o++] = p[2] - ctr[2];
        }
    }
}

static int dims_match(const ag_box *e, const ag_box *c, int k, double tol)
{
    double de[3], dc[3];
    ag_box_extents(e, de);
    ag_box_extents(c, dc);
    if (k & 1) {
        double s = de[0];
        de[0] = de[1];
        de[1] = s;
    }
    for (int a = 0; a < 3; a++)
        if (fabs(de[a] - dc[a]) > tol)
            return 0;
    return 1;
}

typedef struct {
    uint64_t key;
    int32_t head; /* first class in the bucket */
} bucket;

/* Classifies the components in `comps` (in order) with tolerance tol: cls[c] and rot[c] for
 * each, exemplar[k] and count[k] for each class; returns the number of classes, or -1 when
 * out of memory. */
static long classify(const ag_mesh *m, const ag_labels *L, const uint32_t *comps, size_t n,
                     double tol, int no_rotation, int32_t *cls, uint8_t *rot, uint32_t *exemplar,
                     uint32_t *count, double *sa, double *sb)
{
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
    /* buckets: triangle count and the box's height and sorted plan sizes in cells of 4 tol,
     * so a match within tol is always in a neighbouring cell */
    double q = 4 * tol > 0 ? 4 * tol : AG_PROC_TINY;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = comps[i];
        double dx = ag_box_extent(&L->box[c], 0), dy = ag_box_extent(&L->box[c], 1);
        double dz = ag_box_extent(&L->box[c], 2);
        int64_t kb[3] = {(int64_t)floor(dz / q), (int64_t)floor(fmin(dx, dy) / q),
                         (int64_t)floor(fmax(dx, dy) / q)};
        int found = -1, fk = 0;
        for (int nb = 0; nb < 27 && found < 0; nb++) {
            int64_t k0 = kb[0] + nb % 3 - 1, k1 = kb[1] + nb / 3 % 3 - 1, k2 = kb[2] + nb / 9 - 1;
            uint64_t key = ag__mix64(L->ntris[c] * 0x9E3779B97F4A7C15ULL ^ ag__cell_hash(k0, k1, k2));
            size_t h = key & (cap - 1);
            while (bk[h].head >= 0 && bk[h].key != key)
                h = (h + 1) & (cap - 1);
            for (int32_t l = bk[h].head; l >= 0 && found < 0; l = next_in_bucket[l]) {
                uint32_t e = exemplar[l];
                if (L->ntris[e] != L->ntris[c])
                    continue;
                int have_cb = 0;
                for (int k = 0; k < (no_rotation ? 1 : 4) && found < 0; k++) {
                    if (!dims_match(&L->box[e], &L->box[c], k, tol))
                        continue;
                    if (!have_cb) {
                        soup(m, L, c, 0, sb);
                        have_cb = 1;
                    }
                    soup(m, L, e, k, sa);
                    size_t miss = 0;
                    double w = ag_label_match_triangles(sa, L->ntris[e], sb, L->ntris[c], tol,
                                                        &miss);
                    if (w < 0) {
                        free(bk);
                        free(next_in_bucket);
                        return -1;
                    }
                    if (miss == 0) {
                        found = l;
                        fk = k;
                    }
                }
            }
        }
        if (found >= 0) {
            cls[c] = found;
            rot[c] = (uint8_t)fk;
            count[found]++;
            continue;
        }
        int32_t l = (int32_t)ncls++;
        exemplar[l] = c;
        count[l] = 1;
        cls[c] = l;
        rot[c] = 0;
        uint64_t key = ag__mix64(L->ntris[c] * 0x9E3779B97F4A7C15ULL ^
                                 ag__cell_hash(kb[0], kb[1], kb[2]));
        size_t h = key & (cap - 1);
        while (bk[h].head >= 0 && bk[h].key != key)
            h = (h + 1) & (cap - 1);
        bk[h].key = key;
        next_in_bucket[l] = bk[h].head;
        bk[h].head = l;
    }
    free(bk);
    free(next_in_bucket);
    return ncls;
}

ag_status ag_label_components(const ag_mesh *m, const ag_label_options *opt, ag_labels **out,
                              ag_error *err)
{
    ag_label_options o = opt ? *opt : (ag_label_options){0};
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
    L->tri_start = calloc(nc + 2, sizeof *L->tri_start);
    L->tris = malloc((m->ntris + 1) * sizeof *L->tris);
    L->exemplar = malloc((nc + 1) * sizeof *L->exemplar);
    L->count = calloc(nc + 1, sizeof *L->count);
    L->variant = malloc((nc + 1) * sizeof *L->variant);
    L->vrot = calloc(nc + 1, 1);
    L->variant_exemplar = malloc((nc + 1) * sizeof *L->variant_exemplar);
    L->variant_count = calloc(nc + 1, sizeof *L->variant_count);
    L->variant_label = malloc((nc + 1) * sizeof *L->variant_label);
    double *sa = NULL, *sb = NULL;
    size_t maxt = 0;
    ag_status st = AG_ERR_NOMEM;
    if (!L->box || !L->ntris || !L->label || !L->rot || !L->tri_start || !L->tris ||
        !L->exemplar || !L->count || !L->variant || !L->vrot || !L->variant_exemplar ||
        !L->variant_count || !L->variant_label)
        goto fail;

    ag_box all = ag_mesh_bounds(m);
    L->diagonal = ag_box_diagonal(&all);
    if (!(L->diagonal > 0))
        L->diagonal = 0;
    L->tol = o.tolerance * (L->diagonal > 0 ? L->diagonal : 1.0);
    L->exact = o.exact * (L->diagonal > 0 ? L->diagonal : 1.0);

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
    {
        uint32_t *fill = malloc((nc + 1) * sizeof *fill);
        if (!fill)
            goto fail;
        memcpy(fill, L->tri_start, nc * sizeof *fill);
        for (size_t t = 0; t < m->ntris; t++)
            L->tris[fill[m->tri_component[t]]++] = (uint32_t)t;
        free(fill);
    }
    sa = malloc((9 * maxt + 1) * sizeof *sa);
    sb = malloc((9 * maxt + 1) * sizeof *sb);
    if (!sa || !sb)
        goto fail;

    {
        uint32_t *list = malloc((nc + 1) * sizeof *list);
        int32_t *vl = malloc((nc + 1) * sizeof *vl);
        uint8_t *vr = calloc(nc + 1, 1);
        if (!list || !vl || !vr) {
            free(list);
            free(vl);
            free(vr);
            goto fail;
        }
        size_t n = 0;
        for (size_t c = 0; c < nc; c++) {
            L->label[c] = L->variant[c] = -1;
            if (L->ntris[c])
                list[n++] = (uint32_t)c;
        }
        long nv = classify(m, L, list, n, L->exact, o.no_rotation, L->variant, L->vrot,
                           L->variant_exemplar, L->variant_count, sa, sb);
        long nl = nv < 0 ? -1
                         : classify(m, L, L->variant_exemplar, (size_t)nv, L->tol, o.no_rotation,
                                    vl, vr, L->exemplar, L->count, sa, sb);
        if (nl < 0) {
            free(list);
            free(vl);
            free(vr);
            goto fail;
        }
        L->nvariants = (size_t)nv;
        L->nlabels = (size_t)nl;
        for (long k = 0; k < nl; k++)
            L->count[k] = 0;
        for (long v = 0; v < nv; v++)
            L->variant_label[v] = vl[L->variant_exemplar[v]];
        for (size_t i = 0; i < n; i++) {
            uint32_t c = list[i];
            uint32_t e = L->variant_exemplar[L->variant[c]];
            L->label[c] = vl[e];
            L->rot[c] = (uint8_t)((L->vrot[c] + vr[e]) & 3);
            L->count[L->label[c]]++;
        }
        free(list);
        free(vl);
        free(vr);
    }
    free(sa);
    free(sb);
    *out = L;
    return AG_OK;
fail:
    free(sa);
    free(sb);
    ag_labels_free(L);
    return ag_error_set(err, st, 0, "out of memory while labeling");
}
