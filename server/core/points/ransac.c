#include "ransac.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "normals.h"
#include "rng.h"

void ag_plane_list_free(ag_plane_list *l)
{
    free(l->items);
    memset(l, 0, sizeof *l);
}

static int list_push(ag_plane_list *l, const ag_plane *p)
{
    if (AG_ARRAY_RESERVE(l->items, l->cap, l->n + 1))
        return -1;
    l->items[l->n++] = *p;
    return 0;
}

int ag_ransac_fit(const double *xyz, const uint32_t *idx, size_t m, ag_plane *pl)
{
    if (m < 3)
        return -1;
    double mean[3], cov[6];
    ag_normals_covariance(xyz, idx, m, mean, cov);
    double n[3], ev[3];
    ag_normals_smallest_eigenvector(cov, n, ev);
    if (!(ev[1] > ev[2] * 4e-4))
        return -1; /* a line (second axis under 2 % of the first) or one spot: no plane */
    memcpy(pl->n, n, sizeof n);
    pl->d = -(n[0] * mean[0] + n[1] * mean[1] + n[2] * mean[2]);
    pl->count = m;
    return 0;
}

static inline double plane_dist(const ag_plane *pl, const double *p)
{
    return pl->n[0] * p[0] + pl->n[1] * p[1] + pl->n[2] * p[2] + pl->d;
}

static inline int normal_ok(const ag_cloud *c, uint32_t i, const ag_plane *pl, double cosmax)
{
    if (cosmax <= 0)
        return 1;
    const float *nv = c->normals + 3 * (size_t)i;
    double dt = nv[0] * pl->n[0] + nv[1] * pl->n[1] + nv[2] * pl->n[2];
    return fabs(dt) >= cosmax;
}

static inline int is_inlier(const ag_cloud *c, uint32_t i, const ag_plane *pl, double tau,
                            double cosmax)
{
    return fabs(plane_dist(pl, c->xyz + 3 * (size_t)i)) <= tau && normal_ok(c, i, pl, cosmax);
}

/* A candidate through three points (or a point and its normal). */
static int hypothesis(const ag_cloud *c, ag_rng *r, const uint32_t *active, size_t na, ag_plane *pl)
{
    uint32_t a = active[ag_rng_below(r, na)];
    const double *pa = c->xyz + 3 * (size_t)a;
    double n[3];
    if (c->normals) {
        for (int k = 0; k < 3; k++)
            n[k] = c->normals[3 * (size_t)a + k];
    } else {
        const double *pb = c->xyz + 3 * (size_t)active[ag_rng_below(r, na)];
        const double *pc = c->xyz + 3 * (size_t)active[ag_rng_below(r, na)];
        double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
        double v[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
    }
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(l > 1e-12))
        return -1;
    for (int k = 0; k < 3; k++)
        pl->n[k] = n[k] / l;
    pl->d = -(pl->n[0] * pa[0] + pl->n[1] * pa[1] + pl->n[2] * pa[2]);
    return 0;
}

static void select_float(float *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        size_t last = hi - 1, mid = lo + (last - lo) / 2;
        float pivot = v[mid];
        size_t i = lo, j = last;
        for (;;) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i >= j)
                break;
            float t = v[i];
            v[i] = v[j];
            v[j] = t;
            i++;
            j--;
        }
        if (k <= j)
            hi = j + 1;
        else
            lo = j + 1;
    }
}

/* Three robust standard deviations (1.4826 x the median absolute residual) of the inliers,
 * between an eighth of the threshold and the threshold: a clean plane keeps only what lies
 * on it, a rough wall keeps the full slab. */
static double adapted_threshold(const ag_cloud *c, const uint32_t *in, size_t nin,
                                const ag_plane *pl, double tau, float *resid)
{
    if (nin < 8)
        return tau;
    for (size_t j = 0; j < nin; j++)
        resid[j] = (float)fabs(plane_dist(pl, c->xyz + 3 * (size_t)in[j]));
    select_float(resid, nin, nin / 2);
    double t = 3 * 1.4826 * resid[nin / 2];
    return t < tau / 8 ? tau / 8 : t > tau ? tau : t;
}

ag_status ag_ransac_global(const ag_cloud *c, const uint32_t *idx, size_t m,
                           const uint32_t *universe, size_t nu, const ag_ransac_options *o,
                           int32_t *plane_of, ag_plane_list *planes, ag_error *err)
{
    if (!universe) {
        universe = idx;
        nu = m;
    }
    unsigned hyps = o->hypotheses ? o->hypotheses : 256;
    unsigned sample = o->sample ? o->sample : 4096;
    unsigned max_fail = o->failures ? o->failures : 3;
    size_t min_points = o->min_points < 3 ? 3 : o->min_points;
    double tau = o->threshold;
    double cosmax = o->max_angle > 0 ? cos(o->max_angle * M_PI / 180) : 0;
    if (!(tau > 0))
        return ag_error_set(err, AG_ERR_INVALID, 0, "the plane threshold must be positive");
    if (cosmax > 0 && !c->normals)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the normal test needs normals");
    uint32_t *active = malloc((m ? m : 1) * sizeof *active);
    uint32_t *free_pts = malloc((nu ? nu : 1) * sizeof *free_pts);
    uint32_t *in = malloc((nu ? nu : 1) * sizeof *in);
    uint32_t *smp = malloc(sample * sizeof *smp);
    float *resid = malloc((nu ? nu : 1) * sizeof *resid);
    if (!active || !free_pts || !in || !smp || !resid) {
        free(active);
        free(free_pts);
        free(in);
        free(smp);
        free(resid);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t na = 0, nf = 0;
    for (size_t j = 0; j < m; j++)
        if (plane_of[idx[j]] < 0)
            active[na++] = idx[j];
    for (size_t j = 0; j < nu; j++)
        if (plane_of[universe[j]] < 0)
            free_pts[nf++] = universe[j];
    ag_rng rng;
    ag_rng_seed(&rng, o->seed);
    unsigned fails = 0, found = 0;
    ag_status st = AG_OK;
    uint8_t *extra_used = o->nextra ? calloc(o->nextra, 1) : NULL;
    if (o->nextra && !extra_used) {
        free(active);
        free(free_pts);
        free(in);
        free(smp);
        free(resid);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* a budget: a cloud of tiny planes would otherwise cost a full pass per plane */
    unsigned max_planes = o->max_planes ? o->max_planes : 2000;
    while (na >= min_points && fails < max_fail && found < max_planes) {
        if (o->progress && o->progress(o->user, 1.0 - (double)na / (double)(m ? m : 1))) {
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled");
            break;
        }
        size_t ns = na < sample ? na : sample;
        if (na <= sample)
            memcpy(smp, active, na * sizeof *smp);
        else
            for (size_t s = 0; s < ns; s++)
                smp[s] = active[ag_rng_below(&rng, na)];
        ag_plane best = {{0, 0, 1}, 0, 0};
        size_t best_score = 0, best_extra = SIZE_MAX;
        for (unsigned h = 0; h < hyps + o->nextra; h++) {
            ag_plane pl;
            if (h >= hyps) {
                if (extra_used[h - hyps])
                    continue;
                pl = o->extra[h - hyps];
            } else if (hypothesis(c, &rng, active, na, &pl)) {
                continue;
            }
            size_t score = 0;
            for (size_t s = 0; s < ns; s++)
                score += (size_t)is_inlier(c, smp[s], &pl, tau, cosmax);
            if (score > best_score) {
                best_score = score;
                best = pl;
                best_extra = h >= hyps ? h - hyps : SIZE_MAX;
            }
        }
        if (best_extra != SIZE_MAX)
            extra_used[best_extra] = 1;
        if (!best_score || (double)best_score * (double)na / (double)ns < 0.5 * (double)min_points) {
            fails++;
            continue;
        }
        /* refit to all inliers, twice, with the threshold adapted to the plane's noise */
        size_t nin = 0;
        double tau_it = tau;
        int fitted = 0;
        for (int it = 0; it < 3; it++) {
            nin = 0;
            for (size_t j = 0; j < nf; j++)
                if (is_inlier(c, free_pts[j], &best, tau_it, cosmax))
                    in[nin++] = free_pts[j];
            ag_plane fit;
            if (it == 2)
                break;
            if (ag_ransac_fit(c->xyz, in, nin, &fit)) {
                fitted = 0; /* the inliers are no plane (a line, a spot) */
                break;
            }
            fitted = 1;
            best = fit;
            if (o->adaptive)
                tau_it = adapted_threshold(c, in, nin, &best, tau, resid);
        }
        if (nin < min_points || !fitted) {
            fails++;
            continue;
        }
        best.count = nin;
        int32_t id = (int32_t)planes->n;
        if (list_push(planes, &best)) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            break;
        }
        for (size_t j = 0; j < nin; j++)
            plane_of[in[j]] = id;
        size_t w = 0;
        for (size_t j = 0; j < na; j++)
            if (plane_of[active[j]] < 0)
                active[w++] = active[j];
        na = w;
        w = 0;
        for (size_t j = 0; j < nf; j++)
            if (plane_of[free_pts[j]] < 0)
                free_pts[w++] = free_pts[j];
        nf = w;
        found++;
        fails = 0;
    }
    free(extra_used);
    free(resid);
    free(active);
    free(free_pts);
    free(in);
    free(smp);
    return st;
}

/* ---- local pass ---------------------------------------------------------------------- */

typedef struct {
    const ag_cloud *c;
    const ag_ransac_graph *g;
    const int32_t *region;
    int32_t region_id;
    const int32_t *plane_of;
    uint32_t *stamp, cur;
    uint32_t *queue;
    double tau, cosmax, r2;
} grower;

static inline int available(const grower *gr, uint32_t i)
{
    return gr->plane_of[i] < 0 && (!gr->region || gr->region[i] == gr->region_id);
}

/* Points connected to seed through available inliers of pl; they end up in gr->queue.
 * Returns their count (0 when the seed itself does not fit). */
static size_t grow(grower *gr, uint32_t seed, const ag_plane *pl)
{
    const ag_cloud *c = gr->c;
    if (!available(gr, seed) || !is_inlier(c, seed, pl, gr->tau, gr->cosmax))
        return 0;
    gr->cur++;
    size_t qn = 0;
    gr->stamp[seed] = gr->cur;
    gr->queue[qn++] = seed;
    unsigned k = gr->g->k;
    for (size_t h = 0; h < qn; h++) {
        uint32_t q = gr->queue[h];
        const double *pq = c->xyz + 3 * (size_t)q;
        const uint32_t *nb = gr->g->ids + (size_t)q * k;
        for (unsigned j = 0; j < k; j++) {
            uint32_t r = nb[j];
            if (gr->stamp[r] == gr->cur || !available(gr, r))
                continue;
            const double *pr = c->xyz + 3 * (size_t)r;
            if (gr->r2 > 0) {
                double dx = pr[0] - pq[0], dy = pr[1] - pq[1], dz = pr[2] - pq[2];
                if (dx * dx + dy * dy + dz * dz > gr->r2)
                    continue;
            }
            if (!is_inlier(c, r, pl, gr->tau, gr->cosmax))
                continue;
            gr->stamp[r] = gr->cur;
            gr->queue[qn++] = r;
        }
    }
    return qn;
}

typedef struct {
    float v;
    uint32_t id;
} seed_key;

static int cmp_seed(const void *a, const void *b)
{
    const seed_key *x = a, *y = b;
    if (x->v != y->v)
        return x->v < y->v ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

ag_status ag_ransac_local(const ag_cloud *c, const ag_ransac_graph *g, const float *variation,
                          const uint32_t *idx, size_t m, const int32_t *region, int32_t region_id,
                          const ag_ransac_options *o, int32_t *plane_of, ag_plane_list *planes,
                          ag_error *err)
{
    size_t min_points = o->min_points < 3 ? 3 : o->min_points;
    if (!(o->threshold > 0))
        return ag_error_set(err, AG_ERR_INVALID, 0, "the plane threshold must be positive");
    if (!c->normals || !g || !g->ids || !g->k)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the local pass needs normals and neighbours");
    size_t n = c->n;
    grower gr = {c, g, region, region_id, plane_of, NULL, 0, NULL, o->threshold,
                 o->max_angle > 0 ? cos(o->max_angle * M_PI / 180) : 0,
                 o->radius > 0 ? o->radius * o->radius : 0};
    gr.stamp = calloc(n ? n : 1, sizeof *gr.stamp);
    gr.queue = malloc((n ? n : 1) * sizeof *gr.queue);
    uint32_t *comp = malloc((n ? n : 1) * sizeof *comp);
    uint8_t *tried = calloc(n ? n : 1, 1);
    seed_key *seeds = malloc((m ? m : 1) * sizeof *seeds);
    float *resid = malloc((n ? n : 1) * sizeof *resid);
    if (!gr.stamp || !gr.queue || !comp || !tried || !seeds || !resid) {
        free(resid);
        free(gr.stamp);
        free(gr.queue);
        free(comp);
        free(tried);
        free(seeds);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t ns = 0;
    for (size_t j = 0; j < m; j++) {
        uint32_t i = idx[j];
        if (available(&gr, i))
            seeds[ns++] = (seed_key){variation ? variation[i] : 0, i};
    }
    if (variation)
        qsort(seeds, ns, sizeof *seeds, cmp_seed);
    ag_status st = AG_OK;
    unsigned found = 0;
    for (size_t s = 0; s < ns; s++) {
        if (o->progress && (s & 8191) == 0 && o->progress(o->user, (double)s / (double)ns)) {
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled");
            break;
        }
        if (o->max_planes && found >= o->max_planes)
            break;
        uint32_t seed = seeds[s].id;
        if (tried[seed] || !available(&gr, seed))
            continue;
        /* the hypothesis: the seed's own PCA normal through the seed */
        ag_plane pl;
        const float *nv = c->normals + 3 * (size_t)seed;
        const double *ps = c->xyz + 3 * (size_t)seed;
        for (int a = 0; a < 3; a++)
            pl.n[a] = nv[a];
        pl.d = -(pl.n[0] * ps[0] + pl.n[1] * ps[1] + pl.n[2] * ps[2]);
        gr.tau = o->threshold;
        size_t cn = grow(&gr, seed, &pl);
        for (int it = 0; it < 2 && cn >= min_points; it++) {
            memcpy(comp, gr.queue, cn * sizeof *comp);
            ag_plane fit;
            if (ag_ransac_fit(c->xyz, comp, cn, &fit))
                break;
            double tau_before = gr.tau;
            if (o->adaptive)
                gr.tau = adapted_threshold(c, comp, cn, &fit, o->threshold, resid);
            /* grow again from the member that fits the refitted plane best near the seed */
            uint32_t from = seed;
            if (!is_inlier(c, seed, &fit, gr.tau, gr.cosmax)) {
                double bd = INFINITY;
                for (size_t j = 0; j < cn && j < 64; j++) {
                    double dd = fabs(plane_dist(&fit, c->xyz + 3 * (size_t)comp[j]));
                    if (dd < bd && normal_ok(c, comp[j], &fit, gr.cosmax)) {
                        bd = dd;
                        from = comp[j];
                    }
                }
            }
            size_t cn2 = grow(&gr, from, &fit);
            if (cn2 < min_points) {
                /* keep the previous support */
                memcpy(gr.queue, comp, cn * sizeof *comp);
                gr.tau = tau_before;
                break;
            }
            pl = fit;
            cn = cn2;
        }
        if (cn < min_points) {
            for (size_t j = 0; j < cn; j++)
                tried[gr.queue[j]] = 1;
            tried[seed] = 1;
            continue;
        }
        ag_plane fit;
        if (ag_ransac_fit(c->xyz, gr.queue, cn, &fit)) {
            /* a line or a spot: no plane */
            for (size_t j = 0; j < cn; j++)
                tried[gr.queue[j]] = 1;
            tried[seed] = 1;
            continue;
        }
        pl = fit;
        pl.count = cn;
        int32_t id = (int32_t)planes->n;
        if (list_push(planes, &pl)) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            break;
        }
        for (size_t j = 0; j < cn; j++)
            plane_of[gr.queue[j]] = id;
        found++;
    }
    free(gr.stamp);
    free(gr.queue);
    free(comp);
    free(tried);
    free(seeds);
    free(resid);
    return st;
}
