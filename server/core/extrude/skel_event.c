/* Intersection events: computed from the corners' motion, scheduled for the corners and
 * edges an event changed, and clustered (delta1 in height, delta2 in plan, §4.4) into
 * generalized intersections. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skel.h"

#include "tolerance.h"

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

static void split_event(sk *S, uint32_t k, uint32_t fi)
{
    const sk_corner *c = &S->c[k];
    const sk_edge *f = &S->e[fi];
    if (!c->alive || !c->settled || !f->alive || fi == c->in || fi == c->out)
        return;
    if (f->start == NONE || f->end == NONE)
        return;
    const sk_corner *fa = &S->c[f->start], *fb = &S->c[f->end];
    if (!fa->settled || !fb->settled)
        return;
    double z0 = fmax(c->z, S->zcur), px, py;
    ag__skel_cpos(c, z0, &px, &py);
    double dist = f->nx * px + f->ny * py - (f->c + f->s * z0);
    double closing = f->s - (f->nx * c->vx + f->ny * c->vy);
    if (dist < -S->d2 && f->s < 0 && closing < -1e-12) {
        /* an edge moving outwards (a soffit) meets a part of the plan growing towards it
         * from outside: parts of a growing plan collide from the outside */
        dist = -dist;
        closing = -closing;
    } else if (!(closing > 1e-12) || dist < -S->d2) {
        return;
    }
    double dz = dist > 0 ? dist / closing : 0;
    if (dz <= 0 && zero_gap(S, k, fi, z0))
        return;
    double z = z0 + dz;
    if (!isfinite(z))
        return;
    double x, y, ax, ay, bx, by;
    ag__skel_cpos(c, z, &x, &y);
    ag__skel_cpos(fa, z, &ax, &ay);
    ag__skel_cpos(fb, z, &bx, &by);
    double dx = ag__skel_edx(f), dy = ag__skel_edy(f);
    double len = dx * (bx - ax) + dy * (by - ay);
    double t = dx * (x - ax) + dy * (y - ay);
    /* an edge that has shrunk to a point by then is handled by its edge event */
    if (len <= S->d3 || t < -S->d3 || t > len + S->d3)
        return;
    ag_event ev = {0};
    ev.type = AG_EVENT_SPLIT;
    ev.z = z;
    ev.x = x;
    ev.y = y;
    ev.a = k;
    ev.b = fi;
    ev.ver = f->ver;
    ag__skel_push(S, &ev);
}
void ag__skel_schedule_touched(sk *S)
{
    if (S->st != AG_OK)
        return;
    ag__skel_compact_live(S);
    S->stamp++;
    for (size_t i = 0; i < S->ntouched; i++) {
        sk_corner *c = &S->c[S->touched[i]];
        if (!c->alive)
            continue;
        uint32_t es[2] = {c->in, c->out};
        for (int j = 0; j < 2; j++) {
            sk_edge *e = &S->e[es[j]];
            if (!e->alive)
                continue;
            /* the edge changed: its collapse and every corner's hit on it are new */
            edge_event(S, es[j]);
            for (size_t q = 0; q < S->nlive_c; q++)
                split_event(S, S->live_c[q], es[j]);
        }
        for (size_t q = 0; q < S->nlive_e; q++)
            split_event(S, S->touched[i], S->live_e[q]);
    }
    S->ntouched = 0;
}

static int cmp_event_x(const void *a, const void *b)
{
    double x = ((const ag_event *)a)->x, y = ((const ag_event *)b)->x;
    return x < y ? -1 : x > y;
}

typedef struct {
    double z;
    uint32_t root, i;
} gsort;

static int cmp_gsort(const void *a, const void *b)
{
    const gsort *x = a, *y = b;
    if (x->z != y->z)
        return x->z < y->z ? -1 : 1;
    if (x->root != y->root)
        return x->root < y->root ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static uint32_t uf_find(uint32_t *p, uint32_t x)
{
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

/* Plan speed of the fastest corner an intersection event moves (m per unit of height). */
static double event_speed(const sk *S, const ag_event *ev)
{
    uint32_t ks[2] = {ev->a, NONE};
    if (ev->type == AG_EVENT_EDGE) {
        ks[0] = S->e[ev->a].start;
        ks[1] = S->e[ev->a].end;
    }
    double v = 0;
    for (int j = 0; j < 2; j++)
        if (ks[j] != NONE)
            v = fmax(v, hypot(S->c[ks[j]].vx, S->c[ks[j]].vy));
    return v;
}

int ag__skel_event_valid(sk *S, const ag_event *ev)
{
    if (ev->type == AG_EVENT_EDGE)
        return S->e[ev->a].alive && S->e[ev->a].ver == ev->ver;
    if (ev->type == AG_EVENT_SPLIT)
        return S->c[ev->a].alive && S->e[ev->b].alive && S->e[ev->b].ver == ev->ver;
    return 1;
}

void ag__skel_intersections(sk *S, ag_event *batch, size_t nb)
{
    uint32_t *uf;
    /* cluster in plan: union of events closer than delta2 (sorted by x) */
    qsort(batch, nb, sizeof *batch, cmp_event_x);
    if (!ag__skel_grow((void **)&S->W.uf, &S->W.cap_uf, nb, sizeof *S->W.uf)) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    uf = S->W.uf;
    for (size_t i = 0; i < nb; i++)
        uf[i] = (uint32_t)i;
    double r = 10 * S->d2;
    /* events a little apart in height (within delta1) are compared where their points
     * would be at one height: a fast corner (nearly parallel edges) moves its point
     * by its speed times the height difference (bounded: 0.2 mm at building scale) */
    double *sp = malloc(nb * sizeof *sp), maxsp = 0, zlo = INFINITY, zhi = -INFINITY;
    if (!sp) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < nb; i++) {
        sp[i] = event_speed(S, &batch[i]);
        maxsp = fmax(maxsp, sp[i]);
        zlo = fmin(zlo, batch[i].z);
        zhi = fmax(zhi, batch[i].z);
    }
    double rmax = r + fmin(2 * maxsp * (zhi - zlo), 20 * S->d3);
    /* a window of 64 suffices: points of one cluster chain each other */
    for (size_t i = 0; i < nb; i++)
        for (size_t j = i + 1; j < nb && j < i + 64 && batch[j].x - batch[i].x <= rmax; j++) {
            double tol = r + fmin((sp[i] + sp[j]) * fabs(batch[j].z - batch[i].z), 20 * S->d3);
            if (fabs(batch[j].y - batch[i].y) <= tol &&
                hypot(batch[j].x - batch[i].x, batch[j].y - batch[i].y) <= tol) {
                uint32_t a = uf_find(uf, (uint32_t)i), b = uf_find(uf, (uint32_t)j);
                if (a != b)
                    uf[a > b ? a : b] = a < b ? a : b;
            }
        }
    free(sp);
    /* handle groups lowest first: order events by (group's lowest z, group) */
    gsort *gs = malloc(nb * sizeof *gs);
    double *gz = malloc(nb * sizeof *gz);
    ag_event *grp = malloc(nb * sizeof *grp);
    if (!gs || !gz || !grp) {
        free(gs);
        free(gz);
        free(grp);
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < nb; i++)
        gz[i] = INFINITY;
    for (size_t i = 0; i < nb; i++) {
        uint32_t rt = uf_find(uf, (uint32_t)i);
        if (batch[i].z < gz[rt])
            gz[rt] = batch[i].z;
    }
    for (size_t i = 0; i < nb; i++) {
        gs[i].root = uf_find(uf, (uint32_t)i);
        gs[i].z = gz[gs[i].root];
        gs[i].i = (uint32_t)i;
    }
    qsort(gs, nb, sizeof *gs, cmp_gsort);
    size_t first_new = S->ntouched;
    S->defer_settle = 1;
    for (size_t i = 0; i < nb && S->st == AG_OK;) {
        size_t j = i, ng = 0;
        while (j < nb && gs[j].root == gs[i].root)
            grp[ng++] = batch[gs[j++].i];
        ag__skel_intersection(S, grp, ng);
        i = j;
    }
    S->defer_settle = 0;
    for (size_t i = first_new; i < S->ntouched && S->st == AG_OK; i++)
        if (S->c[S->touched[i]].alive && !S->c[S->touched[i]].settled)
            ag__skel_settle(S, S->touched[i]);
    free(gs);
    free(gz);
    free(grp);
    ag__skel_schedule_touched(S);
}
