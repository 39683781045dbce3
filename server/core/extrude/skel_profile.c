/* Profile events: direction events (an edge switches plane, or is held still or released
 * around a flat interval), offset events' side edges and their inside boundaries. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"

#include "../base/tolerance.h"

static int offset_tuple(const ag_plan_offset *o, const sk_edge *e, double *w, int32_t *prof)
{
    *w = o->outside;
    *prof = o->profile;
    for (size_t i = 0; i < o->nedges && !e->step; i++) {
        const ag_offset_edge *x = &o->edges[i];
        if (x->loop != e->loop || x->edge != e->edge)
            continue;
        if (x->disabled)
            return 0;
        if (x->has_outside)
            *w = x->outside;
        if (x->profile >= 0)
            *prof = x->profile;
    }
    return 1;
}

void ag__skel_direction(sk *S, ag_event *evs, size_t n)
{
    double z = evs[0].z;
    S->stamp++;
    uint32_t mark = S->stamp;
    S->stats.directions++;
    ag__skel_compact_live(S);
    /* edges that change: a profile switching segment (new face), or an edge held
     * still for / released after a flat interval (same face) */
    sk_u32vec ch = {0}, ks = {0};
    int flat_start = 0, flat_end = 0;
    const ag_plan_offset *off = NULL; /* an offset event starting here */
    int32_t off_clock = 0;
    for (size_t j = 0; j < n; j++) {
        if (evs[j].a == FLAT_MARK) {
            flat_start |= evs[j].b == 0;
            flat_end |= evs[j].b == 1;
        }
        if (evs[j].a == OFFSET_MARK && evs[j].ver == 0) {
            off = &S->plan->offsets[evs[j].b];
            off_clock = (int32_t)(S->plan->nsteps + 1 + evs[j].b);
        }
    }
    double *off_w = malloc((S->nlive_e ? S->nlive_e : 1) * sizeof *off_w);
    int32_t *off_p = malloc((S->nlive_e ? S->nlive_e : 1) * sizeof *off_p);
    if (!off_w || !off_p) {
        free(off_w);
        free(off_p);
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    uint8_t *newface = malloc(S->nlive_e ? S->nlive_e : 1);
    if (!newface) {
        free(off_w);
        free(off_p);
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    for (size_t i = 0; i < S->nlive_e; i++) {
        uint32_t ei = S->live_e[i];
        sk_edge *e = &S->e[ei];
        int hit = 0;
        for (size_t j = 0; j < n && !hit; j++)
            if (evs[j].a != FLAT_MARK && (uint32_t)e->profile == evs[j].a &&
                (uint32_t)e->seg + 1 == evs[j].b && (uint32_t)e->clock == evs[j].ver)
                hit = 1;
        const ag_profile *p = &S->plan->profiles[e->profile];
        if (off && !e->growing && !e->paused && offset_tuple(off, e, &off_w[ch.n], &off_p[ch.n])) {
            newface[ch.n] = 3; /* moves by its offset over this flat interval */
            if (!ag__skel_vpush(&ch, ei))
                ag__skel_fail(S, AG_ERR_NOMEM);
            continue;
        }
        int next_flat = hit ? ag__skel_seg_flat(p, e->seg + 1) : ag__skel_seg_flat(p, e->seg);
        int grown = flat_end && e->growing;
        int pause = !hit && !e->growing && flat_start && !next_flat && !e->paused;
        int release = !hit && flat_end && e->paused;
        if (!hit && !pause && !release && !grown)
            continue;
        /* a grown edge whose own profile turns at the same height takes the next segment */
        newface[ch.n] = (uint8_t)(grown ? (hit ? 1 : 2) : hit);
        if (!ag__skel_vpush(&ch, ei))
            ag__skel_fail(S, AG_ERR_NOMEM);
    }
    for (size_t i = 0; i < ch.n; i++) {
        sk_edge *e = &S->e[ch.arr[i]];
        uint32_t cs[2] = {e->start, e->end};
        for (int j = 0; j < 2; j++)
            if (S->c[cs[j]].stamp != mark) {
                S->c[cs[j]].stamp = mark;
                if (!ag__skel_vpush(&ks, cs[j]))
                    ag__skel_fail(S, AG_ERR_NOMEM);
            }
    }
    /* retire the corners there, remembering their vertex at this height */
    uint32_t *verts = malloc((ks.n ? ks.n : 1) * sizeof *verts);
    double *xy = malloc((ks.n ? ks.n : 1) * 2 * sizeof *xy);
    if (!verts || !xy) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        goto out;
    }
    for (size_t i = 0; i < ks.n; i++) {
        sk_corner *c = &S->c[ks.arr[i]];
        ag__skel_cpos(c, z, &xy[2 * i], &xy[2 * i + 1]);
        verts[i] = ag__skel_vertex(S, xy[2 * i], xy[2 * i + 1], z);
        ag__skel_retire(S, ks.arr[i], verts[i]);
        c->stamp = (uint32_t)i; /* index into verts until re-made */
    }
    for (size_t i = 0; i < ch.n; i++) {
        sk_edge *e = &S->e[ch.arr[i]];
        const ag_profile *p = &S->plan->profiles[e->profile];
        double s_new;
        if (newface[i] == 3 && off_w[i] == 0) {
            /* no move: it waits through the interval, on its new profile if it has one */
            if (off_p[i] >= 0) {
                uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
                ag__skel_seg(S, e->face, ve, vs);
                e->profile = off_p[i];
                e->seg = 0;
                e->clock = off_clock;
                e->face = ag__skel_new_face(S, e);
                ag__skel_seg(S, e->face, vs, ve);
            }
            e->paused = 1;
            s_new = 0;
        } else if (newface[i] == 3) {
            uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
            ag__skel_seg(S, e->face, ve, vs);
            if (off_p[i] >= 0) {
                e->profile = off_p[i];
                e->seg = 0;
                e->clock = off_clock;
            }
            e->growing = 1; /* its flat face; at the interval's end it carries on */
            e->paused = 0;
            s_new = -off_w[i];
            e->face = ag__skel_new_face(S, e);
            ag__skel_seg(S, e->face, vs, ve);
        } else if (newface[i]) {
            uint32_t vs = verts[S->c[e->start].stamp], ve = verts[S->c[e->end].stamp];
            ag__skel_seg(S, e->face, ve, vs);
            if (newface[i] == 1)
                e->seg++; /* a grown plan edit keeps its profile's first segment */
            s_new = ag__skel_seg_slope(p, e->seg);
            e->paused = 0;
            e->growing = 0; /* before new_face: the new face is a profile segment's */
            e->face = ag__skel_new_face(S, e);
            ag__skel_seg(S, e->face, vs, ve);
        } else if (e->paused) {
            s_new = ag__skel_seg_slope(p, e->seg);
            e->paused = 0;
        } else {
            s_new = 0;
            e->paused = 1;
        }
        e->c += (e->s - s_new) * z;
        e->s = s_new;
        e->ver++;
    }
    size_t first_new = S->ntouched;
    for (size_t i = 0; i < ks.n; i++) {
        sk_corner *c = &S->c[ks.arr[i]];
        c->stamp = 0;
        ag__skel_add_corner(S, c->in, c->out, xy[2 * i], xy[2 * i + 1], z, verts[i]);
    }
    size_t last_new = S->ntouched;
    for (size_t i = first_new; i < last_new && S->st == AG_OK; i++)
        ag__skel_settle(S, S->touched[i]);
out:
    free(newface);
    free(off_w);
    free(off_p);
    free(verts);
    free(xy);
    free(ch.arr);
    free(ks.arr);
}

/* Puts the new edge `ne` (of no length yet) into the active plan right after corner ck, at
 * the corner's point (px, py) where it was made: ck now leads into ne, and a new corner
 * leads from ne into ck's former out-edge; both are settled again. */
static void insert_after(sk *S, uint32_t ck, uint32_t ne, double px, double py)
{
    sk_corner *c = &S->c[ck];
    uint32_t other = c->out;
    c->out = ne;
    S->e[ne].start = ck;
    S->e[other].ver++;
    if (ag_array_reserve((void **)&S->touched, &S->cap_touched, S->ntouched + 1,
                       sizeof(uint32_t)) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return;
    }
    S->touched[S->ntouched++] = ck;
    size_t first = S->ntouched - 1;
    ag__skel_add_corner(S, ne, other, px, py, c->z, c->vert);
    size_t last = S->ntouched;
    for (size_t t = first; t < last && S->st == AG_OK; t++)
        ag__skel_settle(S, S->touched[t]);
}

/* --- profile offset events: side edges ---------------------------------------------------- */

/* After an offset event's interval has started: where a moving edge A meets a waiting
 * (disabled) edge B, a side edge of zero length is put between them along the mitre
 * the two would share if both moved; it holds still while A's corner slides out along
 * it, cutting A's offset region there, and then follows the side profile. */
void ag__skel_insert_sides(sk *S, size_t k)
{
    const ag_plan_offset *o = &S->plan->offsets[k];
    if (o->side < 0)
        return;
    ag__skel_compact_live(S);
    size_t nlive = S->nlive_c;
    for (size_t i = 0; i < nlive && S->st == AG_OK; i++) {
        uint32_t ck = S->live_c[i];
        sk_corner *c = &S->c[ck];
        if (!c->alive)
            continue;
        const sk_edge *ein = &S->e[c->in], *eout = &S->e[c->out];
        int a_in;
        if (ein->growing && eout->paused)
            a_in = 1;
        else if (eout->growing && ein->paused)
            a_in = 0;
        else
            continue;
        const sk_edge *A = a_in ? ein : eout, *B = a_in ? eout : ein;
        /* the shared mitre: where a corner of A and B would go if both moved out */
        double det = A->nx * B->ny - A->ny * B->nx, mx, my;
        if (fabs(det) <= AG_EXTRUDE_PARALLEL) {
            mx = -A->nx;
            my = -A->ny;
        } else {
            mx = (-B->ny + A->ny) / det;
            my = (-A->nx + B->nx) / det;
        }
        double ml = hypot(mx, my);
        if (!(ml > 0))
            continue;
        double dx = (a_in ? -mx : mx) / ml, dy = (a_in ? -my : my) / ml;
        double nx = -dy, ny = dx;
        /* A's end must slide away from B along the side edge, else there is nothing to cut */
        double d2 = A->nx * ny - A->ny * nx;
        if (fabs(d2) <= AG_EXTRUDE_PARALLEL)
            continue;
        double vx = (A->s * ny) / d2, vy = (-A->s * nx) / d2; /* n_A.v = s_A, n_side.v = 0 */
        if (!((a_in ? -1 : 1) * (vx * dx + vy * dy) > 0))
            continue;
        double px, py;
        ag__skel_cpos(c, c->z, &px, &py);
        uint32_t se = ag__skel_add_edge(S);
        if (se == NONE)
            return;
        c = &S->c[ck];
        A = a_in ? &S->e[c->in] : &S->e[c->out];
        sk_edge *e = &S->e[se];
        e->nx = nx;
        e->ny = ny;
        e->s = 0;
        e->c = nx * px + ny * py;
        e->loop = A->loop;
        e->edge = A->edge;
        e->profile = o->side;
        e->seg = 0;
        e->step = -1;
        e->clock = (int32_t)(S->plan->nsteps + 1 + k);
        e->paused = 1; /* released with the others at the interval's end */
        e->face = ag__skel_new_face(S, e);
        insert_after(S, ck, se, px, py);
        S->stats.offset_sides++;
    }
}

/* --- profile offset events: the inside boundary ------------------------------------------- */

#define GAP_MARK (UINT32_MAX - 3)

/* Edge e's gap in offset event o (metres inwards) and its profiles after the event:
 * `inside` for the outer shell's face towards the gap, `inner` for the inner shell (-1:
 * e's own). */
static void gap_tuple(const ag_plan_offset *o, const sk_edge *e, double *from, double *to,
                      int32_t *inside, int32_t *inner)
{
    *from = o->gap_from;
    *to = o->gap_to;
    *inside = o->inside;
    *inner = o->inner;
    for (size_t i = 0; i < o->nedges && !e->step; i++) {
        const ag_offset_edge *x = &o->edges[i];
        if (x->loop != e->loop || x->edge != e->edge)
            continue;
        if (x->has_gap) {
            *from = x->gap_from;
            *to = x->gap_to;
        }
        if (x->inside)
            *inside = x->inside - 1;
        if (x->inner)
            *inner = x->inner - 1;
    }
}

/* One loop of an inset: corners (local plan coordinates) and, per corner i, the active
 * edge the inset's edge from corner i to i + 1 came from. */
typedef struct {
    size_t n, cap, cap_src;
    double *xy;
    uint32_t *src;
    size_t nloops, cap_loops;
    size_t *start; /* nloops + 1 */
} inset;

static void inset_free(inset *in)
{
    free(in->xy);
    free(in->src);
    free(in->start);
}

/* The active plan at virtual height v inset by each edge's distance (dist[i] for live edge
 * i), computed as the cross-section at height 1 of a sweep whose edges rise at slope
 * dist: the same engine keeps the inset's topology (splits, vanishing parts) right. */
static ag_status inset_plan(sk *S, double v, const double *dist, const uint32_t *slot,
                            inset *out, char *why, size_t nwhy)
{
    memset(out, 0, sizeof *out);
    ag_plan *P = ag_plan_create();
    double *xy = malloc(2 * (S->nlive_e + 1) * sizeof *xy);
    int32_t *pr = malloc((S->nlive_e + 1) * sizeof *pr);
    uint8_t *seen = calloc(S->nlive_e + 1, 1);
    ag_shell *sh = NULL;
    ag_error e2 = {0};
    ag_status st = P && xy && pr && seen ? AG_OK : AG_ERR_NOMEM;
    for (size_t i = 0; i < S->nlive_e && st == AG_OK; i++) {
        char name[24];
        snprintf(name, sizeof name, "g%zu", i);
        ag_profile_point pts[2] = {{0, 0}, {dist[i], 1}};
        st = ag_plan_add_profile(P, name, pts, 2, NULL, NULL, &e2);
    }
    for (size_t i = 0; i < S->nlive_e && st == AG_OK; i++) {
        if (seen[i])
            continue;
        size_t n = 0;
        uint32_t ei = S->live_e[i];
        for (;;) {
            const sk_edge *e = &S->e[ei];
            uint32_t q = slot[ei];
            if (q != NONE && seen[q])
                break;
            if (q == NONE || e->start == NONE || e->end == NONE || n >= S->nlive_e) {
                st = AG_ERR_INTERNAL;
                snprintf(why, nwhy, "the active plan does not close into loops");
                break;
            }
            seen[q] = 1;
            ag__skel_cpos(&S->c[e->start], v, &xy[2 * n], &xy[2 * n + 1]);
            pr[n++] = (int32_t)q;
            ei = S->c[e->end].out;
        }
        if (st == AG_OK && n >= 3)
            st = ag_plan_add_loop(P, xy, n, pr, &e2);
    }
    double extent = 0;
    if (st == AG_OK && P->nloops) {
        P->cap_height = 1;
        st = ag_plan_validate(P, NULL, &extent, &e2);
        if (st == AG_OK)
            {
            ag_skeleton_options so = {S->budget, NULL, S->no_winding_repair};
            st = ag_skeleton_build(P, extent, &so, &sh, NULL, &e2);
        }
    }
    if (st != AG_OK && !why[0])
        snprintf(why, nwhy, "%.120s", e2.text[0] ? e2.text : "out of memory");
    /* the cap's loops; each cap edge's twin is the side face of the edge it came from */
    for (size_t f = 0; sh && st == AG_OK && f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        if (fc->kind != AG_SHELL_FACE_CAP)
            continue;
        for (uint32_t l = fc->first_loop; l < fc->first_loop + (fc->nloops & 0x7fffffffu); l++) {
            uint32_t a = sh->loop_start[l], b = sh->loop_start[l + 1];
            size_t first = out->n;
            for (uint32_t h = a; h < b && st == AG_OK; h++) {
                uint32_t t = sh->he_twin[h];
                if (t == UINT32_MAX || sh->faces[sh->he_face[t]].profile < 0) {
                    st = AG_ERR_INTERNAL;
                    snprintf(why, nwhy, "the inset is not closed");
                    break;
                }
                uint32_t src = (uint32_t)sh->faces[sh->he_face[t]].profile;
                /* a corner between two pieces of one edge's line is no corner */
                uint32_t hp = h == a ? b - 1 : h - 1, tp = sh->he_twin[hp];
                if (tp != UINT32_MAX && sh->he_face[tp] == sh->he_face[t])
                    continue;
                if (ag_array_reserve((void **)&out->xy, &out->cap, out->n + 1, 2 * sizeof *out->xy) != AG_OK) {
                    st = AG_ERR_NOMEM;
                    break;
                }
                if (ag_array_reserve((void **)&out->src, &out->cap_src, out->n + 1, sizeof *out->src) != AG_OK) {
                    st = AG_ERR_NOMEM;
                    break;
                }
                out->xy[2 * out->n] = sh->pos[3 * sh->idx[h]];
                out->xy[2 * out->n + 1] = sh->pos[3 * sh->idx[h] + 1];
                out->src[out->n++] = src;
            }
            if (st != AG_OK)
                break;
            if (out->n - first < 3) {
                out->n = first; /* nothing left of it */
                continue;
            }
            if (ag_array_reserve((void **)&out->start, &out->cap_loops, out->nloops + 2, sizeof *out->start) != AG_OK) {
                st = AG_ERR_NOMEM;
                break;
            }
            out->start[out->nloops] = first;
            out->start[++out->nloops] = out->n;
        }
    }
    if (st == AG_ERR_NOMEM && !why[0])
        snprintf(why, nwhy, "out of memory");
    ag_shell_free(sh);
    ag_plan_free(P);
    free(xy);
    free(pr);
    free(seen);
    return st;
}

/* At the end of offset event k's interval (virtual height v): opens the gap. The inset
 * at gap_from, reversed, becomes the outer shell's inner boundary; the inset at gap_to
 * the inner shell's boundary; the ring between them gets a floor facing up. Both insets
 * lie strictly inside the active plan, so nothing is crossed when they are put in. */
void ag__skel_insert_gap(sk *S, size_t k, double v)
{
    const ag_plan_offset *o = &S->plan->offsets[k];
    ag__skel_compact_live(S);
    size_t n = S->nlive_e;
    if (!n)
        return;
    int32_t clock = (int32_t)(S->plan->nsteps + 1 + k);
    double *d = malloc(2 * n * sizeof *d);
    int32_t *pin = malloc(2 * n * sizeof *pin);
    uint32_t *slot = malloc(S->ne * sizeof *slot);
    inset ins[2];
    memset(ins, 0, sizeof ins);
    char why[160] = "";
    ag_status st = d && pin && slot ? AG_OK : AG_ERR_NOMEM;
    for (size_t i = 0; st == AG_OK && i < S->ne; i++)
        slot[i] = NONE;
    for (size_t i = 0; st == AG_OK && i < n; i++) {
        slot[S->live_e[i]] = (uint32_t)i;
        gap_tuple(o, &S->e[S->live_e[i]], &d[i], &d[n + i], &pin[i], &pin[n + i]);
    }
    if (st == AG_OK)
        st = inset_plan(S, v, d, slot, &ins[0], why, sizeof why);
    if (st == AG_OK)
        st = inset_plan(S, v, d + n, slot, &ins[1], why, sizeof why);
    if (st != AG_OK && S->budget->st != AG_OK) {
        ag_error_set(S->err, S->budget->st, (long)k + 1, "the extrusion was %s, opening the "
                     "inside boundary of offset %zu", S->budget->why, k);
        ag__skel_fail(S, S->budget->st);
        goto out;
    }
    if (st != AG_OK) {
        ag_error_set(S->err, st == AG_ERR_NOMEM ? AG_ERR_NOMEM : AG_ERR_INVALID, (long)k + 1,
                     "offset %zu at height %g: the inside boundary could not be made (%s)", k,
                     o->z, why[0] ? why : "out of memory");
        ag__skel_fail(S, st == AG_ERR_NOMEM ? AG_ERR_NOMEM : AG_ERR_INVALID);
        goto out;
    }
    if (!ins[0].nloops)
        goto out; /* the active plan is narrower than the gap's start: no gap */
    S->stats.offset_gaps++;
    ag_shell_face ff = {AG_SHELL_FACE_CAP, -1, -1, o->inside, -1, 0, 0};
    uint32_t floor_face = 0;
    if (ag_shell_add_face(S->shell, &ff, &floor_face) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        goto out;
    }
    size_t first_new = S->ntouched;
    for (int side = 0; side < 2 && S->st == AG_OK; side++) {
        const inset *in = &ins[side];
        for (size_t L = 0; L < in->nloops && S->st == AG_OK; L++) {
            size_t a = in->start[L], m = in->start[L + 1] - a;
            uint32_t v0 = (uint32_t)S->shell->nverts, e0 = (uint32_t)S->ne;
            for (size_t j = 0; j < m; j++)
                ag__skel_vertex(S, in->xy[2 * (a + j)], in->xy[2 * (a + j) + 1], v);
            for (size_t j = 0; j < m && S->st == AG_OK; j++) {
                size_t jn = (j + 1) % m;
                const double *p = &in->xy[2 * (a + j)], *q = &in->xy[2 * (a + jn)];
                uint32_t src = S->live_e[in->src[a + j]];
                uint32_t id = ag__skel_add_edge(S);
                if (id == NONE)
                    break;
                sk_edge *e = &S->e[id];
                const sk_edge *E = &S->e[src];
                double len = hypot(q[0] - p[0], q[1] - p[1]);
                /* the outer shell's boundary runs backwards: its inside is towards the plan's */
                double sg = side == 0 ? -1 : 1;
                e->nx = sg * -(q[1] - p[1]) / len;
                e->ny = sg * (q[0] - p[0]) / len;
                e->loop = E->loop;
                e->edge = E->edge;
                e->step = E->step;
                int32_t prof = pin[(size_t)side * n + in->src[a + j]];
                if (prof >= 0) {
                    e->profile = prof;
                    e->seg = 0;
                    e->clock = clock;
                    e->s = ag__skel_seg_slope(&S->plan->profiles[prof], 0);
                } else {
                    e->profile = E->profile;
                    e->seg = E->seg;
                    e->clock = E->clock;
                    e->s = E->s;
                }
                e->c = e->nx * p[0] + e->ny * p[1] - e->s * v;
                e->face = ag__skel_new_face(S, e);
                uint32_t vp = v0 + (uint32_t)j, vq = v0 + (uint32_t)jn;
                if (side == 0) {
                    ag__skel_seg(S, e->face, vq, vp);
                    ag__skel_seg(S, floor_face, vp, vq);
                } else {
                    ag__skel_seg(S, e->face, vp, vq);
                    ag__skel_seg(S, floor_face, vq, vp);
                }
            }
            if (S->st != AG_OK || S->ne != e0 + m)
                break;
            for (size_t j = 0; j < m && S->st == AG_OK; j++) {
                uint32_t ej = e0 + (uint32_t)j, eprev = e0 + (uint32_t)((j + m - 1) % m);
                const double *p = &in->xy[2 * (a + j)];
                if (side == 0)
                    ag__skel_add_corner(S, ej, eprev, p[0], p[1], v, v0 + (uint32_t)j);
                else
                    ag__skel_add_corner(S, eprev, ej, p[0], p[1], v, v0 + (uint32_t)j);
            }
        }
    }
    size_t last_new = S->ntouched;
    for (size_t i = first_new; i < last_new && S->st == AG_OK; i++)
        ag__skel_settle(S, S->touched[i]);
out:
    inset_free(&ins[0]);
    inset_free(&ins[1]);
    free(d);
    free(pin);
    free(slot);
}

/* --- outward offsets: bevels at sharp corners ---------------------------------------------- */

/* After direction events (a soffit's flat interval starts, an offset event moves edges
 * out, a profile leans outwards): a sharp convex corner of an edge moving outwards would
 * shoot out by width / sin(angle / 2) (20 m for a 0.5 m eave on a 3° spike of digitising
 * noise), or slide that far along a waiting neighbour's line. Where the corner would move
 * faster than the mitre limit times the outward speed, a bevel edge is put in,
 * perpendicular to the corner's bisector and moving out as fast as the outward edge, so
 * the eave is cut square to the bisector as eaves are built; it carries on with the
 * profile of the edge moving outwards (the faster one). */
void ag__skel_insert_bevels(sk *S, double v)
{
    ag__skel_compact_live(S);
    size_t nlive = S->nlive_c;
    for (size_t i = 0; i < nlive && S->st == AG_OK; i++) {
        uint32_t ck = S->live_c[i];
        sk_corner *c = &S->c[ck];
        if (!c->alive || !c->settled || fabs(c->z - v) > S->d1)
            continue;
        const sk_edge *A = &S->e[c->in], *B = &S->e[c->out];
        double out = fmin(A->s, B->s); /* the outward speed (negative) */
        if (!(out < 0) || A->growing || B->growing)
            continue;
        /* a convex corner moving outwards faster than the mitre limit allows */
        double turn = ag__skel_edx(A) * ag__skel_edy(B) - ag__skel_edy(A) * ag__skel_edx(B);
        double nx = A->nx + B->nx, ny = A->ny + B->ny, nl = hypot(nx, ny);
        if (!(turn > 0) || !(nl > 0) || c->vx * nx + c->vy * ny >= 0 ||
            hypot(c->vx, c->vy) <= -out * AG_EXTRUDE_BEVEL_MITRE)
            continue;
        nx /= nl;
        ny /= nl;
        double px = c->x, py = c->y;
        /* the bevel moves and carries on as the edge moving outwards (the faster one) */
        uint32_t mover = A->s <= B->s ? c->in : c->out;
        uint32_t be = ag__skel_add_edge(S);
        if (be == NONE)
            return;
        c = &S->c[ck];
        const sk_edge *M = &S->e[mover];
        sk_edge *e = &S->e[be];
        e->nx = nx;
        e->ny = ny;
        e->s = out;
        e->c = nx * px + ny * py - e->s * v;
        e->loop = M->loop;
        e->edge = M->edge;
        e->profile = M->profile;
        e->seg = M->seg;
        e->step = M->step;
        e->clock = M->clock;
        e->face = ag__skel_new_face(S, e);
        insert_after(S, ck, be, px, py);
        S->stats.bevels++;
    }
}
