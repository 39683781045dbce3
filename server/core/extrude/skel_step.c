/* Plan edits grown as natural steps: a small protrusion or recess seeded into the active
 * plan that grows to its size over a flat interval. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skel.h"

#define STEP_SEED 1e-3 /* side of the protrusion a natural step grows from */

uint32_t ag__skel_make_edge(sk *S, double ax, double ay, double bx, double by, double slope, double z,
                          int32_t step, int32_t profile, int growing)
{
    uint32_t id = ag__skel_add_edge(S);
    if (id == NONE)
        return NONE;
    sk_edge *e = &S->e[id];
    double len = hypot(bx - ax, by - ay);
    e->nx = -(by - ay) / len;
    e->ny = (bx - ax) / len;
    e->s = slope;
    e->c = e->nx * ax + e->ny * ay - slope * z;
    e->loop = -1;
    e->edge = step - 1;
    e->profile = profile;
    e->seg = 0;
    e->step = step;
    e->clock = step;
    e->growing = (uint8_t)growing;
    e->face = ag__skel_new_face(S, e);
    return id;
}

/* At the start of a flat interval: a tiny protrusion (or recess) is put into the active
 * edge at each natural step's anchor; during the interval it grows to the step's width
 * and depth while the other edges wait, so it meets the rest of the plan through the
 * ordinary events and cannot make the plan self-intersect. */
void ag__skel_insert_steps(sk *S, double v)
{
    const ag_plan *P = S->plan;
    for (size_t k = 0; k < P->nsteps && S->st == AG_OK; k++) {
        const ag_plan_step *st = &P->steps[k];
        if (st->npoints)
            continue; /* forced: see forced_step */
        size_t fk = 0;
        while (fk < S->nflat && S->flat_h[fk] != st->at.z)
            fk++;
        if (fk == S->nflat || fabs(S->flat_h[fk] + (double)fk - v) > 1e-9)
            continue;
        ag__skel_compact_live(S);
        double x, y;
        uint32_t ei = ag__skel_anchor_point(S, &st->at, v, &x, &y);
        if (ei == NONE) {
            S->stats.steps_skipped++;
            continue;
        }
        sk_edge *e = &S->e[ei];
        double dx = ag__skel_edx(e), dy = ag__skel_edy(e), h = STEP_SEED / 2;
        double sx, sy, ex, ey;
        ag__skel_cpos(&S->c[e->start], v, &sx, &sy);
        ag__skel_cpos(&S->c[e->end], v, &ex, &ey);
        double t = dx * (x - sx) + dy * (y - sy), len = dx * (ex - sx) + dy * (ey - sy);
        if (t - h < 10 * S->d3 || t + h > len - 10 * S->d3) {
            S->stats.steps_skipped++;
            continue;
        }
        double out = st->depth > 0 ? -1 : 1; /* protrusion: outwards (-n) */
        double ax = x - h * dx, ay = y - h * dy, bx = x + h * dx, by = y + h * dy;
        double a2x = ax + out * STEP_SEED * e->nx, a2y = ay + out * STEP_SEED * e->ny;
        double b2x = bx + out * STEP_SEED * e->nx, b2y = by + out * STEP_SEED * e->ny;
        /* growth over the unit interval: sides to the width, front to the depth; a
         * protrusion's edges move outwards (negative slope), a recess's inwards */
        double side = (st->width / 2 - h) * (st->depth > 0 ? -1 : 1);
        double front = (fabs(st->depth) - STEP_SEED) * (st->depth > 0 ? -1 : 1);
        int32_t sid = (int32_t)k + 1;
        uint32_t e2 = ag__skel_add_edge(S);
        uint32_t s1 = ag__skel_make_edge(S, ax, ay, a2x, a2y, side, v, sid, st->profile, 1);
        uint32_t f = ag__skel_make_edge(S, a2x, a2y, b2x, b2y, front, v, sid, st->profile, 1);
        uint32_t s2 = ag__skel_make_edge(S, b2x, b2y, bx, by, side, v, sid, st->profile, 1);
        if (e2 == NONE || s1 == NONE || f == NONE || s2 == NONE)
            return;
        e = &S->e[ei];
        sk_edge *g = &S->e[e2];
        *g = *e;
        g->ver = 0;
        g->alive = 1;
        g->end = e->end;
        S->c[e->end].in = e2;
        uint32_t va = ag__skel_vertex(S, ax, ay, v), va2 = ag__skel_vertex(S, a2x, a2y, v);
        uint32_t vb2 = ag__skel_vertex(S, b2x, b2y, v), vb = ag__skel_vertex(S, bx, by, v);
        ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, (int32_t)k, st->profile, -1, 0, 0};
        uint32_t floor = 0;
        if (ag_shell_add_face(S->shell, &ff, &floor) != AG_OK) {
            ag__skel_fail(S, AG_ERR_NOMEM);
            return;
        }
        ag__skel_seg(S, e->face, vb, va); /* the piece of the edge the step replaces */
        ag__skel_seg(S, floor, va, vb);
        ag__skel_seg(S, floor, vb, vb2);
        ag__skel_seg(S, floor, vb2, va2);
        ag__skel_seg(S, floor, va2, va);
        ag__skel_seg(S, S->e[s1].face, va, va2);
        ag__skel_seg(S, S->e[f].face, va2, vb2);
        ag__skel_seg(S, S->e[s2].face, vb2, vb);
        size_t first = S->ntouched;
        ag__skel_add_corner(S, ei, s1, ax, ay, v, va);
        ag__skel_add_corner(S, s1, f, a2x, a2y, v, va2);
        ag__skel_add_corner(S, f, s2, b2x, b2y, v, vb2);
        ag__skel_add_corner(S, s2, e2, bx, by, v, vb);
        size_t last = S->ntouched;
        for (size_t i = first; i < last && S->st == AG_OK; i++)
            ag__skel_settle(S, S->touched[i]);
        S->stats.steps++;
    }
}
