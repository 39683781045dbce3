#include "cut.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/box.h"
#include "group.h"
#include "ransac.h"

#define RING 4.0 /* metres of ring outside the buffer where the ground plane is sampled */

int ag_cut_inside(const ag_cut_footprint *f, double x, double y)
{
    int inside = 0;
    for (size_t l = 0; l < f->nloops; l++) {
        const double *p = f->loops[l];
        size_t n = f->sizes[l];
        for (size_t i = 0, j = n - 1; i < n; j = i++) {
            double xi = p[2 * i], yi = p[2 * i + 1], xj = p[2 * j], yj = p[2 * j + 1];
            if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi)
                inside = !inside;
        }
    }
    return inside;
}

double ag_cut_edge_distance(const ag_cut_footprint *f, double x, double y)
{
    double best = INFINITY;
    for (size_t l = 0; l < f->nloops; l++) {
        const double *p = f->loops[l];
        size_t n = f->sizes[l];
        for (size_t i = 0, j = n - 1; i < n; j = i++) {
            double ax = p[2 * j], ay = p[2 * j + 1], bx = p[2 * i], by = p[2 * i + 1];
            double ex = bx - ax, ey = by - ay, l2 = ex * ex + ey * ey;
            double t = l2 > 0 ? ((x - ax) * ex + (y - ay) * ey) / l2 : 0;
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            double dx = ax + t * ex - x, dy = ay + t * ey - y, d = dx * dx + dy * dy;
            if (d < best)
                best = d;
        }
    }
    return sqrt(best);
}

ag_cut_ground ag_cut_ground_method(const ag_cloud *c, ag_cut_ground requested)
{
    if (requested != AG_CUT_GROUND_AUTO)
        return requested;
    const ag_cloud_property *cls = ag_cloud_find(c, "classification");
    for (size_t i = 0; cls && i < c->n; i++)
        if (ag_cloud_get(cls, i) == 2)
            return AG_CUT_GROUND_CLASS;
    return AG_CUT_GROUND_PLANE;
}

static void footprint_box(const ag_cut_footprint *f, double grow, double mn[2], double mx[2])
{
    mn[0] = mn[1] = INFINITY;
    mx[0] = mx[1] = -INFINITY;
    for (size_t l = 0; l < f->nloops; l++)
        for (size_t i = 0; i < f->sizes[l]; i++)
            for (int a = 0; a < 2; a++) {
                double v = f->loops[l][2 * i + a];
                if (v < mn[a])
                    mn[a] = v;
                if (v > mx[a])
                    mx[a] = v;
            }
    for (int a = 0; a < 2; a++) {
        mn[a] -= grow;
        mx[a] += grow;
    }
}

/* Points bucketed by a 2D grid over x y. */
typedef struct {
    double min[2], h;
    size_t nx, ny;
    uint32_t *start; /* nx * ny + 1 */
    uint32_t *pts;
} grid2;

static int grid_build(grid2 *g, const ag_cloud *c)
{
    ag_box b = ag_cloud_box(c);
    const double *mn = b.min;
    double w = ag_box_extent(&b, 0), d = ag_box_extent(&b, 1);
    /* about four points per cell, at least 1 m, at most 4 million cells */
    double h = c->n ? sqrt((w + 1) * (d + 1) / ((double)c->n / 4 + 1)) : 1;
    if (h < 1)
        h = 1;
    while ((w / h + 1) * (d / h + 1) > 4e6)
        h *= 2;
    g->min[0] = mn[0];
    g->min[1] = mn[1];
    g->h = h;
    g->nx = c->n ? (size_t)(w / h) + 1 : 1;
    g->ny = c->n ? (size_t)(d / h) + 1 : 1;
    g->start = calloc(g->nx * g->ny + 1, sizeof *g->start);
    g->pts = malloc((c->n ? c->n : 1) * sizeof *g->pts);
    uint32_t *cell = malloc((c->n ? c->n : 1) * sizeof *cell);
    if (!g->start || !g->pts || !cell) {
        free(cell);
        return -1;
    }
    for (size_t i = 0; i < c->n; i++) {
        size_t cx = (size_t)((c->xyz[3 * i] - mn[0]) / h), cy = (size_t)((c->xyz[3 * i + 1] - mn[1]) / h);
        if (cx >= g->nx)
            cx = g->nx - 1;
        if (cy >= g->ny)
            cy = g->ny - 1;
        cell[i] = (uint32_t)(cy * g->nx + cx);
        g->start[cell[i] + 1]++;
    }
    for (size_t k = 0; k < g->nx * g->ny; k++)
        g->start[k + 1] += g->start[k];
    uint32_t *fill = malloc((g->nx * g->ny + 1) * sizeof *fill);
    if (!fill) {
        free(cell);
        return -1;
    }
    memcpy(fill, g->start, (g->nx * g->ny + 1) * sizeof *fill);
    for (size_t i = 0; i < c->n; i++)
        g->pts[fill[cell[i]]++] = (uint32_t)i;
    free(fill);
    free(cell);
    return 0;
}

/* The points inside the box [mn, mx] (x y), into out; returns their count. */
static size_t grid_points(const grid2 *g, const ag_cloud *c, const double mn[2], const double mx[2],
                          uint32_t *out)
{
    const size_t dims[2] = {g->nx, g->ny};
    size_t lo[2], hi[2];
    for (int a = 0; a < 2; a++) {
        double l = floor((mn[a] - g->min[a]) / g->h), h = floor((mx[a] - g->min[a]) / g->h);
        if (h < 0 || l >= (double)dims[a])
            return 0;
        lo[a] = l < 0 ? 0 : (size_t)l;
        hi[a] = h >= (double)dims[a] ? dims[a] - 1 : (size_t)h;
    }
    size_t m = 0;
    for (size_t cy = lo[1]; cy <= hi[1]; cy++)
        for (size_t cx = lo[0]; cx <= hi[0]; cx++) {
            size_t cell = cy * g->nx + cx;
            for (uint32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
                uint32_t i = g->pts[k];
                double x = c->xyz[3 * (size_t)i], y = c->xyz[3 * (size_t)i + 1];
                if (x >= mn[0] && x <= mx[0] && y >= mn[1] && y <= mx[1])
                    out[m++] = i;
            }
        }
    return m;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

ag_status ag_cut_assign(const ag_cloud *c, const ag_cut_footprint *fps, size_t nfp,
                        const ag_cut_options *opt, int32_t *owner, ag_cut_stats *stats,
                        ag_error *err)
{
    ag_cut_options o = opt ? *opt : (ag_cut_options){0};
    double buffer = o.buffer < 0 ? 0 : o.buffer > 0 ? o.buffer : 0.5;
    double ground_height = o.ground_height > 0 ? o.ground_height : 0.5;
    size_t n = c->n;
    grid2 g = {0};
    float *best = malloc((n ? n : 1) * sizeof *best);
    uint32_t *cand = malloc((n ? n : 1) * sizeof *cand);
    double *zs = malloc((n ? n : 1) * sizeof *zs);
    ag_status st = AG_OK;
    if (!best || !cand || !zs || grid_build(&g, c)) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto out;
    }
    if (stats)
        memset(stats, 0, nfp * sizeof *stats);
    /* best[i]: -1 strictly inside owner[i], else the distance to its footprint's edge */
    for (size_t i = 0; i < n; i++) {
        owner[i] = -1;
        best[i] = INFINITY;
    }
    /* with building points classified, the buffer takes only those */
    const ag_cloud_property *cls = ag_cloud_find(c, "classification");
    int buildings_classified = 0;
    for (size_t i = 0; cls && i < n && !buildings_classified; i++)
        buildings_classified = ag_cloud_get(cls, i) == 6;
    for (size_t f = 0; f < nfp; f++) {
        double mn[2], mx[2];
        footprint_box(&fps[f], buffer, mn, mx);
        size_t m = grid_points(&g, c, mn, mx, cand);
        for (size_t j = 0; j < m; j++) {
            uint32_t i = cand[j];
            double x = c->xyz[3 * (size_t)i], y = c->xyz[3 * (size_t)i + 1];
            if (best[i] < 0)
                continue;
            if (ag_cut_inside(&fps[f], x, y)) {
                owner[i] = (int32_t)f;
                best[i] = -1;
            } else if (buffer > 0 && (!buildings_classified || ag_cloud_get(cls, i) == 6)) {
                double d = ag_cut_edge_distance(&fps[f], x, y);
                if (d <= buffer && d < best[i]) {
                    owner[i] = (int32_t)f;
                    best[i] = (float)d;
                }
            }
        }
    }
    if (stats)
        for (size_t i = 0; i < n; i++)
            if (owner[i] >= 0) {
                if (best[i] < 0)
                    stats[owner[i]].inside++;
                else
                    stats[owner[i]].buffered++;
            }
    /* ground */
    ag_cut_ground method = ag_cut_ground_method(c, o.ground);
    if (method == AG_CUT_GROUND_CLASS) {
        if (!cls) {
            st = ag_error_set(err, AG_ERR_INVALID, 0,
                              "ground by class needs a classification property");
            goto out;
        }
        for (size_t f = 0; stats && f < nfp; f++)
            stats[f].by_class = 1;
        for (size_t i = 0; i < n; i++)
            if (owner[i] >= 0 && ag_cloud_get(cls, i) == 2) {
                if (stats)
                    stats[owner[i]].ground++;
                owner[i] = -1;
            }
    } else if (method == AG_CUT_GROUND_PLANE) {
        /* each footprint's points (CSR by owner) */
        ag_group fp;
        if ((st = ag_group_build(&fp, owner, n, nfp, err)) != AG_OK)
            goto out;
        for (size_t f = 0; f < nfp; f++) {
            /* the ring around the footprint, its lowest third as the ground sample */
            double mn[2], mx[2];
            footprint_box(&fps[f], buffer + RING, mn, mx);
            size_t all = grid_points(&g, c, mn, mx, cand), m = 0;
            for (size_t j = 0; j < all; j++) {
                uint32_t i = cand[j];
                double x = c->xyz[3 * (size_t)i], y = c->xyz[3 * (size_t)i + 1];
                if (ag_cut_inside(&fps[f], x, y))
                    continue;
                double d = ag_cut_edge_distance(&fps[f], x, y);
                if (d > buffer && d <= buffer + RING)
                    cand[m++] = i;
            }
            int own = m < 10;
            if (own) {
                m = 0;
                for (size_t j = fp.start[f]; j < fp.start[f + 1]; j++)
                    cand[m++] = fp.members[j];
            }
            if (!m)
                continue;
            for (size_t j = 0; j < m; j++)
                zs[j] = c->xyz[3 * (size_t)cand[j] + 2];
            qsort(zs, m, sizeof *zs, cmp_double);
            double zlow = zs[own ? m / 50 : m / 10];
            ag_plane pl = {{0, 0, 1}, -zlow, 0};
            if (!own) {
                /* a plane through the ring's low points, when it is nearly level */
                double zcut = zs[m / 3] < zlow + 1 ? zs[m / 3] : zlow + 1;
                size_t k = 0;
                for (size_t j = 0; j < m; j++)
                    if (c->xyz[3 * (size_t)cand[j] + 2] <= zcut)
                        cand[k++] = cand[j];
                ag_plane fit;
                if (k >= 10 && !ag_ransac_fit(c->xyz, cand, k, &fit) && fabs(fit.n[2]) > cos(15 * M_PI / 180))
                    pl = fit;
            }
            double cxm = (mn[0] + mx[0]) / 2, cym = (mn[1] + mx[1]) / 2;
            if (stats)
                stats[f].ground_z = -(pl.n[0] * cxm + pl.n[1] * cym + pl.d) / pl.n[2];
            for (size_t j = fp.start[f]; j < fp.start[f + 1]; j++) {
                size_t i = fp.members[j];
                const double *p = c->xyz + 3 * i;
                double zg = -(pl.n[0] * p[0] + pl.n[1] * p[1] + pl.d) / pl.n[2];
                if (p[2] - zg < ground_height) {
                    owner[i] = -1;
                    if (stats)
                        stats[f].ground++;
                }
            }
        }
        ag_group_free(&fp);
    }
    if (stats)
        for (size_t f = 0; f < nfp; f++)
            stats[f].kept = stats[f].inside + stats[f].buffered - stats[f].ground;
out:
    free(best);
    free(cand);
    free(zs);
    free(g.start);
    free(g.pts);
    return st;
}
