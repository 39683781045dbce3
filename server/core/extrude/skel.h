/* Internal state of the straight-skeleton sweep (ag_skeleton_build) shared by its parts:
 *
 *   skel_sweep.c         the sweep state: edges, corners, shell output, virtual height
 *   skel_event.c         computing and scheduling intersection events, clustering them
 *   skel_intersection.c  the generalized intersection event (chains paired around a point)
 *   skel_merge.c         settling new corners: velocity, collinear merge, ridge zip
 *   skel_profile.c       profile direction events, offset events (side edges, inside gaps)
 *   skel_step.c          plan edits grown as natural steps
 *   skel_forced.c        forced steps: a polygon united with the active plan
 *   skel_anchor.c        anchors located on the active plan, the flat cap
 *   skel_winding.c       the post inter-chain repair: region boundaries by the winding rule
 *   skeleton.c           the driver: initial plan, event loop
 *
 * Not part of the public interface: only the files above include it. */
#ifndef AG_EXTRUDE_SKEL_H
#define AG_EXTRUDE_SKEL_H

#include <stddef.h>
#include <stdint.h>

#include "eventq.h"
#include "skeleton.h"

#define NONE UINT32_MAX

/* Marks in ag_event.a of direction events that are not a profile's segment change. */
#define FLAT_MARK UINT32_MAX          /* b = 0: a flat interval starts, b = 1: it ends */
#define FORCED_MARK (UINT32_MAX - 1)  /* b = forced step */
#define OFFSET_MARK (UINT32_MAX - 2)  /* b = offset event */
#define GAP_MARK (UINT32_MAX - 3)     /* b = offset event whose inside boundary opens */

typedef struct {
    double nx, ny; /* inward unit normal; direction is (ny, -nx) */
    double c, s;   /* the edge's line at height z: n . p = c + s z */
    uint32_t start, end;
    uint32_t face;
    int32_t loop, edge, profile, seg;
    uint32_t ver;
    uint32_t mark;   /* stamp of the last scheduling that visited it */
    uint8_t alive;
    uint8_t paused;  /* held still while other edges make a horizontal face */
    uint8_t growing; /* a plan edit's edge, growing to its size in a flat interval */
    int32_t step;    /* 0: from the plan; k + 1: made by plan edit k; -1: an offset's side */
    int32_t clock;   /* profile heights count from: 0 the plan, k + 1 plan edit k, then
                      * nsteps + 1 + k offset event k */
} sk_edge;

typedef struct {
    double x, y, z; /* where the corner was made */
    double vx, vy;  /* plan velocity per metre of height */
    uint32_t in, out;
    uint32_t vert; /* shell vertex where it was made */
    uint32_t stamp;
    uint8_t alive, settled;
    uint8_t passive; /* convex, both edges moving in or waiting: it splits no edge that does */
    double cond;     /* 1 / |sin| of the angle between its edges: how ill-known its motion is */
    double next_split; /* height of the first hit on an edge queued for it (INFINITY: none) */
} sk_corner;

typedef struct {
    uint32_t *arr;
    size_t n, cap;
} sk_u32vec;

/* A ray of an edge leaving (out) or arriving at an intersection point, by angle. */
typedef struct {
    double ang;
    uint32_t edge;
    int out;
    double s; /* its edge's slope: how it turns just above the point */
} sk_ray;

/* Buffers of the intersection handler, kept across events. */
typedef struct {
    sk_u32vec C, E, splits;
    sk_ray *rays;
    size_t cap_rays;
    ag_event *batch; /* clustering: the events within delta1 of the lowest */
    size_t cap_batch;
    uint32_t *uf; /* clustering: membership of the lowest event's cluster */
    size_t cap_uf;
    double *speed; /* clustering: each event's fastest corner and its height's uncertainty */
    ag_event *cand; /* scheduling: a corner's candidate hits */
    size_t cap_cand;
    size_t cap_speed;
} sk_scratch;

typedef struct {
    const ag_plan *plan;
    ag_shell *shell;
    ag_eventq q;
    sk_edge *e;
    size_t ne, cap_e;
    sk_corner *c;
    size_t nc, cap_c;
    uint32_t *live_c; /* corners that may still split edges (lazily compacted) */
    size_t nlive_c, cap_live_c;
    uint32_t *live_e;
    size_t nlive_e, cap_live_e;
    uint32_t *touched; /* corners made while handling one event */
    size_t ntouched, cap_touched;
    uint32_t stamp;
    double ox, oy; /* local origin */
    double d1, d2, d3;
    double size; /* the plan's size the tolerances were scaled by */
    double zcur;
    /* Horizontal profile segments: the sweep runs in a virtual height in which each
     * height H with a horizontal segment is stretched to an interval [vs, vs + 1] of
     * the same real height; edges with the horizontal segment move by its width over
     * that interval, all others are held still. */
    size_t nflat;
    double *flat_h; /* real heights, ascending */
    ag_status st;
    ag_error *err;
    ag_skeleton_stats stats;
    /* while the groups of one batch of intersections are handled: new corners are settled
     * (merged, zipped) only after all of them, so a collinear merge made at one point
     * cannot run along the line over another point of the same height before it is met */
    int defer_settle;
    /* corners made by the intersections of one height level and left unsettled until
     * every event of that level has been handled (see defer_settle) */
    sk_u32vec deferred;
    double level; /* the height of that level */
    ag_budget *budget; /* events, time, memory, cancel (ag_budget_spend on every push/pop) */
    int no_winding_repair; /* the post inter-chain repair is off (comparisons in tests) */
    sk_u32vec made;        /* corners the intersections (and flat intervals' starts and
                            * ends) of the current height made, for the repair's check;
                            * other direction events change no chain */
    int track_made;        /* set while those are handled */
    double made_z;         /* that height */
    sk_scratch W;
} sk;

static inline double ag__skel_edx(const sk_edge *e) { return e->ny; }
static inline double ag__skel_edy(const sk_edge *e) { return -e->nx; }

/* Position of corner c at (virtual) height z. */
static inline void ag__skel_cpos(const sk_corner *c, double z, double *x, double *y)
{
    *x = c->x + c->vx * (z - c->z);
    *y = c->y + c->vy * (z - c->z);
}

/* --- skel_sweep.c ------------------------------------------------------------------------ */
int ag__skel_vpush(sk_u32vec *v, uint32_t x);
void ag__skel_fail(sk *S, ag_status st);
double ag__skel_real_z(const sk *S, double v);
double ag__skel_virtual_z(const sk *S, double z, int after);
uint32_t ag__skel_vertex(sk *S, double x, double y, double z);
void ag__skel_seg(sk *S, uint32_t face, uint32_t a, uint32_t b);
uint32_t ag__skel_new_face(sk *S, const sk_edge *e);
uint32_t ag__skel_add_edge(sk *S);
uint32_t ag__skel_add_corner(sk *S, uint32_t in, uint32_t out, double x, double y, double z,
                             uint32_t vert);
void ag__skel_retire(sk *S, uint32_t k, uint32_t v);
void ag__skel_kill_edge(sk *S, uint32_t e);
void ag__skel_push(sk *S, const ag_event *ev);
/* Takes the lowest event from the queue (counted against the budget); 0 when empty or
 * when the budget has run out (S->st is then set). */
int ag__skel_pop(sk *S, ag_event *ev);
/* Counts n units of work that are not events (candidate pairs tested) so that the time
 * budget and the cancel callback are polled during long schedulings too. */
void ag__skel_work(sk *S, size_t n);
void ag__skel_compact_live(sk *S);
double ag__skel_seg_slope(const ag_profile *p, int32_t seg);
/* The point where the planes of three edges meet (local plan coordinates, virtual
 * height); 0 when they do not meet in one point. Taken in a fixed order of the planes'
 * coefficients, so the same planes give the same numbers whichever event asks (an edge
 * event and a split event of one vertex event coincide exactly): events are computed
 * from planes, never from corners propagated along (a corner between nearly parallel
 * edges moves at millions of metres per metre of height). */
int ag__skel_meet3(const sk *S, uint32_t e1, uint32_t e2, uint32_t e3, double *x, double *y,
                   double *z);
int ag__skel_seg_flat(const ag_profile *p, int32_t seg);

/* --- skel_event.c ------------------------------------------------------------------------ */
void ag__skel_schedule_touched(sk *S);
/* An event taken from the queue turned out stale: a corner whose first hit it was gets
 * its next one scheduled. */
void ag__skel_event_dropped(sk *S, const ag_event *ev);
/* Schedules corner k's first hit on an edge later than height `after` (a corner kept
 * through an intersection it only touched: that touch is not found again). */
void ag__skel_schedule_corner_after(sk *S, uint32_t k, double after);
int ag__skel_event_valid(sk *S, const ag_event *ev);
/* Handles the cluster of ev0, the lowest intersection event (valid, taken from the queue):
 * the valid events within delta1 above it whose plan points chain to its point within
 * the cluster radius are one generalized intersection (§4.4); the other events taken
 * while looking go back into the queue, to be handled after this one's consequences. */
void ag__skel_next_cluster(sk *S, const ag_event *ev0);

/* --- skel_intersection.c ----------------------------------------------------------------- */
void ag__skel_intersection(sk *S, ag_event *evs, size_t n);

/* --- skel_winding.c ---------------------------------------------------------------------- */
/* Once every event of a height has been handled: checks whether the edges of the corners
 * made there (S->made) cross live edges just above and, if they do, recomputes the active
 * plan's region boundaries by the winding rule (§4.4, post inter-chain intersections).
 * Empties S->made; 1 when the plan was rebuilt (new corners in S->touched). */
int ag__skel_winding_repair(sk *S);

/* --- skel_merge.c ------------------------------------------------------------------------ */
void ag__skel_settle(sk *S, uint32_t k);
/* Settles corner k unless it needs a collinear merge or a ridge zip and `defer` is set:
 * then it is left unsettled and 0 is returned (see sk.deferred). */
int ag__skel_settle_or_defer(sk *S, uint32_t k, int defer);

/* --- skel_profile.c ---------------------------------------------------------------------- */
void ag__skel_direction(sk *S, ag_event *evs, size_t n);
void ag__skel_insert_sides(sk *S, size_t k);
void ag__skel_insert_gap(sk *S, size_t k, double v);
void ag__skel_insert_bevels(sk *S, double v);

/* --- skel_step.c ------------------------------------------------------------------------- */
uint32_t ag__skel_make_edge(sk *S, double ax, double ay, double bx, double by, double slope,
                            double z, int32_t step, int32_t profile, int growing);
void ag__skel_insert_steps(sk *S, double v);

/* --- skel_forced.c ----------------------------------------------------------------------- */
void ag__skel_forced_step(sk *S, size_t k, double v);

/* --- skel_anchor.c ----------------------------------------------------------------------- */
/* Finds the active piece of an anchor's edge at height z and the point on it (local
 * coordinates); returns the edge or NONE. */
uint32_t ag__skel_anchor_point(sk *S, const ag_anchor *a, double z, double *px, double *py);
void ag__skel_locate_anchor(sk *S, ag_anchor *a, double z);
void ag__skel_cap(sk *S, double z);

#endif
