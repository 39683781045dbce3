#include "register.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../proc/label.h"

#define DEFAULT_SAMPLES 256
#define DEFAULT_ITERATIONS 24
/* the final pairing distance, in point spacings */
#define FINAL_PAIRING 3.0
/* the first pairing distance, as a share of the member box's diagonal */
#define FIRST_PAIRING 0.25
/* weight of the point-to-point term next to the point-to-plane one */
#define POINT_WEIGHT 0.05
/* box dimensions within this share count as fitting a turn */
#define TURN_FIT 0.15

void ag_register_apply(const ag_register_result *r, const double x[3], double y[3])
{
    double dx = x[0] - r->pivot[0], dy = x[1] - r->pivot[1];
    ag_label_rotate(r->turn, &dx, &dy);
    y[0] = dx + r->pivot[0] + r->t[0];
    y[1] = dy + r->pivot[1] + r->t[1];
    y[2] = x[2] + r->t[2];
}

/* Solves the symmetric 3x3 system A t = b (A = {a00, a01, a02, a11, a12, a22}); -1 when
 * singular. */
static int solve3(const double A[6], const double b[3], double t[3])
{
    double a = A[0], bb = A[1], c = A[2], d = A[3], e = A[4], f = A[5];
    double c00 = d * f - e * e, c01 = c * e - bb * f, c02 = bb * e - c * d;
    double det = a * c00 + bb * c01 + c * c02;
    if (!(fabs(det) > 1e-30))
        return -1;
    double c11 = a * f - c * c, c12 = bb * c - a * e, c22 = a * d - bb * bb;
    t[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) / det;
    t[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det;
    t[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det;
    return 0;
}

/* Whether k quarter turns map the member box's plan onto the base's. */
static int turn_fits(const ag_box *m, const ag_box *b, int k)
{
    double mx = ag_box_extent(m, k & 1 ? 1 : 0), my = ag_box_extent(m, k & 1 ? 0 : 1);
    double bx = ag_box_extent(b, 0), by = ag_box_extent(b, 1);
    return fabs(mx - bx) <= TURN_FIT * fmax(mx, bx) + 1e-9 &&
           fabs(my - by) <= TURN_FIT * fmax(my, by) + 1e-9;
}

typedef struct {
    const ag_register_base *base;
    const double *sample; /* 3 per sample, member coordinates turned about the pivot */
    size_t ns;
    double spacing;
    unsigned iterations;
    double first;
} icp;

/* ICP from translation t; fills rms, inliers. */
/* Sample s moved by t and its nearest base point within dmax: the residual r (base point less
 * sample) and the base normal n; 0 when none is that near. */
static int pair_of(const icp *I, size_t s, const double t[3], double dmax, double r[3],
                   double n[3])
{
    double y[3] = {I->sample[3 * s] + t[0], I->sample[3 * s + 1] + t[1],
                   I->sample[3 * s + 2] + t[2]};
    uint32_t q;
    double d2;
    if (!ag_kdtree_knn(I->base->tree, y, 1, &q, &d2) || d2 > dmax * dmax)
        return 0;
    const double *p = I->base->xyz + 3 * (size_t)q;
    const float *nf = I->base->normals + 3 * (size_t)q;
    for (int a = 0; a < 3; a++) {
        r[a] = p[a] - y[a];
        n[a] = nf[a];
    }
    return 1;
}

static void run_icp(const icp *I, double t[3], double *rms, double *inliers)
{
    double final = FINAL_PAIRING * I->spacing;
    double dmax = I->first > final ? I->first : final;
    size_t pairs = 0;
    double sq = 0;
    for (unsigned it = 0; it < I->iterations; it++) {
        double A[6] = {0, 0, 0, 0, 0, 0}, b[3] = {0, 0, 0};
        pairs = 0;
        sq = 0;
        for (size_t s = 0; s < I->ns; s++) {
            double r[3], n[3];
            if (!pair_of(I, s, t, dmax, r, n))
                continue;
            double rn = r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
            /* point-to-plane: n n^T dt = n (r . n); point-to-point: w dt = w r */
            A[0] += n[0] * n[0] + POINT_WEIGHT;
            A[1] += n[0] * n[1];
            A[2] += n[0] * n[2];
            A[3] += n[1] * n[1] + POINT_WEIGHT;
            A[4] += n[1] * n[2];
            A[5] += n[2] * n[2] + POINT_WEIGHT;
            for (int a = 0; a < 3; a++)
                b[a] += n[a] * rn + POINT_WEIGHT * r[a];
            sq += rn * rn;
            pairs++;
        }
        double dt[3];
        if (pairs < 3 || solve3(A, b, dt))
            break;
        for (int a = 0; a < 3; a++)
            t[a] += dt[a];
        double step = sqrt(dt[0] * dt[0] + dt[1] * dt[1] + dt[2] * dt[2]);
        /* the pairing distance shrinks geometrically to its final value */
        double next = dmax * 0.7;
        if (step < 0.05 * I->spacing && dmax <= final * 1.0001)
            break;
        dmax = next > final ? next : final;
    }
    /* the measure at the final distance */
    pairs = 0;
    sq = 0;
    for (size_t s = 0; s < I->ns; s++) {
        double r[3], n[3];
        if (!pair_of(I, s, t, final, r, n))
            continue;
        double rn = r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
        sq += rn * rn;
        pairs++;
    }
    *rms = pairs ? sqrt(sq / (double)pairs) : INFINITY;
    *inliers = I->ns ? (double)pairs / (double)I->ns : 0;
}

ag_status ag_register_member(const ag_register_base *base, const double *xyz,
                             const uint32_t *idx, size_t m, const ag_box *box,
                             const ag_register_options *o, ag_register_result *res,
                             ag_error *err)
{
    memset(res, 0, sizeof *res);
    res->rms = INFINITY;
    if (!m || !base->n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "registration needs points on both sides");
    if (!(o->spacing > 0))
        return ag_error_set(err, AG_ERR_INVALID, 0, "registration needs the point spacing");
    size_t ns = o->samples ? o->samples : DEFAULT_SAMPLES;
    if (ns > m)
        ns = m;
    double *sample = malloc(3 * ns * sizeof *sample);
    if (!sample)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    double pivot[3];
    ag_box_centre(box, pivot);
    memcpy(res->pivot, pivot, sizeof pivot);
    double bc[3];
    ag_box_centre(&base->box, bc);
    unsigned turns = o->turns;
    if (!turns)
        for (int k = 0; k < 4; k++)
            if (turn_fits(box, &base->box, k))
                turns |= 1u << k;
    if (!turns)
        turns = 0xF; /* nothing fits: try every turn, the residual decides */
    icp I = {base, sample, ns, o->spacing, o->iterations ? o->iterations : DEFAULT_ITERATIONS,
             FIRST_PAIRING * ag_box_diagonal(box)};
    int found = 0;
    for (int k = 0; k < 4; k++) {
        if (!(turns >> k & 1))
            continue;
        /* an even subsample (stride through the member), turned about the pivot */
        for (size_t s = 0; s < ns; s++) {
            size_t j = (size_t)((double)s * (double)m / (double)ns);
            const double *p = xyz + 3 * (size_t)(idx ? idx[j] : j);
            double dx = p[0] - pivot[0], dy = p[1] - pivot[1];
            ag_label_rotate(k, &dx, &dy);
            sample[3 * s] = dx + pivot[0];
            sample[3 * s + 1] = dy + pivot[1];
            sample[3 * s + 2] = p[2];
        }
        /* the member box turned about its centre */
        ag_box tb = *box;
        if (k & 1)
            for (int a = 0; a < 2; a++) {
                double h = 0.5 * ag_box_extent(box, 1 - a);
                tb.min[a] = pivot[a] - h;
                tb.max[a] = pivot[a] + h;
            }
        /* starts: the caller's offset, centres, mins and maxes aligned */
        double starts[4][3];
        int nstarts = 0;
        if (o->has_offset && k == 0)
            memcpy(starts[nstarts++], o->offset, sizeof starts[0]);
        for (int a = 0; a < 3; a++) {
            starts[nstarts][a] = bc[a] - pivot[a];
            starts[nstarts + 1][a] = base->box.min[a] - tb.min[a];
            starts[nstarts + 2][a] = base->box.max[a] - tb.max[a];
        }
        nstarts += 3;
        for (int s = 0; s < nstarts; s++) {
            double t[3] = {starts[s][0], starts[s][1], starts[s][2]}, rms, in;
            run_icp(&I, t, &rms, &in);
            /* more inliers first; among nearly as many, the smaller residual */
            int better = !found || in > res->inliers + 0.02 ||
                         (in >= res->inliers - 0.02 && rms < res->rms);
            if (better) {
                found = 1;
                res->turn = k;
                memcpy(res->t, t, sizeof t);
                res->rms = rms;
                res->inliers = in;
            }
        }
    }
    free(sample);
    return AG_OK;
}
