#include "resample.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/box.h"
#include "../base/kdtree.h"
#include "voxel.h"

/* Bisection steps of the thinning's cell size, and how close its count must come. */
#define THIN_STEPS 40
#define THIN_CLOSE 0.02

/* Occupied cells at h with the set already sized. */
static size_t occupied(ag__voxel_set *s, const double *xyz, const uint32_t *idx, size_t n, double h,
                       const double o[3])
{
    ag__voxel_set_clear(s);
    for (size_t j = 0; j < n; j++)
        ag__voxel_set_add(s, ag__voxel_key_of(xyz + 3 * (size_t)(idx ? idx[j] : j), o, h));
    return s->used;
}

ag_status ag_resample_occupied(const double *xyz, const uint32_t *idx, size_t n, double h,
                               const double origin[3], size_t *count, ag_error *err)
{
    *count = 0;
    if (!n)
        return AG_OK;
    if (!(h > 0))
        return ag_error_set(err, AG_ERR_INVALID, 0, "the cell size must be positive");
    ag__voxel_set s;
    if (ag__voxel_set_init(&s, n)) {
        ag__voxel_set_free(&s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    *count = occupied(&s, xyz, idx, n, h, origin);
    ag__voxel_set_free(&s);
    return AG_OK;
}

/* The grid of the disk thinning: cells of the radius, each with its kept points (a list
 * through next[]). */
typedef struct {
    ag__voxel_set cells;
    uint32_t *head, *next;
    double o[3], r;
} thin_grid;

static void cell_of_point(const thin_grid *g, const double p[3], int64_t c[3])
{
    for (int a = 0; a < 3; a++)
        c[a] = (int64_t)floor((p[a] - g->o[a]) / g->r) + 1; /* >= 1: neighbours stay >= 0 */
}

/* Keeps, in index order, every point farther than r from the points kept before it; the
 * count (keep: the kept indices when not NULL). */
static size_t disk_thin(thin_grid *g, const double *xyz, size_t n, double r, uint32_t *keep)
{
    g->r = r;
    ag__voxel_set_clear(&g->cells);
    size_t kept = 0;
    double r2 = r * r;
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        int64_t c[3];
        cell_of_point(g, p, c);
        int near = 0;
        for (int dx = -1; dx <= 1 && !near; dx++)
            for (int dy = -1; dy <= 1 && !near; dy++)
                for (int dz = -1; dz <= 1 && !near; dz++) {
                    uint32_t k = ag__voxel_set_find(
                        &g->cells, ag__voxel_key((uint64_t)(c[0] + dx), (uint64_t)(c[1] + dy),
                                                 (uint64_t)(c[2] + dz)));
                    if (k == UINT32_MAX)
                        continue;
                    for (uint32_t q = g->head[k]; q != UINT32_MAX && !near; q = g->next[q]) {
                        const double *x = xyz + 3 * (size_t)q;
                        double d0 = x[0] - p[0], d1 = x[1] - p[1], d2 = x[2] - p[2];
                        near = d0 * d0 + d1 * d1 + d2 * d2 < r2;
                    }
                }
        if (near)
            continue;
        size_t before = g->cells.used;
        uint32_t k = ag__voxel_set_add(
            &g->cells, ag__voxel_key((uint64_t)c[0], (uint64_t)c[1], (uint64_t)c[2]));
        if (g->cells.used > before)
            g->head[k] = UINT32_MAX;
        g->next[i] = g->head[k];
        g->head[k] = (uint32_t)i;
        if (keep)
            keep[kept] = (uint32_t)i;
        kept++;
    }
    return kept;
}

ag_status ag_resample_thin(const double *xyz, size_t n, size_t target, uint32_t *keep,
                           size_t *nkeep, double *cell, ag_error *err)
{
    *nkeep = 0;
    if (cell)
        *cell = 0;
    if (n <= target || n < 2) {
        for (size_t i = 0; i < n; i++)
            keep[i] = (uint32_t)i;
        *nkeep = n;
        return AG_OK;
    }
    if (!target)
        return AG_OK;
    ag_box b = ag_box_empty();
    for (size_t i = 0; i < n; i++)
        ag_box_extend_point(&b, xyz + 3 * i);
    double diag = ag_box_diagonal(&b);
    if (!(diag > 0)) {
        keep[0] = 0; /* one spot */
        *nkeep = 1;
        return AG_OK;
    }
    thin_grid g = {.head = malloc(n * sizeof *g.head), .next = malloc(n * sizeof *g.next)};
    memcpy(g.o, b.min, sizeof g.o);
    if (!g.head || !g.next || ag__voxel_set_init(&g.cells, n)) {
        free(g.head);
        free(g.next);
        ag__voxel_set_free(&g.cells);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* count(r) falls as r grows: bisection in log r, first on a stride sample of the points
     * (a disk rule's count hardly depends on the density once the points are several times
     * denser than the kept ones), then on all of them in a narrow bracket around its radius */
    size_t sample = 8 * target, stride = n > 2 * sample ? n / sample : 1;
    double *sxyz = NULL;
    size_t ns = n;
    if (stride > 1) {
        ns = (n + stride - 1) / stride;
        if (!(sxyz = malloc(3 * ns * sizeof *sxyz))) {
            free(g.head);
            free(g.next);
            ag__voxel_set_free(&g.cells);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        for (size_t i = 0, j = 0; i < n; i += stride, j++)
            memcpy(sxyz + 3 * j, xyz + 3 * i, 3 * sizeof *sxyz);
    }
    double lo = 4 * diag / (double)AG__VOXEL_AXIS_MAX, hi = diag;
    double best_r = hi;
    for (int pass = stride > 1 ? 0 : 1; pass < 2; pass++) {
        const double *px = pass == 0 ? sxyz : xyz;
        size_t pn = pass == 0 ? ns : n;
        size_t best_got = 1;
        if (pass == 1 && stride > 1) {
            lo = best_r / 1.5; /* the sample's bracket has closed around its radius */
            hi = best_r * 1.5;
            best_got = disk_thin(&g, xyz, n, best_r, NULL);
        }
        for (int it = 0; it < THIN_STEPS; it++) {
            if (fabs((double)best_got - (double)target) <= THIN_CLOSE * (double)target)
                break;
            double r = sqrt(lo * hi);
            size_t got = disk_thin(&g, px, pn, r, NULL);
            if (fabs((double)got - (double)target) < fabs((double)best_got - (double)target)) {
                best_got = got;
                best_r = r;
            }
            if (got > target)
                lo = r;
            else
                hi = r;
        }
    }
    free(sxyz);
    *nkeep = disk_thin(&g, xyz, n, best_r, keep); /* index order: ascending */
    if (cell)
        *cell = best_r;
    free(g.head);
    free(g.next);
    ag__voxel_set_free(&g.cells);
    return AG_OK;
}

double ag_resample_area_factor(const double A[3][3], const float n[3])
{
    /* the cofactor matrix: columns of A crossed pairwise */
    double C[3][3];
    C[0][0] = A[1][1] * A[2][2] - A[1][2] * A[2][1];
    C[0][1] = A[1][2] * A[2][0] - A[1][0] * A[2][2];
    C[0][2] = A[1][0] * A[2][1] - A[1][1] * A[2][0];
    C[1][0] = A[0][2] * A[2][1] - A[0][1] * A[2][2];
    C[1][1] = A[0][0] * A[2][2] - A[0][2] * A[2][0];
    C[1][2] = A[0][1] * A[2][0] - A[0][0] * A[2][1];
    C[2][0] = A[0][1] * A[1][2] - A[0][2] * A[1][1];
    C[2][1] = A[0][2] * A[1][0] - A[0][0] * A[1][2];
    C[2][2] = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    double v[3];
    for (int i = 0; i < 3; i++)
        v[i] = C[i][0] * n[0] + C[i][1] * n[1] + C[i][2] * n[2];
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* A uniform number in [0, 1) from (seed, i, k). */
static double unit_hash(uint64_t seed, uint64_t i, uint64_t k)
{
    uint64_t h = ag__voxel_mix(seed ^ ag__voxel_mix(i * 0x9E3779B97F4A7C15ull + k + 1));
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

unsigned ag_resample_copies(double f, uint64_t seed, uint64_t i)
{
    if (!(f > 0))
        return 0;
    if (f > 64)
        f = 64; /* a degenerate map; bounded output */
    double whole = floor(f);
    return (unsigned)whole + (unit_hash(seed, i, 0) < f - whole);
}

void ag_resample_jitter(const float n[3], double radius, uint64_t seed, uint64_t i,
                        unsigned copy, double d[3])
{
    /* a tangent basis of n */
    double nn[3] = {n[0], n[1], n[2]};
    double l = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    if (!(l > 0)) {
        nn[0] = 0;
        nn[1] = 0;
        nn[2] = 1;
        l = 1;
    }
    for (int a = 0; a < 3; a++)
        nn[a] /= l;
    double ref[3] = {fabs(nn[0]) < 0.9 ? 1 : 0, fabs(nn[0]) < 0.9 ? 0 : 1, 0};
    double u[3] = {nn[1] * ref[2] - nn[2] * ref[1], nn[2] * ref[0] - nn[0] * ref[2],
                   nn[0] * ref[1] - nn[1] * ref[0]};
    double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; a++)
        u[a] /= lu;
    double v[3] = {nn[1] * u[2] - nn[2] * u[1], nn[2] * u[0] - nn[0] * u[2],
                   nn[0] * u[1] - nn[1] * u[0]};
    double r = radius * sqrt(unit_hash(seed, i, 2 * (uint64_t)copy + 1));
    double th = 2 * M_PI * unit_hash(seed, i, 2 * (uint64_t)copy + 2);
    for (int a = 0; a < 3; a++)
        d[a] = r * (cos(th) * u[a] + sin(th) * v[a]);
}

typedef struct {
    int hit;
} hit_ctx;

static int on_hit(void *user, uint32_t id, double d2)
{
    (void)id;
    (void)d2;
    ((hit_ctx *)user)->hit = 1;
    return 1; /* one is enough */
}

ag_status ag_resample_dedupe(const double *xyz, const uint32_t *a, size_t na,
                             const uint32_t *b, size_t nb, double r, uint8_t *drop,
                             ag_error *err)
{
    memset(drop, 0, nb);
    if (!na || !nb)
        return AG_OK;
    ag_kdtree *t;
    ag_status st = ag_kdtree_build(xyz, a, na, &t, err);
    if (st != AG_OK)
        return st;
    for (size_t j = 0; j < nb; j++) {
        hit_ctx h = {0};
        ag_kdtree_radius(t, xyz + 3 * (size_t)b[j], r, on_hit, &h);
        drop[j] = (uint8_t)h.hit;
    }
    ag_kdtree_free(t);
    return AG_OK;
}
