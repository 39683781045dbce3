/* Forced steps: a polygon united with the active plan at its height (a polygon boolean
 * on the active plan's edges). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "predicates.h"

/* --- plan edits (forced steps) ------------------------------------------------------------ */

#define FORCED_MARK (UINT32_MAX - 1)

typedef struct {
    double x, y;
    double te, tq;     /* parameters along the active edge and along the polygon edge */
    uint32_t e;        /* active edge crossed */
    uint32_t qi;       /* polygon edge crossing it */
    uint32_t vert;
    int enters;        /* the active edge enters the polygon here */
    uint32_t p_before, p_after, q_before, q_after;
} xing;

static int cmp_xing_e(const void *a, const void *b)
{
    const xing *x = *(const xing *const *)a, *y = *(const xing *const *)b;
    if (x->e != y->e)
        return x->e < y->e ? -1 : 1;
    return x->te < y->te ? -1 : x->te > y->te;
}

static int cmp_xing_q(const void *a, const void *b)
{
    const xing *x = *(const xing *const *)a, *y = *(const xing *const *)b;
    if (x->qi != y->qi)
        return x->qi < y->qi ? -1 : 1;
    return x->tq < y->tq ? -1 : x->tq > y->tq;
}

/* Is (x, y) inside the active plan at height v? Even-odd over the live edges. */
static int in_active(sk *S, double v, double x, double y)
{
    int in = 0;
    for (size_t i = 0; i < S->nlive_e; i++) {
        const sk_edge *e = &S->e[S->live_e[i]];
        double ax, ay, bx, by;
        ag__skel_cpos(&S->c[e->start], v, &ax, &ay);
        ag__skel_cpos(&S->c[e->end], v, &bx, &by);
        if ((ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay))
            in = !in;
    }
    return in;
}

static uint32_t forced_edge(sk *S, double ax, double ay, double bx, double by, double v,
                            const ag_plan_step *st, int32_t sid)
{
    double slope = ag__skel_seg_slope(&S->plan->profiles[st->profile], 0);
    return ag__skel_make_edge(S, ax, ay, bx, by, slope, v, sid, st->profile, 0);
}

/* Unites the step's polygon Q with the active plan at virtual height v: active edges are
 * cut where Q crosses them, the parts inside Q end (their faces closed at v), Q's parts
 * outside the plan become new edges with the step's profile, and Q minus the plan gets a
 * floor face. Near-touching configurations are refused (skipped) rather than guessed. */
void ag__skel_forced_step(sk *S, size_t k, double v)
{
    const ag_plan_step *st = &S->plan->steps[k];
    size_t n = st->npoints;
    ag__skel_compact_live(S);
    double *q = malloc(2 * n * sizeof *q);
    if (!q) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    xing *X = NULL, **byE = NULL, **byQ = NULL;
    size_t nx = 0, capx = 0;
    uint32_t *cvert = NULL, *qin = NULL, *qout = NULL, *qvert = NULL;
    uint8_t *cin = NULL, *qinside = NULL;
    /* the polygon in local plan coordinates, counter-clockwise */
    if (st->plan_frame) {
        for (size_t i = 0; i < n; i++) {
            q[2 * i] = st->points[2 * i] - S->ox;
            q[2 * i + 1] = st->points[2 * i + 1] - S->oy;
        }
    } else {
        double ax, ay;
        uint32_t ei = ag__skel_anchor_point(S, &st->at, v, &ax, &ay);
        if (ei == NONE)
            goto skip;
        const sk_edge *e = &S->e[ei];
        double dx = ag__skel_edx(e), dy = ag__skel_edy(e);
        for (size_t i = 0; i < n; i++) {
            double u = st->points[2 * i], w = st->points[2 * i + 1];
            q[2 * i] = ax + u * dx - w * e->nx;
            q[2 * i + 1] = ay + u * dy - w * e->ny;
        }
    }
    double area = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        area += q[2 * i] * q[2 * j + 1] - q[2 * j] * q[2 * i + 1];
    }
    if (area < 0)
        for (size_t i = 0; i < n / 2; i++)
            for (int c = 0; c < 2; c++) {
                double t = q[2 * i + c];
                q[2 * i + c] = q[2 * (n - 1 - i) + c];
                q[2 * (n - 1 - i) + c] = t;
            }
    double tol = 10 * S->d3;
    /* crossings; anything closer than tol that is not a clean crossing is refused */
    for (size_t i = 0; i < S->nlive_e; i++) {
        uint32_t ei = S->live_e[i];
        const sk_edge *e = &S->e[ei];
        double a[2], b[2];
        ag__skel_cpos(&S->c[e->start], v, &a[0], &a[1]);
        ag__skel_cpos(&S->c[e->end], v, &b[0], &b[1]);
        for (size_t j = 0; j < n; j++) {
            const double *c = &q[2 * j], *d = &q[2 * ((j + 1) % n)];
            if (ag_pred_segment_dist(c, a, b) <= tol || ag_pred_segment_dist(a, c, d) <= tol)
                goto skip;
            double oa = ag_pred_orient2d(c, d, a), ob = ag_pred_orient2d(c, d, b);
            double oc = ag_pred_orient2d(a, b, c), od = ag_pred_orient2d(a, b, d);
            /* every corner is some edge's first: the tests above covered all corner to
             * edge distances, so the signs here are clear */
            if ((oa > 0) == (ob > 0) || (oc > 0) == (od > 0))
                continue;
            if (ag_array_reserve((void **)&X, &capx, nx + 1, sizeof *X) != AG_OK) {
                ag__skel_fail(S, AG_ERR_NOMEM);
                goto out;
            }
            xing *x = &X[nx++];
            memset(x, 0, sizeof *x);
            x->te = oa / (oa - ob);
            x->tq = oc / (oc - od);
            x->x = a[0] + x->te * (b[0] - a[0]);
            x->y = a[1] + x->te * (b[1] - a[1]);
            x->e = ei;
            x->qi = (uint32_t)j;
            x->enters = oa < 0; /* the active edge starts right of Q's edge: outside Q */
            x->p_before = x->p_after = x->q_before = x->q_after = NONE;
        }
    }
    /* corners of the active plan inside Q, Q's corners inside the plan */
    cin = calloc(S->nc ? S->nc : 1, 1);
    cvert = malloc((S->nc ? S->nc : 1) * sizeof *cvert);
    qin = malloc(n * sizeof *qin);
    qout = malloc(n * sizeof *qout);
    qvert = malloc(n * sizeof *qvert);
    qinside = malloc(2 * n); /* n corners, then n edges without crossings */
    byE = malloc((nx ? nx : 1) * sizeof *byE);
    byQ = malloc((nx ? nx : 1) * sizeof *byQ);
    if (!cin || !cvert || !qin || !qout || !qvert || !qinside || !byE || !byQ) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        goto out;
    }
    int any_out = 0;
    for (size_t i = 0; i < n; i++) {
        size_t i2 = (i + 1) % n;
        qinside[i] = (uint8_t)in_active(S, v, q[2 * i], q[2 * i + 1]);
        qinside[n + i] = (uint8_t)in_active(S, v, (q[2 * i] + q[2 * i2]) / 2,
                                            (q[2 * i + 1] + q[2 * i2 + 1]) / 2);
        any_out |= !qinside[i];
        qin[i] = qout[i] = NONE;
    }
    int any_in = 0;
    for (size_t i = 0; i < S->nlive_c; i++) {
        uint32_t c = S->live_c[i];
        double x, y;
        ag__skel_cpos(&S->c[c], v, &x, &y);
        cin[c] = (uint8_t)ag_pred_point_in_polygon(q, n, x, y);
        any_in |= cin[c];
    }
    if (!nx && !any_out && !any_in) {
        goto skip; /* wholly inside the active plan: nothing changes */
    }
    for (size_t i = 0; i < nx; i++)
        byE[i] = byQ[i] = &X[i];
    qsort(byE, nx, sizeof *byE, cmp_xing_e);
    qsort(byQ, nx, sizeof *byQ, cmp_xing_q);
    /* the crossings must alternate in and out along every edge of either outline, and
     * agree with the sides its corners are on */
    int bad = 0;
    for (size_t i = 0; i < nx; i++) {
        const xing *a = byE[i], *b = byQ[i];
        if (i == 0 || byE[i - 1]->e != a->e)
            bad |= a->enters == cin[S->e[a->e].start];
        else
            bad |= a->enters == byE[i - 1]->enters;
        if (i + 1 == nx || byE[i + 1]->e != a->e)
            bad |= a->enters != cin[S->e[a->e].end];
        /* Q enters the plan where the active edge leaves Q */
        if (i == 0 || byQ[i - 1]->qi != b->qi)
            bad |= b->enters != qinside[b->qi];
        else
            bad |= b->enters == byQ[i - 1]->enters;
        if (i + 1 == nx || byQ[i + 1]->qi != b->qi)
            bad |= b->enters == qinside[(b->qi + 1) % n];
    }
    if (bad) {
        goto skip;
    }
    ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, (int32_t)k, st->profile, -1, 0, 0};
    uint32_t floor = 0;
    if (ag_shell_add_face(S->shell, &ff, &floor) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        goto out;
    }
    for (size_t i = 0; i < nx; i++)
        X[i].vert = ag__skel_vertex(S, X[i].x, X[i].y, v);
    /* corners inside Q end here */
    size_t nlive_c = S->nlive_c;
    for (size_t i = 0; i < nlive_c; i++) {
        uint32_t c = S->live_c[i];
        if (!cin[c])
            continue;
        double x, y;
        ag__skel_cpos(&S->c[c], v, &x, &y);
        cvert[c] = ag__skel_vertex(S, x, y, v);
        ag__skel_retire(S, c, cvert[c]);
    }
    /* the active edges: pieces inside Q are closed, pieces outside carry on */
    size_t nlive_e = S->nlive_e, xi = 0;
    for (size_t i = 0; i < nlive_e && S->st == AG_OK; i++) {
        uint32_t ei = S->live_e[i];
        size_t x0 = xi;
        while (xi < nx && byE[xi]->e == ei)
            xi++;
        uint32_t cs = S->e[ei].start, ce = S->e[ei].end;
        int inside = cin[cs];
        if (x0 == xi && !inside)
            continue;
        uint32_t cur = inside ? NONE : ei, va = inside ? cvert[cs] : NONE;
        for (size_t j = x0; j <= xi; j++) {
            int last = j == xi;
            uint32_t vb = last ? (cin[ce] ? cvert[ce] : NONE) : byE[j]->vert;
            if (inside) {
                uint32_t face = S->e[ei].face;
                ag__skel_seg(S, face, vb, va);
                ag__skel_seg(S, floor, va, vb);
                if (!last) {
                    /* an outside piece starts at this crossing: a copy of the edge */
                    uint32_t g = ag__skel_add_edge(S);
                    if (g == NONE)
                        break;
                    S->e[g] = S->e[ei];
                    S->e[g].ver = 0;
                    S->e[g].alive = 1;
                    S->e[g].start = S->e[g].end = NONE;
                    byE[j]->p_after = g;
                    cur = g;
                }
            } else {
                if (last) {
                    S->e[cur].end = ce;
                    S->c[ce].in = cur;
                    S->e[cur].ver++;
                } else {
                    byE[j]->p_before = cur;
                    S->e[cur].ver++;
                    cur = NONE;
                }
            }
            va = vb;
            inside = !inside;
        }
        if (cin[cs])
            ag__skel_kill_edge(S, ei); /* its outside pieces, if any, carry on as copies */
    }
    /* Q's pieces outside the active plan become edges */
    int32_t sid = (int32_t)k + 1;
    for (size_t i = 0; i < n; i++)
        qvert[i] = NONE;
    xi = 0;
    for (size_t i = 0; i < n && S->st == AG_OK; i++) {
        size_t x0 = xi;
        while (xi < nx && byQ[xi]->qi == i)
            xi++;
        size_t i2 = (i + 1) % n;
        /* inside at Q's corner i: Q enters the plan where the active edge leaves Q */
        int inside = x0 < xi ? byQ[x0]->enters : qinside[n + i];
        double ax = q[2 * i], ay = q[2 * i + 1];
        uint32_t va = NONE;
        if (!inside) {
            if (qvert[i] == NONE)
                qvert[i] = ag__skel_vertex(S, ax, ay, v);
            va = qvert[i];
        }
        for (size_t j = x0; j <= xi; j++) {
            int last = j == xi;
            double bx = last ? q[2 * i2] : byQ[j]->x, by = last ? q[2 * i2 + 1] : byQ[j]->y;
            uint32_t vb;
            if (last) {
                if (!inside && qvert[i2] == NONE)
                    qvert[i2] = ag__skel_vertex(S, bx, by, v);
                vb = qvert[i2];
            } else {
                vb = byQ[j]->vert;
            }
            if (!inside) {
                uint32_t g = forced_edge(S, ax, ay, bx, by, v, st, sid);
                if (g == NONE)
                    goto out;
                ag__skel_seg(S, S->e[g].face, va, vb);
                ag__skel_seg(S, floor, vb, va);
                if (j == x0)
                    qout[i] = g;
                else
                    byQ[j - 1]->q_after = g;
                if (last)
                    qin[i2] = g;
                else
                    byQ[j]->q_before = g;
            }
            ax = bx;
            ay = by;
            va = vb;
            inside = !inside;
        }
    }
    /* the new corners: at the crossings and at Q's corners outside the plan */
    size_t first = S->ntouched;
    for (size_t i = 0; i < nx && S->st == AG_OK; i++) {
        xing *x = &X[i];
        uint32_t in = x->enters ? x->p_before : x->q_before;
        uint32_t out = x->enters ? x->q_after : x->p_after;
        if (in == NONE || out == NONE) {
            ag_error_set(S->err, AG_ERR_INTERNAL, 0, "forced step %zu: inconsistent crossing at "
                         "(%.6f, %.6f)", k, x->x + S->ox, x->y + S->oy);
            ag__skel_fail(S, AG_ERR_INTERNAL);
            goto out;
        }
        ag__skel_add_corner(S, in, out, x->x, x->y, v, x->vert);
    }
    for (size_t i = 0; i < n && S->st == AG_OK; i++)
        if (qin[i] != NONE && qout[i] != NONE)
            ag__skel_add_corner(S, qin[i], qout[i], q[2 * i], q[2 * i + 1], v, qvert[i]);
    size_t last = S->ntouched;
    for (size_t i = first; i < last && S->st == AG_OK; i++)
        ag__skel_settle(S, S->touched[i]);
    S->stats.steps++;
    goto out;
skip:
    S->stats.steps_skipped++;
out:
    free(q);
    free(X);
    free(byE);
    free(byQ);
    free(cin);
    free(cvert);
    free(qin);
    free(qout);
    free(qvert);
    free(qinside);
}
