/* Anchors located on the active plan, and the flat cap that closes what is left. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skel.h"

/* --- anchors ----------------------------------------------------------------------------- */

uint32_t ag__skel_anchor_point(sk *S, const ag_anchor *a, double z, double *px, double *py)
{
    if (a->loop < 0 || (size_t)a->loop >= S->plan->nloops || a->edge < 0 ||
        (size_t)a->edge >= S->plan->loops[a->loop].n)
        return NONE;
    const ag_plan_loop *lp = &S->plan->loops[a->loop];
    size_t i = (size_t)a->edge, j = (i + 1) % lp->n;
    double bx = lp->xy[2 * i] - S->ox, by = lp->xy[2 * i + 1] - S->oy;
    double ex = lp->xy[2 * j] - S->ox, ey = lp->xy[2 * j + 1] - S->oy;
    double len = hypot(ex - bx, ey - by), dx = (ex - bx) / len, dy = (ey - by) / len;
    /* the pieces of this edge in the active plan, as parameters along its direction */
    double lo = INFINITY, hi = -INFINITY;
    for (size_t q = 0; q < S->nlive_e; q++) {
        const sk_edge *e = &S->e[S->live_e[q]];
        if (!e->alive || e->step || e->loop != a->loop || e->edge != a->edge)
            continue;
        double ax, ay, cx, cy;
        ag__skel_cpos(&S->c[e->start], z, &ax, &ay);
        ag__skel_cpos(&S->c[e->end], z, &cx, &cy);
        lo = fmin(lo, dx * (ax - bx) + dy * (ay - by));
        hi = fmax(hi, dx * (cx - bx) + dy * (cy - by));
    }
    if (!(hi > lo))
        return NONE;
    double t = a->absolute ? a->along : lo + a->along * (hi - lo);
    for (size_t q = 0; q < S->nlive_e; q++) {
        uint32_t id = S->live_e[q];
        const sk_edge *e = &S->e[id];
        if (!e->alive || e->step || e->loop != a->loop || e->edge != a->edge)
            continue;
        double ax, ay, cx, cy;
        ag__skel_cpos(&S->c[e->start], z, &ax, &ay);
        ag__skel_cpos(&S->c[e->end], z, &cx, &cy);
        double t0 = dx * (ax - bx) + dy * (ay - by), t1 = dx * (cx - bx) + dy * (cy - by);
        if (t < t0 - S->d3 || t > t1 + S->d3)
            continue;
        /* the point on the edge's line at this height */
        double off = e->c + e->s * z - (e->nx * bx + e->ny * by);
        *px = bx + t * dx + off * e->nx;
        *py = by + t * dy + off * e->ny;
        return id;
    }
    return NONE;
}

void ag__skel_locate_anchor(sk *S, ag_anchor *a, double z)
{
    double x, y;
    uint32_t id = ag__skel_anchor_point(S, a, z, &x, &y);
    if (id == NONE)
        return;
    const sk_edge *e = &S->e[id];
    a->found = 1;
    a->pos[0] = x + S->ox;
    a->pos[1] = y + S->oy;
    a->pos[2] = ag__skel_real_z(S, z);
    /* the face's outward normal: the plane n.p - s z = c, pointing away from inside */
    double nl = sqrt(1 + e->s * e->s);
    a->normal[0] = -e->nx / nl;
    a->normal[1] = -e->ny / nl;
    a->normal[2] = e->s / nl;
    a->face = (int32_t)e->face;
    a->tangent[0] = ag__skel_edx(e);
    a->tangent[1] = ag__skel_edy(e);
    a->tangent[2] = 0;
}

/* --- the cap ----------------------------------------------------------------------------- */

void ag__skel_cap(sk *S, double z)
{
    ag__skel_compact_live(S);
    if (!S->nlive_e)
        return;
    S->stats.capped = 1;
    ag_shell_face f = {AG_SHELL_FACE_CAP, -1, -1, -1, -1, 0, 0};
    uint32_t face = 0;
    if (ag_shell_add_face(S->shell, &f, &face) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    uint32_t *verts = calloc(S->nc ? S->nc : 1, sizeof *verts);
    if (!verts) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < S->nlive_c; i++) {
        uint32_t k = S->live_c[i];
        double x, y;
        ag__skel_cpos(&S->c[k], z, &x, &y);
        verts[k] = ag__skel_vertex(S, x, y, z);
        ag__skel_retire(S, k, verts[k]);
    }
    for (size_t i = 0; i < S->nlive_e; i++) {
        sk_edge *e = &S->e[S->live_e[i]];
        ag__skel_seg(S, e->face, verts[e->end], verts[e->start]);
        ag__skel_seg(S, face, verts[e->start], verts[e->end]);
        e->alive = 0;
    }
    free(verts);
}
