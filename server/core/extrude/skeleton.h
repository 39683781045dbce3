/* The sweep-plane weighted straight skeleton that turns a validated plan with per-edge
 * profiles into an architectural shell.
 *
 * A plane rises from z = 0; every active plan edge moves inwards by its profile
 * segment's slope per metre of height. Events are kept in a heap: edge events (an
 * edge shrinks to nothing), split events (a corner reaches another edge) and profile
 * direction events (a profile changes slope). Each event is computed from the planes
 * that meet there; the lowest one and the events at its point (within delta2 in plan, and
 * in height within what its corners move in delta2 or within the uncertainty of their
 * heights) are handled together as one generalized intersection, then the consequences are
 * scheduled before any later event: the corners that arrive are retired, edges passing
 * through the point are split, and the edges leaving the point are paired around it into
 * new corners (in the order their edges take just above the point). Neighbouring edges
 * that become collinear are resolved by the plan's priority scheme (the winner's plane
 * takes over), antiparallel neighbours (a ridge) are zipped. Horizontal profile segments,
 * profile offset events and natural steps each get a stretched interval of sweep height in
 * which only their edges move; forced steps are united with the active plan at their height.
 * An offset event's inside boundary (a gap between an outer and an inner shell) is opened
 * at the end of its interval from two insets of the active plan, each computed by a sweep
 * of its own (edges rising at their gap distance, cut at height 1). */
#ifndef AG_EXTRUDE_SKELETON_H
#define AG_EXTRUDE_SKELETON_H

#include <stddef.h>

#include "../status.h"
#include "budget.h"
#include "plan.h"
#include "shell.h"

typedef struct {
    /* the running budget account (shared with nested sweeps), or NULL: the defaults of
     * ag_extrude_budget for this plan */
    ag_budget *budget;
    /* plan->nanchors entries to locate (usually plan->anchors), or NULL */
    ag_anchor *anchors;
    /* 1: no post inter-chain repair (to compare with it in tests) */
    int no_winding_repair;
} ag_skeleton_options;

typedef struct {
    size_t intersections; /* generalized intersection events handled */
    size_t directions;    /* profile direction events handled */
    size_t zips, merges;  /* ridge zips and collinear merges */
    /* intersections whose edges did not alternate in and out around the point (nested
     * chains, §4.4's non-connected class): resolved by nesting the pairs, but the shape
     * there may be undesirable */
    size_t irregular;
    /* post inter-chain repair (§4.4): levels after which chains crossed just above, how
     * many of them were rebuilt by the winding rule and how many were left (a degenerate
     * contact the repair does not take), chain pieces the winding rule removed */
    size_t winding_invalid, winding_repairs, winding_refused, winding_pieces_dropped;
    /* heights with two horizontal faces or more, rebuilt as the difference of the plans
     * below and above, and left as they were (see flats.h) */
    size_t flat_levels, flat_rebuilt, flat_left;
    size_t steps, steps_skipped; /* plan edits made / not made (anchor not on the plan) */
    size_t offsets, offset_sides; /* offset events handled, side edges they made */
    size_t offset_gaps;   /* inside boundaries (gaps) opened by offset events */
    size_t bevels;        /* sharp corners of outward offsets cut by a bevel edge */
    int capped;           /* the top was closed flat */
    size_t events;        /* events taken from and put into the queue */
    double top;           /* highest height reached */
} ag_skeleton_stats;

/* plan must have passed ag_plan_validate (extent from it). The shell's faces are tagged
 * with loop/edge/profile/segment; it has been through ag_shell_finish. */
ag_status ag_skeleton_build(const ag_plan *plan, double extent, const ag_skeleton_options *opt,
                            ag_shell **out, ag_skeleton_stats *stats, ag_error *err);

#endif
