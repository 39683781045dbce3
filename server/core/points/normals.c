#include "normals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_K 64

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Unit vector of the null space of (A - lambda I) when it is one-dimensional: the largest
 * cross product of two rows. Returns its squared length before normalising. */
static double null_vector(const double a[6], double lambda, double v[3])
{
    double r0[3] = {a[0] - lambda, a[1], a[2]};
    double r1[3] = {a[1], a[3] - lambda, a[4]};
    double r2[3] = {a[2], a[4], a[5] - lambda};
    double c[3][3];
    cross(r0, r1, c[0]);
    cross(r0, r2, c[1]);
    cross(r1, r2, c[2]);
    int best = 0;
    double bl = dot(c[0], c[0]);
    for (int i = 1; i < 3; i++) {
        double l = dot(c[i], c[i]);
        if (l > bl) {
            bl = l;
            best = i;
        }
    }
    if (bl > 0) {
        double s = 1 / sqrt(bl);
        for (int k = 0; k < 3; k++)
            v[k] = c[best][k] * s;
    }
    return bl;
}

void ag_normals_smallest_eigenvector(const double a_in[6], double n[3], double ev[3])
{
    /* scale to unit size so the thresholds below are relative */
    double scale = 0;
    for (int i = 0; i < 6; i++)
        if (fabs(a_in[i]) > scale)
            scale = fabs(a_in[i]);
    n[0] = 0;
    n[1] = 0;
    n[2] = 1;
    if (!(scale > 0) || !isfinite(scale)) {
        if (ev)
            ev[0] = ev[1] = ev[2] = 0;
        return;
    }
    double a[6];
    for (int i = 0; i < 6; i++)
        a[i] = a_in[i] / scale;
    double e[3];
    double p1 = a[1] * a[1] + a[2] * a[2] + a[4] * a[4];
    double q = (a[0] + a[3] + a[5]) / 3;
    if (p1 < 1e-30) {
        e[0] = a[0];
        e[1] = a[3];
        e[2] = a[5];
    } else {
        double b0 = a[0] - q, b3 = a[3] - q, b5 = a[5] - q;
        double p2 = b0 * b0 + b3 * b3 + b5 * b5 + 2 * p1;
        double p = sqrt(p2 / 6);
        double det = b0 * (b3 * b5 - a[4] * a[4]) - a[1] * (a[1] * b5 - a[4] * a[2]) +
                     a[2] * (a[1] * a[4] - b3 * a[2]);
        double r = det / (2 * p * p * p);
        r = r < -1 ? -1 : r > 1 ? 1 : r;
        double phi = acos(r) / 3;
        e[2] = q + 2 * p * cos(phi);
        e[0] = q + 2 * p * cos(phi + 2 * M_PI / 3);
        e[1] = 3 * q - e[0] - e[2];
    }
    /* ascending */
    for (int i = 0; i < 2; i++)
        for (int j = i + 1; j < 3; j++)
            if (e[j] < e[i]) {
                double t = e[i];
                e[i] = e[j];
                e[j] = t;
            }
    if (ev)
        for (int i = 0; i < 3; i++)
            ev[i] = e[i] * scale;
    double gap = e[1] - e[0];
    if (gap > 1e-12 * (e[2] > 0 ? e[2] : 1) && null_vector(a, e[0], n) > 1e-24)
        return;
    /* the two smallest are equal (points on a line): any vector across the largest axis */
    double axis[3];
    if (e[2] - e[1] > 1e-12 && null_vector(a, e[2], axis) > 1e-24) {
        double t[3] = {fabs(axis[0]) < 0.9 ? 1 : 0, fabs(axis[0]) < 0.9 ? 0 : 1, 0};
        cross(axis, t, n);
        double l = sqrt(dot(n, n));
        for (int k = 0; k < 3; k++)
            n[k] /= l;
        return;
    }
    n[0] = 0;
    n[1] = 0;
    n[2] = 1; /* isotropic: no preferred direction */
}

void ag_normals_covariance(const double *xyz, const uint32_t *idx, size_t m, double mean[3],
                           double cov[6])
{
    mean[0] = mean[1] = mean[2] = 0;
    for (int i = 0; i < 6; i++)
        cov[i] = 0;
    for (size_t j = 0; j < m; j++) {
        const double *p = xyz + 3 * (size_t)(idx ? idx[j] : j);
        for (int a = 0; a < 3; a++)
            mean[a] += p[a];
    }
    for (int a = 0; a < 3 && m; a++)
        mean[a] /= (double)m;
    for (size_t j = 0; j < m; j++) {
        const double *p = xyz + 3 * (size_t)(idx ? idx[j] : j);
        double x = p[0] - mean[0], y = p[1] - mean[1], z = p[2] - mean[2];
        cov[0] += x * x;
        cov[1] += x * y;
        cov[2] += x * z;
        cov[3] += y * y;
        cov[4] += y * z;
        cov[5] += z * z;
    }
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

typedef struct {
    ag_cloud *c;
    const ag_normals_options *opt;
    unsigned k;
    double centroid[3];
    float *variation;
    uint32_t *neighbours;
    float *nearest;
    size_t sample_every, nsample, done;
} normals_pass;

/* One point: covariance of its neighbours, smallest axis, orientation, variation. */
static int normal_of(void *user, uint32_t i, const uint32_t *idx, const double *d2,
                     const double *const *pos, size_t m)
{
    normals_pass *np = user;
    ag_cloud *c = np->c;
    const ag_normals_options *opt = np->opt;
    if (opt && opt->progress && (np->done & 16383) == 0 &&
        opt->progress(opt->user, (double)np->done / (double)c->n))
        return 1;
    np->done++;
    unsigned k = np->k;
    const double *p = c->xyz + 3 * (size_t)i;
    if (np->neighbours) {
        uint32_t *row = np->neighbours + (size_t)i * k;
        for (size_t j = 0; j < k; j++)
            row[j] = j < m ? idx[j] : m ? idx[m - 1] : i;
    }
    if (i % np->sample_every == 0)
        for (size_t j = 1; j < m; j++)
            if (d2[j] > 0) { /* duplicates do not count as neighbours */
                np->nearest[np->nsample++] = (float)sqrt(d2[j]);
                break;
            }
    /* the neighbours side by side, for the shared covariance */
    double near[3 * MAX_K], mean[3], cov[6];
    for (size_t j = 0; j < m; j++)
        memcpy(near + 3 * j, pos[j], 3 * sizeof(double));
    ag_normals_covariance(near, NULL, m, mean, cov);
    double nv[3], ev[3];
    ag_normals_smallest_eigenvector(cov, nv, ev);
    /* orientation: up for roofs and floors, outwards for walls */
    if (fabs(nv[2]) > 0.5) {
        if (nv[2] < 0)
            for (int a = 0; a < 3; a++)
                nv[a] = -nv[a];
    } else if (nv[0] * (p[0] - np->centroid[0]) + nv[1] * (p[1] - np->centroid[1]) < 0) {
        for (int a = 0; a < 3; a++)
            nv[a] = -nv[a];
    }
    for (int a = 0; a < 3; a++)
        c->normals[3 * (size_t)i + a] = (float)nv[a];
    if (np->variation) {
        double e0 = ev[0] > 0 ? ev[0] : 0, sum = e0 + ev[1] + ev[2]; /* rounding: ev0 >= 0 */
        np->variation[i] = sum > 0 ? (float)(e0 / sum) : 0;
    }
    return 0;
}

ag_status ag_normals_compute(ag_cloud *c, const ag_kdtree *tree, const ag_normals_options *opt,
                             float *variation, uint32_t *neighbours, ag_normals_info *info,
                             ag_error *err)
{
    unsigned k = opt && opt->k ? opt->k : 16;
    if (k > MAX_K)
        k = MAX_K;
    if (info)
        info->spacing = 0;
    ag_status st = ag_cloud_add_normals(c, err);
    if (st != AG_OK)
        return st;
    size_t n = c->n;
    if (ag_kdtree_size(tree) != n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the spatial index does not hold the cloud");
    normals_pass np = {c, opt, k, {0, 0, 0}, variation, neighbours, NULL, 1, 0, 0};
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            np.centroid[a] += c->xyz[3 * i + a];
    for (int a = 0; a < 3 && n; a++)
        np.centroid[a] /= (double)n;
    /* nearest-neighbour distances of a sample, for the spacing */
    np.sample_every = n > 200000 ? n / 100000 : 1;
    np.nearest = malloc((n / np.sample_every + 1) * sizeof *np.nearest);
    if (!np.nearest)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (ag_kdtree_knn_each(tree, k, normal_of, &np)) {
        free(np.nearest);
        return ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled");
    }
    if (info && np.nsample) {
        qsort(np.nearest, np.nsample, sizeof *np.nearest, cmp_float);
        info->spacing = np.nearest[np.nsample / 2];
    }
    free(np.nearest);
    return AG_OK;
}
