/* Intersection events: computed from the corners' motion, scheduled for the corners and
 * edges an event changed, and clustered (delta1 in height, delta2 in plan, §4.4) into
 * generalized intersections. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "../base/tolerance.h"

static void edge_event(sk *S, uint32_t ei)
{
    const sk_edge *e = &S->e[ei];
    if (!e->alive || e->start == NONE || e->end == NONE)
        return;
    const sk_corner *a = &S->c[e->start], *b = &S->c[e->end];
    if (!a->settled || !b->settled || !a->alive || !b->alive)
        return;
    double z0 = fmax(fmax(a->z, b->z), S->zcur);
    double ax, ay, bx, by;
    ag__skel_cpos(a, z0, &ax, &ay);
    ag__skel_cpos(b, z0, &bx, &by);
    double dx = ag__skel_edx(e), dy = ag__skel_edy(e);
    double len = dx * (bx - ax) + dy * (by - ay);
    double rate = dx * (b->vx - a->vx) + dy * (b->vy - a->vy);
    if (!(rate < -1e-12))
        return;
    double dz = len / -rate;
    if (dz < 0)
        dz = 0;
    ag_event ev = {0};
    ev.type = AG_EVENT_EDGE;
    ev.z = z0 + dz;
    ag__skel_cpos(a, ev.z, &ax, &ay);
    ag__skel_cpos(b, ev.z, &bx, &by);
    ev.x = (ax + bx) / 2;
    ev.y = (ay + by) / 2;
    /* where the planes of the edge and its two neighbours meet: exact for fast corners */
    uint32_t p = a->in, q = b->out;
    double px, py, pz;
    if (fmax(a->cond, b->cond) > AG_EXTRUDE_MEET_COND && p != ei && q != ei && p != q &&
        ag__skel_meet3(S, p, ei, q, &px, &py, &pz) &&
        pz >= z0 && fabs(pz - ev.z) <= AG_EXTRUDE_MEET_AGREE * S->size) {
        ev.x = px;
        ev.y = py;
        ev.z = pz;
    }
    ev.a = ei;
    ev.ver = e->ver;
    if (isfinite(ev.z))
        ag__skel_push(S, &ev);
}

/* Is edge fi the one after (or before) the corner's neighbouring edge, and that edge of
 * no length at height z? Then the corner merely starts on fi's line where a side edge
 * was put in (an offset event's cut), which is no split. */
static int zero_gap(const sk *S, uint32_t k, uint32_t fi, double z)
{
    const sk_corner *c = &S->c[k];
    const sk_edge *o = &S->e[c->out], *i = &S->e[c->in];
    const sk_edge *g = NULL;
    if (o->end != NONE && S->c[o->end].out == fi)
        g = o;
    else if (i->start != NONE && S->c[i->start].in == fi)
        g = i;
    if (!g || g->start == NONE || g->end == NONE)
        return 0;
    double ax, ay, bx, by;
    ag__skel_cpos(&S->c[g->start], z, &ax, &ay);
    ag__skel_cpos(&S->c[g->end], z, &bx, &by);
    return hypot(bx - ax, by - ay) <= S->d2;
}

/* Where corner k would hit edge fi, if it does: 1 with ev filled. */
static int split_event(sk *S, uint32_t k, uint32_t fi, ag_event *out)
{
    const sk_corner *c = &S->c[k];
    const sk_edge *f = &S->e[fi];
    /* a convex corner whose edges move inwards (or wait) opens towards any edge moving in
     * on it: that edge meets the corner's sides, or its own corners meet them, first */
    if (c->passive && f->s >= 0)
        return 0;
    if (!c->alive || !c->settled || !f->alive || fi == c->in || fi == c->out)
        return 0;
    if (f->start == NONE || f->end == NONE)
        return 0;
    const sk_corner *fa = &S->c[f->start], *fb = &S->c[f->end];
    if (!fa->settled || !fb->settled)
        return 0;
    double z0 = fmax(c->z, S->zcur), px, py;
    ag__skel_cpos(c, z0, &px, &py);
    double dist = f->nx * px + f->ny * py - (f->c + f->s * z0);
    double closing = f->s - (f->nx * c->vx + f->ny * c->vy);
    if (dist < -S->d2 && f->s < 0 && closing < -AG_EXTRUDE_MIN_RATE) {
        /* an edge moving outwards (a soffit) meets a part of the plan growing towards it
         * from outside: parts of a growing plan collide from the outside */
        dist = -dist;
        closing = -closing;
    } else if (!(closing > AG_EXTRUDE_MIN_RATE) || dist < -S->d2) {
        return 0;
    }
    double dz = dist > 0 ? dist / closing : 0;
    if (dz <= 0 && zero_gap(S, k, fi, z0))
        return 0;
    double z = z0 + dz;
    if (!isfinite(z))
        return 0;
    double x, y, ax, ay, bx, by;
    ag__skel_cpos(c, z, &x, &y);
    /* the point where the corner's two planes meet the edge's: exact for fast corners */
    double mx, my, mz;
    if (c->cond > AG_EXTRUDE_MEET_COND && ag__skel_meet3(S, c->in, c->out, fi, &mx, &my, &mz) &&
        mz >= z0 &&
        fabs(mz - z) <= AG_EXTRUDE_MEET_AGREE * S->size) {
        x = mx;
        y = my;
        z = mz;
    }
    ag__skel_cpos(fa, z, &ax, &ay);
    ag__skel_cpos(fb, z, &bx, &by);
    double dx = ag__skel_edx(f), dy = ag__skel_edy(f);
    double len = dx * (bx - ax) + dy * (by - ay);
    double t = dx * (x - ax) + dy * (y - ay);
    /* an edge that has shrunk to a point by then is handled by its edge event */
    if (len <= S->d3 || t < -S->d3 || t > len + S->d3)
        return 0;
    memset(out, 0, sizeof *out);
    out->type = AG_EVENT_SPLIT;
    out->z = z;
    out->x = x;
    out->y = y;
    out->a = k;
    out->b = fi;
    out->ver = f->ver;
    return 1;
}

/* Schedules corner k's next hits on edges: of all the live edges it would hit, only the
 * first (and any within delta1 of it, one vertex event's other edges) go into the queue,
 * so the queue holds a few events per corner, not one per corner and edge (a 20,000-corner
 * plan would hold hundreds of millions). When that event turns out stale, the corner is
 * scheduled again (ag__skel_event_dropped). */
static void schedule_corner(sk *S, uint32_t k, double after)
{
    sk_corner *c = &S->c[k];
    sk_scratch *W = &S->W;
    size_t n = 0;
    double best = INFINITY;
    for (size_t q = 0; q < S->nlive_e && S->st == AG_OK; q++) {
        if (c->passive && S->e[S->live_e[q]].s >= 0)
            continue;
        ag_event ev;
        if (!split_event(S, k, S->live_e[q], &ev) || ev.z > best + S->d1 || ev.z <= after)
            continue;
        if (ag_array_reserve((void **)&W->cand, &W->cap_cand, n + 1, sizeof *W->cand) != AG_OK) {
            ag__skel_fail(S, AG_ERR_NOMEM);
            return;
        }
        W->cand[n++] = ev;
        best = fmin(best, ev.z);
    }
    ag__skel_work(S, S->nlive_e);
    S->c[k].next_split = best;
    for (size_t i = 0; i < n; i++)
        if (W->cand[i].z <= best + S->d1)
            ag__skel_push(S, &W->cand[i]);
}

void ag__skel_event_dropped(sk *S, const ag_event *ev)
{
    if (ev->type != AG_EVENT_SPLIT)
        return;
    const sk_corner *c = &S->c[ev->a];
    /* the corner's first hit went stale: find its next one (later ones were never queued) */
    if (c->alive && c->settled && ev->z <= c->next_split + S->d1)
        schedule_corner(S, ev->a, -INFINITY);
}

void ag__skel_schedule_corner_after(sk *S, uint32_t k, double after)
{
    ag__skel_compact_live(S);
    schedule_corner(S, k, after);
}

void ag__skel_schedule_touched(sk *S)
{
    if (S->st != AG_OK)
        return;
    ag__skel_compact_live(S);
    /* the touched corners' own first hits */
    for (size_t i = 0; i < S->ntouched && S->st == AG_OK; i++)
        if (S->c[S->touched[i]].alive)
            schedule_corner(S, S->touched[i], -INFINITY);
    /* the changed edges: their collapse, and hits on them earlier than a corner's first */
    uint32_t mark = ++S->stamp;
    for (size_t i = 0; i < S->ntouched && S->st == AG_OK; i++) {
        sk_corner *c = &S->c[S->touched[i]];
        if (!c->alive)
            continue;
        uint32_t es[2] = {c->in, c->out};
        for (int j = 0; j < 2; j++) {
            sk_edge *e = &S->e[es[j]];
            if (!e->alive || e->mark == mark)
                continue;
            e->mark = mark; /* both its corners may have been touched */
            edge_event(S, es[j]);
            for (size_t q = 0; q < S->nlive_c; q++) {
                uint32_t k = S->live_c[q];
                ag_event ev;
                if (split_event(S, k, es[j], &ev) && ev.z <= S->c[k].next_split + S->d1) {
                    ag__skel_push(S, &ev);
                    S->c[k].next_split = fmin(S->c[k].next_split, ev.z);
                }
            }
            ag__skel_work(S, S->nlive_c);
        }
    }
    S->ntouched = 0;
}

/* Plan speed of the fastest corner an intersection event moves (m per unit of height). */
/* Plan speed of the fastest corner an intersection event moves (m per unit of height),
 * and how far off its height may be: a corner between nearly parallel edges (an angle
 * of sin = 1 / cond) has its velocity, hence its position, known only to about
 * cond * eps * height, and the event's height with it. */
static void event_speed(const sk *S, const ag_event *ev, double *speed, double *sigma)
{
    uint32_t ks[2] = {ev->a, NONE};
    if (ev->type == AG_EVENT_EDGE) {
        ks[0] = S->e[ev->a].start;
        ks[1] = S->e[ev->a].end;
    }
    double v = 0, cond = 1;
    for (int j = 0; j < 2; j++)
        if (ks[j] != NONE) {
            v = fmax(v, hypot(S->c[ks[j]].vx, S->c[ks[j]].vy));
            cond = fmax(cond, S->c[ks[j]].cond);
        }
    *speed = v;
    *sigma = AG_EXTRUDE_HEIGHT_ULPS * DBL_EPSILON * (fabs(ev->z) + S->size) * cond;
}

int ag__skel_event_valid(sk *S, const ag_event *ev)
{
    if (ev->type == AG_EVENT_EDGE)
        return S->e[ev->a].alive && S->e[ev->a].ver == ev->ver;
    if (ev->type == AG_EVENT_SPLIT)
        return S->c[ev->a].alive && S->e[ev->b].alive && S->e[ev->b].ver == ev->ver;
    return 1;
}

/* Two events of one batch (within delta1 in height) are one point when their plan points
 * are within the cluster radius and their corners move less than that radius between
 * their heights: a fast corner (between nearly parallel edges) crosses metres within
 * delta1, so two events at one spot but apart in height are two events, with others
 * (elsewhere along its way) between them. */
static int same_point(const sk *S, const ag_event *a, const ag_event *b, const double *sa,
                      const double *sb)
{
    double tol = AG_EXTRUDE_CLUSTER_POINTS * S->d2, dz = fabs(a->z - b->z);
    /* apart in height by less than the corners move within the radius, or by less than
     * the heights are known (then they are one event computed twice) */
    int same_height = fmax(sa[0] + sb[0], 1) * dz <= tol || dz <= sa[1] + sb[1];
    return same_height && fabs(a->y - b->y) <= tol && hypot(a->x - b->x, a->y - b->y) <= tol;
}

void ag__skel_next_cluster(sk *S, const ag_event *ev0)
{
    sk_scratch *W = &S->W;
    /* the batch: ev0 and every valid intersection event within delta1 above it */
    size_t nb = 0;
    if (ag_array_reserve((void **)&W->batch, &W->cap_batch, 1, sizeof *W->batch) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    W->batch[nb++] = *ev0;
    const ag_event *top;
    while ((top = ag_eventq_peek(&S->q)) && top->z <= ev0->z + S->d1 &&
           (top->type == AG_EVENT_EDGE || top->type == AG_EVENT_SPLIT)) {
        ag_event nx;
        if (!ag__skel_pop(S, &nx))
            return;
        if (!ag__skel_event_valid(S, &nx)) {
            ag__skel_event_dropped(S, &nx);
            continue;
        }
        if (ag_array_reserve((void **)&W->batch, &W->cap_batch, nb + 1, sizeof *W->batch) != AG_OK ||
            ag_array_reserve((void **)&W->uf, &W->cap_uf, nb + 1, sizeof *W->uf) != AG_OK) {
            ag__skel_fail(S, AG_ERR_NOMEM);
            return;
        }
        W->batch[nb++] = nx;
    }
    if (ag_array_reserve((void **)&W->uf, &W->cap_uf, nb, sizeof *W->uf) != AG_OK ||
        ag_array_reserve((void **)&W->speed, &W->cap_speed, 2 * nb, sizeof *W->speed) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    ag_event *batch = W->batch;
    /* ev0's cluster: the events whose points chain to its point (uf marks members) */
    uint32_t *in = W->uf;
    double *sp = W->speed;
    for (size_t i = 0; i < nb; i++) {
        in[i] = i == 0;
        event_speed(S, &batch[i], &sp[2 * i], &sp[2 * i + 1]);
    }
    for (int grew = 1; grew;) {
        grew = 0;
        for (size_t i = 0; i < nb; i++) {
            if (!in[i])
                continue;
            for (size_t j = 1; j < nb; j++)
                if (!in[j] && same_point(S, &batch[i], &batch[j], &sp[2 * i], &sp[2 * j])) {
                    in[j] = 1;
                    grew = 1;
                }
        }
    }
    size_t ng = 0;
    for (size_t i = 0; i < nb; i++) {
        if (in[i])
            batch[ng++] = batch[i];
        else
            ag__skel_push(S, &batch[i]); /* a later cluster: after this one's consequences */
    }
    ag__skel_intersection(S, batch, ng);
}
