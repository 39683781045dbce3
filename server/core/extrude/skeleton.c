/* The sweep's driver: the initial active plan, the user events, the event loop. The parts
 * of the sweep are listed in skel.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "../base/tolerance.h"

/* Settles the corners the intersections of one height level left unsettled. */
static void settle_deferred(sk *S)
{
    S->track_made = 1;
    for (size_t i = 0; i < S->deferred.n && S->st == AG_OK; i++) {
        uint32_t k = S->deferred.arr[i];
        if (!S->c[k].alive || S->c[k].settled)
            continue;
        ag__skel_settle(S, k);
        /* its events are scheduled with the corners its settling made */
        if (S->c[k].alive &&
            ag_array_reserve((void **)&S->touched, &S->cap_touched, S->ntouched + 1,
                           sizeof *S->touched) != AG_OK)
            ag__skel_fail(S, AG_ERR_NOMEM);
        else if (S->c[k].alive)
            S->touched[S->ntouched++] = k;
    }
    S->deferred.n = 0;
    S->track_made = 0;
    ag__skel_schedule_touched(S);
}

ag_status ag_skeleton_build(const ag_plan *plan, double extent, const ag_skeleton_options *opt,
                            ag_shell **out, ag_skeleton_stats *stats, ag_error *err)
{
    *out = NULL;
    sk S;
    memset(&S, 0, sizeof S);
    S.plan = plan;
    S.err = err;
    S.no_winding_repair = opt && opt->no_winding_repair;
    ag_budget own;
    if (opt && opt->budget) {
        S.budget = opt->budget;
    } else {
        size_t corners = 0;
        for (size_t L = 0; L < plan->nloops; L++)
            corners += plan->loops[L].n;
        ag_budget_start(&own, NULL, corners);
        S.budget = &own;
    }
    size_t events0 = S.budget->events;
    /* the sweep runs in a frame at the plan's first corner: coordinates up to the extent */
    ag_extrude_tol tol = ag_extrude_tolerances(extent, extent);
    S.d1 = tol.height;
    S.d2 = tol.point;
    S.d3 = tol.along;
    S.size = tol.size;
    S.shell = ag_shell_create();
    if (!S.shell)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* local origin: the first corner */
    S.ox = plan->loops[0].xy[0];
    S.oy = plan->loops[0].xy[1];
    ag_shell_face ff = {AG_SHELL_FACE_FLOOR, -1, -1, -1, -1, 0, 0};
    uint32_t floor_face = 0;
    if (ag_shell_add_face(S.shell, &ff, &floor_face) != AG_OK)
        ag__skel_fail(&S, AG_ERR_NOMEM);
    /* heights with a horizontal segment, ascending and distinct */
    size_t maxflat = 0;
    for (size_t i = 0; i < plan->nprofiles; i++)
        maxflat += plan->profiles[i].npoints;
    S.flat_h = malloc((maxflat ? maxflat : 1) * sizeof *S.flat_h);
    if (!S.flat_h)
        ag__skel_fail(&S, AG_ERR_NOMEM);
    for (size_t i = 0; i < plan->nprofiles && S.flat_h; i++) {
        const ag_profile *p = &plan->profiles[i];
        for (size_t j = 0; j + 1 < p->npoints; j++) {
            if (!ag__skel_seg_flat(p, (int32_t)j))
                continue;
            double h = p->points[j].z;
            size_t k = 0;
            while (k < S.nflat && S.flat_h[k] < h)
                k++;
            if (k < S.nflat && S.flat_h[k] == h)
                continue;
            memmove(&S.flat_h[k + 1], &S.flat_h[k], (S.nflat - k) * sizeof *S.flat_h);
            S.flat_h[k] = h;
            S.nflat++;
        }
    }
    for (size_t k = 0; k < plan->nsteps && S.flat_h; k++) {
        if (plan->steps[k].npoints)
            continue; /* forced steps are not grown */
        double h = plan->steps[k].at.z;
        size_t q = 0;
        while (q < S.nflat && S.flat_h[q] < h)
            q++;
        if (q < S.nflat && S.flat_h[q] == h)
            continue;
        double *nf = realloc(S.flat_h, (S.nflat + 1 + maxflat) * sizeof *nf);
        if (!nf) {
            ag__skel_fail(&S, AG_ERR_NOMEM);
            break;
        }
        S.flat_h = nf;
        memmove(&S.flat_h[q + 1], &S.flat_h[q], (S.nflat - q) * sizeof *S.flat_h);
        S.flat_h[q] = h;
        S.nflat++;
    }
    /* offset events: a flat interval each, of their own */
    for (size_t k = 0; k < plan->noffsets && S.flat_h && S.st == AG_OK; k++) {
        double h = plan->offsets[k].z;
        size_t q = 0;
        while (q < S.nflat && S.flat_h[q] < h)
            q++;
        if (q < S.nflat && S.flat_h[q] == h) {
            ag_error_set(err, AG_ERR_INVALID, (long)k + 1,
                         "offset %zu at height %g coincides with a horizontal profile segment, a "
                         "natural step or another offset there (move it)", k, h);
            ag__skel_fail(&S, AG_ERR_INVALID);
            break;
        }
        double *nf = realloc(S.flat_h, (S.nflat + 1 + maxflat) * sizeof *nf);
        if (!nf) {
            ag__skel_fail(&S, AG_ERR_NOMEM);
            break;
        }
        S.flat_h = nf;
        memmove(&S.flat_h[q + 1], &S.flat_h[q], (S.nflat - q) * sizeof *S.flat_h);
        S.flat_h[q] = h;
        S.nflat++;
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        const ag_plan_step *st = &plan->steps[k];
        const ag_profile *p = &plan->profiles[st->profile];
        for (size_t j = 1; j + 1 < p->npoints; j++) {
            ag_event ev = {0};
            ev.type = AG_EVENT_DIRECTION;
            ev.z = ag__skel_virtual_z(&S, st->at.z + p->points[j].z, 1);
            ev.a = (uint32_t)st->profile;
            ev.b = (uint32_t)j;
            ev.ver = (uint32_t)k + 1;
            ag__skel_push(&S, &ev);
        }
    }
    for (size_t k = 0; k < plan->noffsets && S.st == AG_OK; k++) {
        const ag_plan_offset *o = &plan->offsets[k];
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = OFFSET_MARK;
        ev.b = (uint32_t)k;
        ev.z = ag__skel_virtual_z(&S, o->z, 0);
        ag__skel_push(&S, &ev);
        if (o->has_gap) {
            ev.a = GAP_MARK; /* the gap opens when the interval ends */
            ev.z += 1;
            ag__skel_push(&S, &ev);
        }
        /* the profiles the event hands out count their heights from it */
        for (size_t e = 0; e < 3 * (o->nedges + 2); e++) {
            size_t x = e % (o->nedges + 2), which = e / (o->nedges + 2);
            int32_t pi;
            if (which == 0)
                pi = x == o->nedges ? o->profile : x == o->nedges + 1 ? o->side
                                                                      : o->edges[x].profile;
            else if (!o->has_gap || x == o->nedges + 1)
                continue;
            else if (which == 1)
                pi = x == o->nedges ? o->inside : o->edges[x].inside - 1;
            else
                pi = x == o->nedges ? o->inner : o->edges[x].inner - 1;
            if (pi < 0)
                continue;
            const ag_profile *pr = &plan->profiles[pi];
            for (size_t j = 1; j + 1 < pr->npoints; j++) {
                ag_event d = {0};
                d.type = AG_EVENT_DIRECTION;
                d.z = ag__skel_virtual_z(&S, o->z + pr->points[j].z, 1);
                d.a = (uint32_t)pi;
                d.b = (uint32_t)j;
                d.ver = (uint32_t)(plan->nsteps + 1 + k);
                ag__skel_push(&S, &d);
            }
        }
    }
    for (size_t k = 0; k < plan->nsteps; k++) {
        if (!plan->steps[k].npoints)
            continue;
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = FORCED_MARK;
        ev.b = (uint32_t)k;
        ev.z = ag__skel_virtual_z(&S, plan->steps[k].at.z, 1);
        ag__skel_push(&S, &ev);
    }
    for (size_t k = 0; k < S.nflat; k++) {
        ag_event ev = {0};
        ev.type = AG_EVENT_DIRECTION;
        ev.a = FLAT_MARK;
        ev.b = 0;
        ev.z = S.flat_h[k] + (double)k;
        ag__skel_push(&S, &ev);
        ev.b = 1;
        ev.z += 1;
        ag__skel_push(&S, &ev);
    }
    double top_profile = 0;
    for (size_t i = 0; i < plan->nprofiles; i++) {
        const ag_profile *p = &plan->profiles[i];
        top_profile = fmax(top_profile, ag__skel_virtual_z(&S, p->points[p->npoints - 1].z, 1));
        for (size_t j = 1; j + 1 < p->npoints; j++) {
            ag_event ev = {0};
            ev.type = AG_EVENT_DIRECTION;
            double z = p->points[j].z;
            if (ag__skel_seg_flat(p, (int32_t)j))
                ev.z = ag__skel_virtual_z(&S, z, 0); /* the flat interval starts */
            else if (ag__skel_seg_flat(p, (int32_t)j - 1))
                ev.z = ag__skel_virtual_z(&S, z, 0) + 1; /* it ends */
            else
                ev.z = ag__skel_virtual_z(&S, z, 1);
            ev.a = (uint32_t)i;
            ev.b = (uint32_t)j;
            ag__skel_push(&S, &ev);
        }
    }
    ag_anchor *anchors = opt ? opt->anchors : NULL;
    for (size_t i = 0; anchors && i < plan->nanchors; i++) {
        ag_event ev = {0};
        ev.type = AG_EVENT_ANCHOR;
        ev.z = ag__skel_virtual_z(&S, anchors[i].z, 0);
        ev.b = (uint32_t)i;
        anchors[i].found = 0;
        anchors[i].face = -1;
        ag__skel_push(&S, &ev);
    }
    for (size_t L = 0; L < plan->nloops && S.st == AG_OK; L++) {
        const ag_plan_loop *lp = &plan->loops[L];
        size_t n = lp->n;
        uint32_t e0 = (uint32_t)S.ne;
        uint32_t v0 = (uint32_t)S.shell->nverts;
        for (size_t i = 0; i < n; i++)
            ag__skel_vertex(&S, lp->xy[2 * i] - S.ox, lp->xy[2 * i + 1] - S.oy, 0);
        for (size_t i = 0; i < n; i++) {
            uint32_t ei = ag__skel_add_edge(&S);
            if (ei == NONE)
                break;
            sk_edge *e = &S.e[ei];
            size_t j = (i + 1) % n;
            double dx = lp->xy[2 * j] - lp->xy[2 * i], dy = lp->xy[2 * j + 1] - lp->xy[2 * i + 1];
            double len = hypot(dx, dy);
            e->nx = -dy / len;
            e->ny = dx / len;
            const ag_profile *p = &plan->profiles[lp->profile[i]];
            e->s = ag__skel_seg_slope(p, 0);
            e->c = e->nx * (lp->xy[2 * i] - S.ox) + e->ny * (lp->xy[2 * i + 1] - S.oy);
            e->loop = (int32_t)L;
            e->edge = (int32_t)i;
            e->profile = lp->profile[i];
            e->seg = 0;
            e->face = ag__skel_new_face(&S, e);
            ag__skel_seg(&S, e->face, v0 + (uint32_t)i, v0 + (uint32_t)j);
            ag__skel_seg(&S, floor_face, v0 + (uint32_t)j, v0 + (uint32_t)i);
        }
        for (size_t i = 0; i < n && S.st == AG_OK; i++)
            ag__skel_add_corner(&S, e0 + (uint32_t)((i + n - 1) % n), e0 + (uint32_t)i,
                       lp->xy[2 * i] - S.ox, lp->xy[2 * i + 1] - S.oy, 0, v0 + (uint32_t)i);
    }
    for (size_t i = 0; i < S.ntouched && S.st == AG_OK; i++)
        ag__skel_settle(&S, S.touched[i]);
    ag__skel_schedule_touched(&S);

    double limit = plan->cap_height > 0 ? ag__skel_virtual_z(&S, plan->cap_height, 0) : INFINITY;
    ag_event *batch = NULL;
    size_t cap_batch = 0;
    while (S.st == AG_OK) {
        ag_event ev;
        int more = ag__skel_pop(&S, &ev);
        if (S.st != AG_OK)
            break;
        if (more && !ag__skel_event_valid(&S, &ev)) {
            ag__skel_event_dropped(&S, &ev);
            continue;
        }
        int intersection = more && (ev.type == AG_EVENT_EDGE || ev.type == AG_EVENT_SPLIT);
        if (S.deferred.n && (!intersection || ev.z > S.level + S.d1)) {
            /* every event of the level is handled: settle the corners it left */
            if (more)
                ag__skel_push(&S, &ev);
            settle_deferred(&S);
            continue;
        }
        if (S.made.n && (!more || ev.z > S.made_z + AG_EXTRUDE_WINDING_PROBE * S.d1)) {
            /* every event of the height the last corners were made at is handled: do the
             * chains still form a valid plan just above it? */
            if (ag__skel_winding_repair(&S)) {
                /* the rebuilt plan's events may come before this one */
                if (more)
                    ag__skel_push(&S, &ev);
                ag__skel_schedule_touched(&S);
                continue;
            }
        }
        if (!more || ev.z > limit)
            break;
        if (ev.type == AG_EVENT_ANCHOR) {
            /* only observes: the sweep height stays where the last event left it */
            ag__skel_compact_live(&S);
            ag__skel_locate_anchor(&S, &anchors[ev.b], ev.z);
            continue;
        }
        if (ev.z > S.zcur)
            S.zcur = ev.z;
        if (intersection) {
            if (!S.deferred.n)
                S.level = ev.z;
            S.defer_settle = 1;
            S.track_made = 1;
            ag__skel_next_cluster(&S, &ev);
            S.track_made = 0;
            S.defer_settle = 0;
            ag__skel_schedule_touched(&S);
            continue;
        }
        size_t nb = 0;
        if (ag_array_reserve((void **)&batch, &cap_batch, 1, sizeof *batch) != AG_OK) {
            ag__skel_fail(&S, AG_ERR_NOMEM);
            break;
        }
        batch[nb++] = ev;
        const ag_event *top;
        /* direction events at one height are one event (their heights come from the
         * profiles' points, equal heights are equal numbers) */
        while ((top = ag_eventq_peek(&S.q)) && top->z <= ev.z + S.d1 &&
               top->type == AG_EVENT_DIRECTION) {
            ag_event nx;
            if (!ag__skel_pop(&S, &nx))
                break;
            if (ag_array_reserve((void **)&batch, &cap_batch, nb + 1, sizeof *batch) != AG_OK) {
                ag__skel_fail(&S, AG_ERR_NOMEM);
                break;
            }
            batch[nb++] = nx;
        }
        int only_forced = 1;
        for (size_t i = 0; i < nb; i++) {
            only_forced &= batch[i].a == FORCED_MARK;
            /* a flat interval's start or end moves parts of the plan against each other
             * (overhangs growing out, terraces in): its corners are checked too */
            S.track_made |= batch[i].a == FLAT_MARK;
        }
        if (!only_forced)
            ag__skel_direction(&S, batch, nb);
        for (size_t i = 0; i < nb && S.st == AG_OK; i++)
            if (batch[i].a == OFFSET_MARK) {
                S.stats.offsets++;
                ag__skel_insert_sides(&S, batch[i].b);
            }
        for (size_t i = 0; i < nb; i++)
            if (batch[i].a == FLAT_MARK && batch[i].b == 0)
                ag__skel_insert_steps(&S, batch[i].z);
        if (S.st == AG_OK)
            ag__skel_insert_bevels(&S, batch[0].z);
        for (size_t i = 0; i < nb && S.st == AG_OK; i++)
            if (batch[i].a == FORCED_MARK)
                ag__skel_forced_step(&S, batch[i].b, batch[i].z);
        for (size_t i = 0; i < nb && S.st == AG_OK; i++)
            if (batch[i].a == GAP_MARK)
                ag__skel_insert_gap(&S, batch[i].b, batch[i].z);
        S.track_made = 0;
        ag__skel_schedule_touched(&S);
    }
    if (S.st == AG_OK) {
        double zc = plan->cap_height > 0 ? limit : fmax(S.zcur, top_profile);
        ag__skel_compact_live(&S);
        if (S.nlive_e)
            ag__skel_cap(&S, zc);
        S.stats.top = ag__skel_real_z(&S, S.nlive_e ? zc : S.zcur);
    }
    free(batch);
    free(S.W.C.arr);
    free(S.W.E.arr);
    free(S.W.splits.arr);
    free(S.W.rays);
    free(S.W.uf);
    free(S.W.batch);
    free(S.W.speed);
    free(S.W.cand);
    free(S.deferred.arr);
    free(S.made.arr);
    ag_status st = S.st;
    if (st == AG_OK) {
        st = ag_shell_finish(S.shell, S.d1);
        S.stats.flat_levels = S.shell->flat_levels;
        S.stats.flat_rebuilt = S.shell->flat_rebuilt;
        S.stats.flat_left = S.shell->flat_left;
    }
    ag_eventq_free(&S.q);
    free(S.e);
    free(S.c);
    free(S.live_c);
    free(S.live_e);
    free(S.touched);
    free(S.flat_h);
    S.stats.events = S.budget->events - events0;
    if (stats)
        *stats = S.stats;
    if (st != AG_OK) {
        ag_shell_free(S.shell);
        if (!err || err->code == AG_OK)
            ag_error_set(err, st, 0, "%s", st == AG_ERR_NOMEM ? "out of memory" : "extrusion failed");
        return st;
    }
    *out = S.shell;
    return AG_OK;
}
