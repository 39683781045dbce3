/* Settling a new corner: its velocity from its two edges' planes; collinear neighbours
 * with different slopes merged by priority (§4.8), antiparallel ones (a ridge) zipped. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skel.h"

#include "../base/tolerance.h"

static int velocity(sk *S, sk_corner *c)
{
    const sk_edge *a = &S->e[c->in], *b = &S->e[c->out];
    double det = a->nx * b->ny - a->ny * b->nx;
    if (fabs(det) <= AG_EXTRUDE_PARALLEL)
        return 0;
    c->vx = (a->s * b->ny - b->s * a->ny) / det;
    c->vy = (a->nx * b->s - b->nx * a->s) / det;
    c->cond = 1 / fabs(det);
    /* Put the corner on its trajectory, the line where its two planes meet: the point of
     * that line nearest to where it was made (an event's point, which may be off the
     * planes by the cluster's spread). A corner between nearly parallel edges moves
     * fast; made a nanometre off its line, it would be off its planes and meet the next
     * edges at the wrong time. q is the line's point at the corner's height, t how much
     * higher the nearest point lies (nearest in plan and height). */
    double ca = a->c + a->s * c->z, cb = b->c + b->s * c->z;
    double qx = (ca * b->ny - cb * a->ny) / det, qy = (a->nx * cb - b->nx * ca) / det;
    double dx = qx - c->x, dy = qy - c->y, v2 = c->vx * c->vx + c->vy * c->vy;
    double t = -(dx * c->vx + dy * c->vy) / (v2 + 1);
    if (isfinite(t) && hypot(dx + t * c->vx, dy + t * c->vy) + fabs(t) <= AG_EXTRUDE_ANCHOR * S->d3) {
        c->x = qx + t * c->vx;
        c->y = qy + t * c->vy;
        c->z += t;
    }
    return 1;
}

static void merge(sk *S, uint32_t k)
{
    sk_corner *c = &S->c[k];
    uint32_t ein = c->in, eout = c->out;
    int min_vol = S->plan->priority == AG_PRIORITY_MIN_VOLUME;
    double sin_ = S->e[ein].s, sout = S->e[eout].s;
    /* the tags of the segments the two edges are on now */
    int32_t pin = ag_profile_priority(&S->plan->profiles[S->e[ein].profile], S->e[ein].seg);
    int32_t pout = ag_profile_priority(&S->plan->profiles[S->e[eout].profile], S->e[eout].seg);
    int in_wins = pin != pout ? pin > pout : min_vol ? sin_ > sout : sin_ < sout;
    double z = c->z;
    uint32_t vl = c->vert;
    S->stats.merges++;
    c->alive = 0; /* made and retired at the same point: no arc */
    if (in_wins) {
        uint32_t loser = eout, m = S->e[loser].end;
        uint32_t x_out = S->c[m].out;
        double px, py;
        ag__skel_cpos(&S->c[m], z, &px, &py);
        uint32_t vm = ag__skel_vertex(S, px, py, z);
        ag__skel_retire(S, m, vm);
        ag__skel_seg(S, S->e[loser].face, vm, vl);
        ag__skel_seg(S, S->e[ein].face, vl, vm);
        ag__skel_kill_edge(S, loser);
        if (x_out == loser || x_out == ein) {
            ag__skel_kill_edge(S, ein); /* the loop was only these two edges */
            return;
        }
        uint32_t k2 = ag__skel_add_corner(S, ein, x_out, px, py, z, vm);
        if (k2 != NONE)
            ag__skel_settle(S, k2);
    } else {
        uint32_t loser = ein, m = S->e[loser].start;
        uint32_t y_in = S->c[m].in;
        double px, py;
        ag__skel_cpos(&S->c[m], z, &px, &py);
        uint32_t vm = ag__skel_vertex(S, px, py, z);
        ag__skel_retire(S, m, vm);
        ag__skel_seg(S, S->e[loser].face, vl, vm);
        ag__skel_seg(S, S->e[eout].face, vm, vl);
        ag__skel_kill_edge(S, loser);
        if (y_in == loser || y_in == eout) {
            ag__skel_kill_edge(S, eout);
            return;
        }
        uint32_t k2 = ag__skel_add_corner(S, y_in, eout, px, py, z, vm);
        if (k2 != NONE)
            ag__skel_settle(S, k2);
    }
}

static void zip(sk *S, uint32_t k)
{
    sk_corner *c = &S->c[k];
    uint32_t B = c->in, A = c->out;
    uint32_t cA = S->e[A].end, cB = S->e[B].start;
    double z = c->z;
    uint32_t vl = c->vert;
    S->stats.zips++;
    c->alive = 0;
    double pax, pay, pbx, pby;
    ag__skel_cpos(&S->c[cA], z, &pax, &pay);
    ag__skel_cpos(&S->c[cB], z, &pbx, &pby);
    if (cA == cB) {
        uint32_t vp = ag__skel_vertex(S, pax, pay, z);
        ag__skel_retire(S, cA, vp);
        ag__skel_seg(S, S->e[A].face, vp, vl);
        ag__skel_seg(S, S->e[B].face, vl, vp);
        ag__skel_kill_edge(S, A);
        ag__skel_kill_edge(S, B);
        return;
    }
    double dx = ag__skel_edx(&S->e[A]), dy = ag__skel_edy(&S->e[A]);
    double lenA = dx * (pax - c->x) + dy * (pay - c->y);
    double lenB = dx * (pbx - c->x) + dy * (pby - c->y);
    if (fabs(lenA - lenB) <= S->d2 * 10) {
        double px = (pax + pbx) / 2, py = (pay + pby) / 2;
        uint32_t vp = ag__skel_vertex(S, px, py, z);
        uint32_t yin = S->c[cB].in, xout = S->c[cA].out;
        ag__skel_retire(S, cA, vp);
        ag__skel_retire(S, cB, vp);
        ag__skel_seg(S, S->e[A].face, vp, vl);
        ag__skel_seg(S, S->e[B].face, vl, vp);
        ag__skel_kill_edge(S, A);
        ag__skel_kill_edge(S, B);
        if (yin == xout) {
            /* a single edge is left between the two: it has shrunk to this point */
            ag__skel_kill_edge(S, yin);
            return;
        }
        uint32_t k2 = ag__skel_add_corner(S, yin, xout, px, py, z, vp);
        if (k2 != NONE)
            ag__skel_settle(S, k2);
    } else if (lenA < lenB) {
        uint32_t vp = ag__skel_vertex(S, pax, pay, z);
        uint32_t xout = S->c[cA].out;
        ag__skel_retire(S, cA, vp);
        ag__skel_seg(S, S->e[A].face, vp, vl);
        ag__skel_seg(S, S->e[B].face, vl, vp);
        ag__skel_kill_edge(S, A);
        uint32_t k2 = ag__skel_add_corner(S, B, xout, pax, pay, z, vp);
        if (k2 != NONE)
            ag__skel_settle(S, k2);
    } else {
        uint32_t vp = ag__skel_vertex(S, pbx, pby, z);
        uint32_t yin = S->c[cB].in;
        ag__skel_retire(S, cB, vp);
        ag__skel_seg(S, S->e[A].face, vp, vl);
        ag__skel_seg(S, S->e[B].face, vl, vp);
        ag__skel_kill_edge(S, B);
        uint32_t k2 = ag__skel_add_corner(S, yin, A, pbx, pby, z, vp);
        if (k2 != NONE)
            ag__skel_settle(S, k2);
    }
}

void ag__skel_settle(sk *S, uint32_t k)
{
    ag__skel_settle_or_defer(S, k, 0);
}

int ag__skel_settle_or_defer(sk *S, uint32_t k, int defer)
{
    if (S->st != AG_OK)
        return 1;
    sk_corner *c = &S->c[k];
    if (!c->alive)
        return 1;
    if (c->in == c->out) {
        /* a loop of one edge: it has closed */
        ag__skel_kill_edge(S, c->in);
        c->alive = 0;
        return 1;
    }
    const sk_edge *a = &S->e[c->in], *b = &S->e[c->out];
    c->passive = 0;
    if (velocity(S, c)) {
        c->settled = 1;
        /* convex (the edges turn left: their normals' cross product is positive, and not
         * near zero here) with both edges moving in or waiting */
        c->passive = a->nx * b->ny - a->ny * b->nx > 0 && a->s >= 0 && b->s >= 0;
        return 1;
    }
    double dot = a->nx * b->nx + a->ny * b->ny;
    if (dot > 0 && fabs(a->s - b->s) <= AG_EXTRUDE_SAME_SLOPE) {
        /* collinear, same slope: the corner moves with the common plane */
        double nx = a->nx + b->nx, ny = a->ny + b->ny, l = hypot(nx, ny);
        c->vx = a->s * nx / l;
        c->vy = a->s * ny / l;
        c->cond = 1;
        c->settled = 1;
        return 1;
    }
    if (defer)
        return 0;
    if (dot > 0)
        merge(S, k);
    else
        zip(S, k);
    return 1;
}
