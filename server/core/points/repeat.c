#include "repeat.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/kdtree.h"
#include "../base/tolerance.h"
#include "group.h"
#include "normals.h"
#include "voxel.h"

#define DEFAULT_MIN_EXPLAINED 0.85
#define DEFAULT_MIN_COVERED 0.3
#define DEFAULT_MAX_MATCHES 10000
/* a host is larger than the template by this on one of its plane's axes */
#define HOST_LARGER 1.5
/* two matches overlap when they are closer than this share of the template on every axis */
#define OVERLAP 0.7
/* most rounds of a climb */
#define CLIMB_ROUNDS 40
/* automatic: hosts reach at least this share of the diagonal and hold this share of points */
#define AUTO_HOST_EXTENT 0.1
#define AUTO_HOST_POINTS 0.01
/* automatic: an element lies within this of its host plane (metres, and at most a share of the
 * diagonal), is at most this share of its host's size, and its normal within this angle */
#define AUTO_MAX_DEPTH 1.5
#define AUTO_MAX_DEPTH_SHARE 0.05
#define AUTO_MAX_SHARE 0.5
#define AUTO_MAX_DEGREES 25.0

void ag_repeat_report_clear(ag_repeat_report *rep)
{
    if (!rep)
        return;
    free(rep->matches);
    memset(rep, 0, sizeof *rep);
}

/* ---- a grid over the cloud for box queries ------------------------------------------------ */

typedef struct {
    ag_box b;
    double h;
    size_t nx, ny, nz;
    ag_group cells;
} pgrid;

static ag_status grid_build(pgrid *g, const ag_cloud *c, double h, ag_error *err)
{
    memset(g, 0, sizeof *g);
    g->b = ag_cloud_box(c);
    if (!c->n)
        g->b = (ag_box){{0, 0, 0}, {0, 0, 0}};
    double e[3];
    ag_box_extents(&g->b, e);
    if (!(h > 0))
        h = 1;
    /* at most about four cells per point */
    while ((e[0] / h + 1) * (e[1] / h + 1) * (e[2] / h + 1) > 4.0 * (double)c->n + 64)
        h *= 1.5;
    g->h = h;
    g->nx = (size_t)(e[0] / h) + 1;
    g->ny = (size_t)(e[1] / h) + 1;
    g->nz = (size_t)(e[2] / h) + 1;
    int32_t *cell = malloc((c->n ? c->n : 1) * sizeof *cell);
    if (!cell)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < c->n; i++) {
        size_t q[3], n[3] = {g->nx, g->ny, g->nz};
        for (int a = 0; a < 3; a++) {
            double v = (c->xyz[3 * i + a] - g->b.min[a]) / h;
            q[a] = v < 0 ? 0 : (size_t)v >= n[a] ? n[a] - 1 : (size_t)v;
        }
        cell[i] = (int32_t)((q[2] * g->ny + q[1]) * g->nx + q[0]);
    }
    ag_status st = ag_group_build(&g->cells, cell, c->n, g->nx * g->ny * g->nz, err);
    free(cell);
    return st;
}

/* The points inside box, appended to *out (capacity *cap); skip[i] != 0 leaves point i out. */
static ag_status grid_query(const pgrid *g, const ag_cloud *c, const ag_box *box,
                            const uint8_t *skip, uint32_t **out, size_t *n, size_t *cap)
{
    *n = 0;
    size_t lo[3], hi[3], dim[3] = {g->nx, g->ny, g->nz};
    for (int a = 0; a < 3; a++) {
        double l = (box->min[a] - g->b.min[a]) / g->h, u = (box->max[a] - g->b.min[a]) / g->h;
        if (u < 0 || l >= (double)dim[a])
            return AG_OK;
        lo[a] = l < 0 ? 0 : (size_t)l;
        hi[a] = u >= (double)dim[a] ? dim[a] - 1 : (size_t)u;
    }
    for (size_t z = lo[2]; z <= hi[2]; z++)
        for (size_t y = lo[1]; y <= hi[1]; y++)
            for (size_t x = lo[0]; x <= hi[0]; x++) {
                size_t k = (z * g->ny + y) * g->nx + x;
                const uint32_t *m = ag_group_members(&g->cells, k);
                size_t cnt = ag_group_size(&g->cells, k);
                for (size_t j = 0; j < cnt; j++) {
                    uint32_t i = m[j];
                    if ((skip && skip[i]) || !ag_box_contains_point(box, c->xyz + 3 * (size_t)i, 0))
                        continue;
                    if (AG_ARRAY_RESERVE(*out, *cap, *n + 1))
                        return AG_ERR_NOMEM;
                    (*out)[(*n)++] = i;
                }
            }
    return AG_OK;
}

static void grid_free(pgrid *g)
{
    ag_group_free(&g->cells);
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The range of the points idx[0..m) along the unit axis e, about origin o. */
static void project_range(const ag_cloud *c, const uint32_t *idx, size_t m, const double o[3],
                          const double e[3], double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t j = 0; j < m; j++) {
        const double *p = c->xyz + 3 * (size_t)idx[j];
        double d[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
        double v = dot3(d, e);
        if (v < *lo)
            *lo = v;
        if (v > *hi)
            *hi = v;
    }
}

/* The range of a box's corners along e about o. */
static void box_range(const ag_box *b, const double o[3], const double e[3], double *lo,
                      double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int k = 0; k < 8; k++) {
        double p[3] = {k & 1 ? b->max[0] : b->min[0], k & 2 ? b->max[1] : b->min[1],
                       k & 4 ? b->max[2] : b->min[2]};
        double d[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
        double v = dot3(d, e);
        if (v < *lo)
            *lo = v;
        if (v > *hi)
            *hi = v;
    }
}

static ag_box box_moved(const ag_box *b, const double d[3])
{
    ag_box r = *b;
    for (int a = 0; a < 3; a++) {
        r.min[a] += d[a];
        r.max[a] += d[a];
    }
    return r;
}

/* The spec of every segment r has now (for a rebuild that adds elements); old elements share a
 * label through their group (their label). *next_group gets a free group id. */
static ag_segment_cloud_spec *current_spec(const ag_segment_cloud_result *r, size_t extra,
                                           int32_t *next_group)
{
    ag_segment_cloud_spec *spec = malloc((r->nsegments + extra + 1) * sizeof *spec);
    if (!spec)
        return NULL;
    int32_t g = 0;
    for (size_t s = 0; s < r->nsegments; s++) {
        const ag_segment_cloud_item *it = &r->segments[s];
        int el = it->kind == AG_SEGMENT_CLOUD_ELEMENT;
        spec[s] = (ag_segment_cloud_spec){it->kind, el ? it->host : -1, el ? it->label : -1,
                                          el ? it->box : ag_box_empty()};
        if (el && it->label >= g)
            g = it->label + 1;
    }
    *next_group = g;
    return spec;
}

/* Segments left over around the elements (the ring of wall points at an opening's edge that
 * was no part of the wall's plane, bits of reveals): a segment that is not a host, holds no
 * more points than an element and whose remaining points lie within that element's box grown
 * by a share of its size joins the element. spec[first .. first + nel) are the elements. */
#define ADOPT_GROW 0.15
static void adopt_fragments(const ag_cloud *c, ag_segment_cloud_result *r,
                            ag_segment_cloud_spec *spec, size_t first, size_t nel,
                            const int32_t *is_host)
{
    size_t *el_count = calloc(nel + 1, sizeof *el_count);
    if (!el_count)
        return; /* nothing adopted: still a valid decomposition */
    for (size_t i = 0; i < c->n; i++)
        if (r->segment[i] >= (int32_t)first && (size_t)r->segment[i] < first + nel)
            el_count[r->segment[i] - first]++;
    for (size_t s = 0; s < r->nsegments; s++) {
        if (is_host[s] || r->segments[s].kind == AG_SEGMENT_CLOUD_ELEMENT)
            continue;
        const uint32_t *m = r->members + r->member_start[s];
        size_t cnt = r->member_start[s + 1] - r->member_start[s], left = 0;
        ag_box b = ag_box_empty();
        for (size_t j = 0; j < cnt; j++)
            if (r->segment[m[j]] == (int32_t)s) {
                ag_box_extend_point(&b, c->xyz + 3 * (size_t)m[j]);
                left++;
            }
        if (!left)
            continue;
        for (size_t e = 0; e < nel; e++) {
            const ag_box *eb = &spec[first + e].box;
            if (left > el_count[e])
                continue;
            double g = 0;
            for (int a = 0; a < 3; a++)
                g = fmax(g, ADOPT_GROW * ag_box_extent(eb, a));
            if (!ag_box_contains(eb, &b, g))
                continue;
            for (size_t j = 0; j < cnt; j++)
                if (r->segment[m[j]] == (int32_t)s)
                    r->segment[m[j]] = (int32_t)(first + e);
            ag_box_extend_box(&spec[first + e].box, &b);
            el_count[e] += left;
            break;
        }
    }
    free(el_count);
}

/* ---- template matching -------------------------------------------------------------------- */

typedef struct {
    const ag_cloud *c;
    const ag_segment_cloud_result *r;
    const pgrid *grid;
    int32_t host;
    uint8_t *skip;        /* per point: the host's, or taken by a match */
    const ag_box *tmpl;
    /* the template's own points */
    uint32_t *tidx;
    size_t nt;
    double *txyz;         /* their positions relative to nothing (cloud-local) */
    ag_kdtree *ttree;
    double tau;
    double min_explained, min_covered;
    /* the template's cells of size tau (the quick score) */
    ag__voxel_set tcells;
    double vo[3];
    uint32_t *stamp, cur;
    /* the frame */
    double e[3][3], o[3], ext[3], step[3], lo[3], hi[3], q0[3];
    /* scratch */
    uint32_t *cand;
    size_t ncand, capcand;
    double *cxyz;
    size_t capc;
    size_t positions;
} matcher;

/* Share of the points idx[0..n) (moved by -d) within tau of a template point. */
static double explained(const matcher *M, const uint32_t *idx, size_t n, const double d[3],
                        double tau)
{
    if (!n)
        return 0;
    size_t hit = 0;
    for (size_t j = 0; j < n; j++) {
        const double *p = M->c->xyz + 3 * (size_t)idx[j];
        double q[3] = {p[0] - d[0], p[1] - d[1], p[2] - d[2]};
        uint32_t k;
        double d2;
        if (ag_kdtree_knn(M->ttree, q, 1, &k, &d2) && d2 <= tau * tau)
            hit++;
    }
    return (double)hit / (double)n;
}

/* Share of the template within tau of a point of idx[0..n) (moved by -d). */
static ag_status covered(matcher *M, const uint32_t *idx, size_t n, const double d[3],
                         double tau, double *out, ag_error *err)
{
    *out = 0;
    if (!n)
        return AG_OK;
    if (AG_ARRAY_RESERVE(M->cxyz, M->capc, 3 * n))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t j = 0; j < n; j++)
        for (int a = 0; a < 3; a++)
            M->cxyz[3 * j + a] = M->c->xyz[3 * (size_t)idx[j] + a] - d[a];
    ag_kdtree *t;
    ag_status st = ag_kdtree_build(M->cxyz, NULL, n, &t, err);
    if (st != AG_OK)
        return st;
    size_t hit = 0;
    for (size_t j = 0; j < M->nt; j++) {
        uint32_t k;
        double d2;
        if (ag_kdtree_knn(t, M->txyz + 3 * j, 1, &k, &d2) && d2 <= tau * tau)
            hit++;
    }
    ag_kdtree_free(t);
    *out = (double)hit / (double)M->nt;
    return AG_OK;
}

/* Frame coordinates of a translation. */
static void frame_of(const matcher *M, const double d[3], double u[3])
{
    for (int a = 0; a < 3; a++)
        u[a] = dot3(d, M->e[a]);
}

static int overlaps(const matcher *M, const double u[3], const ag_repeat_match *acc, size_t nacc)
{
    for (size_t k = 0; k < nacc; k++) {
        double v[3];
        frame_of(M, acc[k].offset, v);
        int all = 1;
        for (int a = 0; a < 3 && all; a++)
            all = fabs(u[a] - v[a]) < OVERLAP * M->ext[a] + 1e-12;
        if (all)
            return 1;
    }
    return 0;
}

/* The quick score of the template moved by d: the share of the points in the moved box (less
 * the skipped) whose cell or a neighbouring one holds a template point, and the share of the
 * template's cells with such a point nearby. *n receives the points compared (in M->cand). */
static ag_status quick(matcher *M, const double d[3], double *ex, double *cov, size_t *n)
{
    M->positions++;
    *ex = *cov = 0;
    ag_box b = box_moved(M->tmpl, d);
    if (grid_query(M->grid, M->c, &b, M->skip, &M->cand, &M->ncand, &M->capcand))
        return AG_ERR_NOMEM;
    *n = M->ncand;
    if (!M->ncand)
        return AG_OK;
    M->cur++;
    size_t hit = 0, cells = 0;
    for (size_t j = 0; j < M->ncand; j++) {
        const double *p = M->c->xyz + 3 * (size_t)M->cand[j];
        double q[3] = {p[0] - d[0], p[1] - d[1], p[2] - d[2]};
        uint64_t k = ag__voxel_key_of(q, M->vo, M->tau);
        uint64_t x = k >> 42, y = (k >> 21) & 0x1FFFFF, z = k & 0x1FFFFF;
        int any = 0;
        for (int dx = -1; dx <= 1; dx++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dz = -1; dz <= 1; dz++) {
                    uint32_t t = ag__voxel_set_find(
                        &M->tcells, ag__voxel_key(x + (uint64_t)(int64_t)dx, y + (uint64_t)(int64_t)dy,
                                                  z + (uint64_t)(int64_t)dz));
                    if (t == UINT32_MAX)
                        continue;
                    any = 1;
                    if (M->stamp[t] != M->cur) {
                        M->stamp[t] = M->cur;
                        cells++;
                    }
                }
        hit += any;
    }
    *ex = (double)hit / (double)M->ncand;
    *cov = (double)cells / (double)M->tcells.used;
    return AG_OK;
}

/* explained and covered with exact distances for the template moved by d. */
static ag_status exact_score(matcher *M, const double d[3], double *ex, double *cov,
                             ag_error *err)
{
    M->positions++;
    *ex = *cov = 0;
    ag_box b = box_moved(M->tmpl, d);
    if (grid_query(M->grid, M->c, &b, M->skip, &M->cand, &M->ncand, &M->capcand))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (M->ncand < 4)
        return AG_OK;
    *ex = explained(M, M->cand, M->ncand, d, M->tau);
    return covered(M, M->cand, M->ncand, d, M->tau, cov, err);
}

/* Compares the template moved by d; on a hit climbs the quick score to its best position
 * nearby, checks it with exact distances and fills m: returns 1 for a match. */
static int try_position(matcher *M, const double d[3], ag_repeat_match *m, ag_status *st,
                        ag_error *err)
{
    double ex, cov;
    size_t n;
    if ((*st = quick(M, d, &ex, &cov, &n))) {
        *st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        return 0;
    }
    if (n < 4 || n > 3 * M->nt + 16 || ex < 0.5 * M->min_explained ||
        cov < 0.5 * M->min_covered)
        return 0;
    /* hill climbing on explained x covered: the quick score with steps halving down to the
     * tolerance, then the exact one down to an eighth of it */
    double best[3] = {d[0], d[1], d[2]}, score = ex * cov;
    double s[3] = {M->step[0], M->step[1], M->step[2]};
    int exact = 0;
    for (int it = 0; it < CLIMB_ROUNDS; it++) {
        int moved = 0;
        for (int a = 0; a < 3 && *st == AG_OK; a++)
            for (int dir = -1; dir <= 1; dir += 2) {
                double t[3];
                for (int x = 0; x < 3; x++)
                    t[x] = best[x] + dir * s[a] * M->e[a][x];
                if (exact)
                    *st = exact_score(M, t, &ex, &cov, err);
                else if ((*st = quick(M, t, &ex, &cov, &n)))
                    *st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                if (*st)
                    return 0;
                if (ex * cov > score + 1e-9) {
                    score = ex * cov;
                    memcpy(best, t, sizeof best);
                    moved = 1;
                }
            }
        if (moved)
            continue;
        int small = 1;
        for (int a = 0; a < 3; a++) {
            s[a] *= 0.5;
            small &= s[a] < (exact ? M->tau / 8 : M->tau);
        }
        if (small && exact)
            break;
        if (small) {
            /* the exact score from here on */
            exact = 1;
            if ((*st = exact_score(M, best, &ex, &cov, err)))
                return 0;
            score = ex * cov;
            for (int a = 0; a < 3; a++)
                s[a] = 0.5 * M->tau;
        }
    }
    /* the exact check: distances to the nearest points */
    ag_box rb = box_moved(M->tmpl, best);
    if (grid_query(M->grid, M->c, &rb, M->skip, &M->cand, &M->ncand, &M->capcand)) {
        *st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        return 0;
    }
    n = M->ncand;
    if (n < 4)
        return 0;
    ex = explained(M, M->cand, n, best, M->tau);
    if (ex < M->min_explained)
        return 0;
    if ((*st = covered(M, M->cand, n, best, M->tau, &cov, err)))
        return 0;
    if (cov < M->min_covered)
        return 0;
    m->box = rb;
    memcpy(m->offset, best, sizeof best);
    m->explained = ex;
    m->covered = cov;
    m->points = n;
    return 1;
}

/* A line of positions already scanned: its axis and the other two coordinates in steps. */
typedef struct {
    int axis;
    long k1, k2;
} line_key;

static void matcher_free(matcher *M)
{
    free(M->skip);
    free(M->tidx);
    free(M->txyz);
    free(M->cand);
    free(M->cxyz);
    ag_kdtree_free(M->ttree);
    ag__voxel_set_free(&M->tcells);
    free(M->stamp);
    memset(M, 0, sizeof *M);
}

/* A matcher of the template box over c's segmentation r, with its grid (built here) and a
 * cleared skip mask. */
static ag_status matcher_init(matcher *M, const ag_cloud *c, const ag_segment_cloud_result *r,
                              const ag_box *tmpl, const ag_repeat_options *opt, pgrid *grid,
                              ag_error *err)
{
    memset(M, 0, sizeof *M);
    memset(grid, 0, sizeof *grid);
    if (r->n != c->n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the segmentation is of another cloud");
    if (ag_box_is_empty(tmpl))
        return ag_error_set(err, AG_ERR_INVALID, 0, "template: the box is empty");
    *M = (matcher){.c = c, .r = r, .tmpl = tmpl, .grid = grid};
    M->min_explained = opt->min_explained > 0 ? opt->min_explained : DEFAULT_MIN_EXPLAINED;
    M->min_covered = opt->min_covered > 0 ? opt->min_covered : DEFAULT_MIN_COVERED;
    double spacing = r->spacing > 0 ? r->spacing : 0.01;
    M->tau = opt->tolerance > 0 ? opt->tolerance : 2 * spacing;
    double te[3];
    ag_box_extents(tmpl, te);
    double tsize = fmax(te[0], fmax(te[1], te[2]));
    ag_status st = grid_build(grid, c, tsize > 0 ? tsize / 2 : 1, err);
    if (st == AG_OK && !(M->skip = calloc(c->n ? c->n : 1, 1)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return st;
}

/* The template matching itself, for both callers: the template (the points in the box that
 * are the host's when in_host, else those that are not) slid along the host's frame as the
 * header says. *out gets the matches, the template first (the caller frees them). */
static ag_status match(matcher *M, int32_t host, int in_host, size_t max_matches,
                       const ag_repeat_options *opt, ag_repeat_match **out, size_t *nout,
                       ag_error *err)
{
    const ag_cloud *c = M->c;
    const ag_segment_cloud_result *r = M->r;
    const ag_box *tmpl = M->tmpl;
    double spacing = r->spacing > 0 ? r->spacing : 0.01;
    *out = NULL;
    *nout = 0;
    M->host = host;
    ag_repeat_match *acc = NULL, *tried = NULL;
    size_t nacc = 0, capacc = 0, ntried = 0, captried = 0;
    size_t *queue = NULL, qn = 0, capq = 0;
    line_key *lines = NULL;
    size_t nlines = 0, caplines = 0;
    ag_status st = AG_OK;
    const ag_segment_cloud_item *H = &r->segments[host];
    for (size_t i = 0; i < c->n; i++)
        M->skip[i] = in_host ? r->segment[i] != host : r->segment[i] == host;
    /* the template's own points */
    if (grid_query(M->grid, c, tmpl, M->skip, &M->cand, &M->ncand, &M->capcand) ||
        !(M->tidx = malloc((M->ncand ? M->ncand : 1) * sizeof *M->tidx))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    M->nt = M->ncand;
    memcpy(M->tidx, M->cand, M->nt * sizeof *M->tidx);
    if (M->nt < 8) {
        st = in_host ? ag_error_set(err, AG_ERR_INVALID, 0,
                                    "template: the box holds only %zu points of segment %d",
                                    M->nt, (int)host)
                     : ag_error_set(err, AG_ERR_INVALID, 0,
                                    "template: the box holds only %zu points besides its host "
                                    "plane's (an element flush with its wall cannot be told "
                                    "from the wall)",
                                    M->nt);
        goto done;
    }
    if (!(M->txyz = malloc(3 * M->nt * sizeof *M->txyz))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t j = 0; j < M->nt; j++)
        memcpy(M->txyz + 3 * j, c->xyz + 3 * (size_t)M->tidx[j], 3 * sizeof *M->txyz);
    if ((st = ag_kdtree_build(M->txyz, NULL, M->nt, &M->ttree, err)) != AG_OK)
        goto done;
    for (int a = 0; a < 3; a++)
        M->vo[a] = tmpl->min[a] - 1e5 * M->tau;
    if (ag__voxel_set_init(&M->tcells, M->nt) ||
        !(M->stamp = calloc(M->nt + 1, sizeof *M->stamp))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t j = 0; j < M->nt; j++)
        ag__voxel_set_add(&M->tcells, ag__voxel_key_of(M->txyz + 3 * j, M->vo, M->tau));
    /* the host's frame, its extent and the template's */
    memcpy(M->o, H->centroid, sizeof M->o);
    const uint32_t *hidx = r->members + r->member_start[host];
    size_t nh = r->member_start[host + 1] - r->member_start[host];
    for (int a = 0; a < 3; a++) {
        memcpy(M->e[a], H->axes[a], sizeof M->e[a]);
        double lo, hi;
        box_range(tmpl, M->o, M->e[a], &lo, &hi);
        M->ext[a] = hi - lo;
        M->q0[a] = 0.5 * (lo + hi);
        M->step[a] = fmax(AG_POINTS_TEMPLATE_STEP * M->ext[a], 0.5 * spacing);
        project_range(c, hidx, nh, M->o, M->e[a], &M->lo[a], &M->hi[a]);
    }
    /* match 0: the template itself */
    if (AG_ARRAY_RESERVE(acc, capacc, 1) || AG_ARRAY_RESERVE(queue, capq, 1)) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    acc[0] = (ag_repeat_match){*tmpl, {0, 0, 0}, 1, 1, M->nt};
    nacc = 1;
    queue[qn++] = 0;
    for (size_t j = 0; j < M->nt; j++)
        M->skip[M->tidx[j]] = 1;
    for (size_t qh = 0; qh < qn && st == AG_OK && nacc < max_matches; qh++) {
        if (opt->progress && opt->progress(opt->user, (double)qh / (double)(qn + 1))) {
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled");
            break;
        }
        double u0[3];
        frame_of(M, acc[queue[qh]].offset, u0);
        for (int a = 0; a < 3 && st == AG_OK; a++) {
            int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
            line_key key = {a, lround(u0[b1] / M->step[b1]), lround(u0[b2] / M->step[b2])};
            int seen = 0;
            for (size_t l = 0; l < nlines && !seen; l++)
                seen = lines[l].axis == key.axis && lines[l].k1 == key.k1 && lines[l].k2 == key.k2;
            if (seen)
                continue;
            if (AG_ARRAY_RESERVE(lines, caplines, nlines + 1)) {
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                break;
            }
            lines[nlines++] = key;
            for (int dir = -1; dir <= 1 && st == AG_OK; dir += 2)
                for (long k = 1;; k++) {
                    double u[3] = {u0[0], u0[1], u0[2]};
                    u[a] += dir * k * M->step[a];
                    /* the moved box's centre stays on the host */
                    double centre = M->q0[a] + u[a];
                    if (centre < M->lo[a] - M->step[a] || centre > M->hi[a] + M->step[a])
                        break;
                    if (overlaps(M, u, acc, nacc) || overlaps(M, u, tried, ntried))
                        continue;
                    double d[3];
                    for (int x = 0; x < 3; x++)
                        d[x] = u[0] * M->e[0][x] + u[1] * M->e[1][x] + u[2] * M->e[2][x];
                    ag_repeat_match m;
                    size_t before = M->positions;
                    if (!try_position(M, d, &m, &st, err)) {
                        if (st != AG_OK)
                            break;
                        /* a climb that found nothing: no other climb from around here */
                        if (M->positions > before + 1) {
                            if (AG_ARRAY_RESERVE(tried, captried, ntried + 1)) {
                                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                                break;
                            }
                            tried[ntried] = (ag_repeat_match){*tmpl, {d[0], d[1], d[2]}, 0, 0, 0};
                            ntried++;
                        }
                        continue;
                    }
                    double um[3];
                    frame_of(M, m.offset, um);
                    if (overlaps(M, um, acc, nacc))
                        continue;
                    if (AG_ARRAY_RESERVE(acc, capacc, nacc + 1) ||
                        AG_ARRAY_RESERVE(queue, capq, qn + 1)) {
                        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                        break;
                    }
                    acc[nacc] = m;
                    for (size_t j = 0; j < M->ncand; j++)
                        M->skip[M->cand[j]] = 1;
                    queue[qn++] = nacc++;
                    if (nacc >= max_matches)
                        break;
                }
        }
    }
done:
    if (st == AG_OK) {
        *out = acc;
        *nout = nacc;
        acc = NULL;
    }
    free(acc);
    free(tried);
    free(queue);
    free(lines);
    return st;
}

ag_status ag_repeat_in_segment(const ag_cloud *c, const ag_segment_cloud_result *r,
                               const ag_box *tmpl, int32_t segment, const ag_repeat_options *o,
                               ag_repeat_match **matches, size_t *nmatches, size_t *positions,
                               ag_error *err)
{
    ag_repeat_options opt = o ? *o : (ag_repeat_options){0};
    *matches = NULL;
    *nmatches = 0;
    *positions = 0;
    if (segment < 0 || (size_t)segment >= r->nsegments)
        return ag_error_set(err, AG_ERR_INVALID, 0, "there is no segment %d", (int)segment);
    matcher M;
    pgrid grid;
    ag_status st = matcher_init(&M, c, r, tmpl, &opt, &grid, err);
    if (st == AG_OK)
        st = match(&M, segment, 1, opt.max_matches ? opt.max_matches : DEFAULT_MAX_MATCHES, &opt,
                   matches, nmatches, err);
    *positions = M.positions;
    matcher_free(&M);
    grid_free(&grid);
    return st;
}

ag_status ag_repeat_template(const ag_cloud *c, ag_segment_cloud_result *r, const ag_box *tmpl,
                             const ag_repeat_options *o, ag_repeat_report *rep, ag_error *err)
{
    ag_repeat_options opt = o ? *o : (ag_repeat_options){0};
    if (rep)
        memset(rep, 0, sizeof *rep);
    if (!c->normals)
        return ag_error_set(err, AG_ERR_INVALID, 0, "template: the cloud has no normals");
    size_t max_matches = opt.max_matches ? opt.max_matches : DEFAULT_MAX_MATCHES;
    matcher M;
    pgrid grid;
    ag_repeat_match *acc = NULL;
    size_t nacc = 0;
    ag_segment_cloud_spec *spec = NULL;
    size_t *hcount = NULL;
    uint32_t *hidx = NULL;  /* the host's points: in r->members until the rebuild frees it */
    uint32_t *hkept = NULL; /* their copy that outlives the rebuild */
    size_t nh = 0;
    int32_t host = -1;
    ag_status st = matcher_init(&M, c, r, tmpl, &opt, &grid, err);
    if (st != AG_OK)
        goto done;
    if (!(hcount = calloc(r->nsegments + 1, sizeof *hcount))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    /* the host: the largest plane crossing the box and larger than it */
    if ((st = grid_query(&grid, c, tmpl, NULL, &M.cand, &M.ncand, &M.capcand))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    if (!M.ncand) {
        st = ag_error_set(err, AG_ERR_INVALID, 0, "template: the box holds no points");
        goto done;
    }
    for (size_t j = 0; j < M.ncand; j++)
        if (r->segment[M.cand[j]] >= 0)
            hcount[r->segment[M.cand[j]]]++;
    for (size_t s = 0; s < r->nsegments; s++) {
        const ag_segment_cloud_item *it = &r->segments[s];
        if (!hcount[s] || it->kind != AG_SEGMENT_CLOUD_PLANE)
            continue;
        double lo, hi, larger = 0;
        for (int a = 0; a < 2; a++) {
            box_range(tmpl, it->centroid, it->axes[a], &lo, &hi);
            if (it->extent[a] >= HOST_LARGER * (hi - lo))
                larger = 1;
        }
        if (larger && (host < 0 || it->count > r->segments[host].count))
            host = (int32_t)s;
    }
    if (host < 0) {
        st = ag_error_set(err, AG_ERR_INVALID, 0,
                          "template: the box crosses no plane larger than itself to slide along");
        goto done;
    }
    hidx = r->members + r->member_start[host];
    nh = r->member_start[host + 1] - r->member_start[host];
    if ((st = match(&M, host, 0, max_matches, &opt, &acc, &nacc, err)) != AG_OK)
        goto done;
    /* the matches become elements of one group: the points in each box but the host's */
    int32_t group;
    if (!(spec = current_spec(r, nacc, &group))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    memset(M.skip, 0, c->n);
    for (size_t i = 0; i < c->n; i++)
        M.skip[i] = r->segment[i] == host;
    for (size_t k = 0; k < nacc; k++) {
        if ((st = grid_query(&grid, c, &acc[k].box, M.skip, &M.cand, &M.ncand, &M.capcand))) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        int32_t id = (int32_t)(r->nsegments + k);
        spec[id] = (ag_segment_cloud_spec){AG_SEGMENT_CLOUD_ELEMENT, host, group, acc[k].box};
        for (size_t j = 0; j < M.ncand; j++) {
            r->segment[M.cand[j]] = id;
            M.skip[M.cand[j]] = 1;
        }
    }
    size_t before = r->nsegments;
    {
        int32_t *is_host = calloc(before + 1, sizeof *is_host);
        if (!is_host) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        is_host[host] = 1;
        adopt_fragments(c, r, spec, before, nacc, is_host);
        free(is_host);
    }
    if (rep && nh) {
        if (!(hkept = malloc(nh * sizeof *hkept))) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        memcpy(hkept, hidx, nh * sizeof *hkept);
    }
    hidx = hkept;
    if ((st = ag_segment_cloud_rebuild(c, r, spec, before + nacc, err)) != AG_OK)
        goto done;
    if (rep) {
        /* the host's and the matches' ids after the rebuild: find them by their points */
        rep->host = -1;
        for (size_t j = 0; j < nh && rep->host < 0; j++)
            if (r->segment[hidx[j]] >= 0 &&
                r->segments[r->segment[hidx[j]]].kind != AG_SEGMENT_CLOUD_ELEMENT)
                rep->host = r->segment[hidx[j]];
        rep->label = r->segment[M.tidx[0]] >= 0 ? r->segments[r->segment[M.tidx[0]]].label : -1;
        rep->matches = acc;
        rep->nmatches = nacc;
        rep->positions = M.positions;
        acc = NULL;
    }
done:
    free(hkept);
    free(spec);
    free(hcount);
    free(acc);
    matcher_free(&M);
    grid_free(&grid);
    return st;
}

/* ---- automatic ---------------------------------------------------------------------------- */

typedef struct {
    int32_t seg;           /* its segment */
    int32_t piece;         /* its piece (planes), -1: the whole segment (clusters) */
    size_t count;
} unit;

static int cmp_unit(const void *a, const void *b)
{
    const unit *x = a, *y = b;
    if (x->count != y->count)
        return x->count > y->count ? -1 : 1;
    if (x->seg != y->seg)
        return x->seg < y->seg ? -1 : 1;
    return (x->piece > y->piece) - (x->piece < y->piece);
}

ag_status ag_repeat_auto(const ag_cloud *c, ag_segment_cloud_result *r,
                         const ag_repeat_options *o, ag_repeat_report *rep, ag_error *err)
{
    (void)o;
    if (rep)
        memset(rep, 0, sizeof *rep);
    if (r->n != c->n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the segmentation is of another cloud");
    if (r->nsegments < 2 || c->n < 3)
        return AG_OK;
    double diag = r->diagonal > 0 ? r->diagonal : 1, spacing = r->spacing > 0 ? r->spacing : 0.01;
    size_t min_points = c->n / 10000 > 10 ? c->n / 10000 : 10;
    double max_depth = fmin(AUTO_MAX_DEPTH, AUTO_MAX_DEPTH_SHARE * diag);
    if (max_depth < 3 * spacing)
        max_depth = 3 * spacing;
    double cos_max = cos(AUTO_MAX_DEGREES * M_PI / 180);
    size_t ns = r->nsegments;
    /* hosts: large planes, with their in-plane ranges */
    int32_t *hosts = malloc((ns + 1) * sizeof *hosts);
    double (*range)[4] = malloc((ns + 1) * sizeof *range);
    ag_group pieces = {0};
    unit *units = NULL;
    size_t nunits = 0, capunits = 0;
    uint8_t *taken = calloc(c->n, 1), *is_host_seg = NULL;
    uint32_t *cand = NULL;
    size_t ncand = 0, capcand = 0;
    ag_segment_cloud_spec *spec = NULL;
    pgrid grid = {0};
    ag_status st = AG_OK;
    if (!hosts || !range || !taken) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    size_t nhosts = 0;
    for (size_t s = 0; s < ns; s++) {
        const ag_segment_cloud_item *it = &r->segments[s];
        if (it->kind != AG_SEGMENT_CLOUD_PLANE ||
            fmax(it->extent[0], it->extent[1]) < AUTO_HOST_EXTENT * diag ||
            (double)it->count < AUTO_HOST_POINTS * (double)c->n)
            continue;
        const uint32_t *m = r->members + r->member_start[s];
        size_t cnt = r->member_start[s + 1] - r->member_start[s];
        project_range(c, m, cnt, it->centroid, it->axes[0], &range[s][0], &range[s][1]);
        project_range(c, m, cnt, it->centroid, it->axes[1], &range[s][2], &range[s][3]);
        hosts[nhosts++] = (int32_t)s;
    }
    if (!nhosts)
        goto done;
    if (!(is_host_seg = calloc(ns + 1, 1))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t h = 0; h < nhosts; h++)
        is_host_seg[hosts[h]] = 1;
    if ((st = ag_group_build(&pieces, r->piece, c->n, r->npieces, err)) != AG_OK)
        goto done;
    /* units: the pieces of planes in several pieces, and the clusters */
    {
        size_t *npieces_of = calloc(ns + 1, sizeof *npieces_of);
        if (!npieces_of) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        for (size_t p = 0; p < pieces.ngroups; p++) {
            size_t cnt = ag_group_size(&pieces, p);
            if (cnt && r->segment[ag_group_members(&pieces, p)[0]] >= 0)
                npieces_of[r->segment[ag_group_members(&pieces, p)[0]]]++;
        }
        for (size_t p = 0; p < pieces.ngroups && st == AG_OK; p++) {
            size_t cnt = ag_group_size(&pieces, p);
            if (cnt < min_points)
                continue;
            int32_t s = r->segment[ag_group_members(&pieces, p)[0]];
            if (s < 0 || r->segments[s].kind != AG_SEGMENT_CLOUD_PLANE || npieces_of[s] < 2)
                continue;
            if (AG_ARRAY_RESERVE(units, capunits, nunits + 1))
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            else
                units[nunits++] = (unit){s, (int32_t)p, cnt};
        }
        free(npieces_of);
        for (size_t s = 0; s < ns && st == AG_OK; s++)
            if (r->segments[s].kind == AG_SEGMENT_CLOUD_CLUSTERED &&
                r->segments[s].count >= min_points) {
                if (AG_ARRAY_RESERVE(units, capunits, nunits + 1))
                    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                else
                    units[nunits++] = (unit){(int32_t)s, -1, r->segments[s].count};
            }
        if (st != AG_OK)
            goto done;
    }
    if (nunits > 1) /* qsort takes no null array, even empty */
        qsort(units, nunits, sizeof *units, cmp_unit);
    if ((st = grid_build(&grid, c, 8 * spacing, err)) != AG_OK)
        goto done;
    int32_t group;
    if (!(spec = current_spec(r, nunits, &group))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    (void)group;
    size_t nel = 0;
    for (size_t u = 0; u < nunits; u++) {
        const uint32_t *m = units[u].piece >= 0
                                ? ag_group_members(&pieces, (size_t)units[u].piece)
                                : r->members + r->member_start[units[u].seg];
        size_t cnt = units[u].count;
        size_t free_pts = 0;
        for (size_t j = 0; j < cnt; j++)
            free_pts += !taken[m[j]];
        if (free_pts * 2 < cnt)
            continue; /* mostly inside an element already */
        ag_segment_cloud_item d;
        memset(&d, 0, sizeof d);
        double mean[3], cov[6], n[3], ev[3];
        ag_normals_covariance(c->xyz, m, cnt, mean, cov);
        ag_normals_smallest_eigenvector(cov, n, ev);
        ag_box ub = ag_box_empty();
        for (size_t j = 0; j < cnt; j++)
            ag_box_extend_point(&ub, c->xyz + 3 * (size_t)m[j]);
        int planar = units[u].piece >= 0;
        /* the nearest parallel host behind or in front */
        int32_t best = -1;
        double best_depth = INFINITY;
        for (size_t h = 0; h < nhosts; h++) {
            int32_t hs = hosts[h];
            if (hs == units[u].seg)
                continue;
            const ag_segment_cloud_item *H = &r->segments[hs];
            if (planar && fabs(dot3(n, H->plane.n)) < cos_max)
                continue;
            double dm[3] = {mean[0] - H->centroid[0], mean[1] - H->centroid[1],
                            mean[2] - H->centroid[2]};
            double depth = fabs(dot3(dm, H->plane.n));
            if (depth < 2 * spacing || depth > max_depth || depth >= best_depth)
                continue;
            /* the whole unit within reach of the host (a corner's leftovers running down two
             * walls are no element of the roof) */
            double ulo, uhi;
            box_range(&ub, H->centroid, H->plane.n, &ulo, &uhi);
            if (uhi - ulo > max_depth + 2 * spacing)
                continue;
            int inside = 1;
            for (int a = 0; a < 2 && inside; a++) {
                double lo, hi;
                box_range(&ub, H->centroid, H->axes[a], &lo, &hi);
                double hl = range[hs][2 * a], hh = range[hs][2 * a + 1];
                inside = lo >= hl - 2 * spacing && hi <= hh + 2 * spacing &&
                         hi - lo <= AUTO_MAX_SHARE * (hh - hl);
            }
            if (!inside)
                continue;
            best = hs;
            best_depth = depth;
        }
        if (best < 0)
            continue;
        /* the box: the unit and its shadow on the host plane, grown by two spacings */
        const ag_segment_cloud_item *H = &r->segments[best];
        ag_box eb = ub;
        for (size_t j = 0; j < cnt; j++) {
            const double *p = c->xyz + 3 * (size_t)m[j];
            double dp[3] = {p[0] - H->centroid[0], p[1] - H->centroid[1], p[2] - H->centroid[2]};
            double h = dot3(dp, H->plane.n);
            double q[3] = {p[0] - h * H->plane.n[0], p[1] - h * H->plane.n[1],
                           p[2] - h * H->plane.n[2]};
            ag_box_extend_point(&eb, q);
        }
        for (int a = 0; a < 3; a++) {
            eb.min[a] -= 2 * spacing;
            eb.max[a] += 2 * spacing;
        }
        if ((st = grid_query(&grid, c, &eb, taken, &cand, &ncand, &capcand))) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        /* not the host's points, nor those of another host across it (the walls at a
         * roof's edge); a parallel one (the panes' plane of a row of windows) gives its own */
        size_t kept = 0;
        for (size_t j = 0; j < ncand; j++) {
            int32_t cs = r->segment[cand[j]];
            if (cs == best)
                continue;
            if (cs >= 0 && is_host_seg[cs] &&
                fabs(dot3(r->segments[cs].plane.n, H->plane.n)) < cos_max)
                continue;
            cand[kept++] = cand[j];
        }
        ncand = kept;
        if (ncand < min_points)
            continue;
        int32_t id = (int32_t)(r->nsegments + nel++);
        spec[id] = (ag_segment_cloud_spec){AG_SEGMENT_CLOUD_ELEMENT, best, -1, eb};
        for (size_t j = 0; j < ncand; j++) {
            r->segment[cand[j]] = id;
            taken[cand[j]] = 1;
        }
    }
    if (nel) {
        int32_t *is_host = calloc(ns + 1, sizeof *is_host);
        if (!is_host) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        for (size_t h = 0; h < nhosts; h++)
            is_host[hosts[h]] = 1;
        adopt_fragments(c, r, spec, r->nsegments, nel, is_host);
        free(is_host);
        st = ag_segment_cloud_rebuild(c, r, spec, r->nsegments + nel, err);
    }
    if (rep)
        rep->elements = nel;
done:
    free(hosts);
    free(range);
    ag_group_free(&pieces);
    free(units);
    free(taken);
    free(is_host_seg);
    free(cand);
    free(spec);
    grid_free(&grid);
    return st;
}
