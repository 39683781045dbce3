/* A building plan for extrusion: polygons (outer rings counter-clockwise, holes
 * clockwise, inside on the left of every edge) with one profile per edge.
 *
 * A profile is a polyline (w, z) monotone in z, starting at (0, 0): w is the horizontal
 * offset towards the inside of the plan, z the height above the plan. Each segment is
 * a direction plane through the edge; its slope is dw/dz (0 = vertical wall, 1 = 45°,
 * negative = leaning outwards). The last segment continues upwards until the roof
 * closes or the plan's cap height is reached, where what is left is closed flat. */
#ifndef AG_EXTRUDE_PLAN_H
#define AG_EXTRUDE_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef struct {
    double w, z;
} ag_profile_point;

typedef struct {
    char *name;
    size_t npoints;
    ag_profile_point *points;
    /* Copied onto the faces the profile makes (e.g. "roof", "wall"); may be NULL. */
    char *tag;
} ag_profile;

typedef struct {
    size_t n;
    double *xy;        /* 2 * n corner coordinates */
    int32_t *profile;  /* n: profile of the edge from corner i to corner i+1 */
} ag_plan_loop;

typedef enum {
    AG_PRIORITY_MAX_VOLUME = 0, /* ambiguous collinear edges: the shallowest slope wins */
    AG_PRIORITY_MIN_VOLUME = 1, /* ... the steepest slope wins */
} ag_priority;

typedef struct {
    size_t nloops;
    ag_plan_loop *loops;
    size_t nprofiles;
    ag_profile *profiles;
    double cap_height; /* > 0: close the shell flat at this height */
    ag_priority priority;
    size_t cap_loops, cap_profiles; /* private */
} ag_plan;

ag_plan *ag_plan_create(void);
void ag_plan_free(ag_plan *p);

/* Adds a profile (points copied); fails with AG_ERR_INVALID when the points are not
 * monotone in z, do not start at (0, 0), hold NaN/inf or are fewer than two. */
ag_status ag_plan_add_profile(ag_plan *p, const char *name, const ag_profile_point *pts,
                              size_t n, const char *tag, size_t *index, ag_error *err);
/* Adds a loop of n corners (xy copied); profiles may be NULL (all edges profile 0). */
ag_status ag_plan_add_loop(ag_plan *p, const double *xy, size_t n, const int32_t *profiles,
                           ag_error *err);
/* Index of the profile with this name, or -1. */
int32_t ag_plan_find_profile(const ag_plan *p, const char *name);

/* What validation changed, one entry per cleaned corner or loop. */
typedef enum {
    AG_PLAN_FIX_DUPLICATE = 1, /* corner equal to the previous one: removed */
    AG_PLAN_FIX_COLLINEAR,     /* corner on a straight line with equal profiles: removed */
    AG_PLAN_FIX_SPIKE,         /* corner where the boundary turns back on itself: removed */
    AG_PLAN_FIX_REVERSED,      /* loop with the wrong orientation: reversed */
    AG_PLAN_FIX_DROPPED,       /* loop with no area left: removed */
} ag_plan_fix_kind;

typedef struct {
    ag_plan_fix_kind kind;
    long loop;   /* 0-based loop index in the input */
    long corner; /* 0-based corner index in the input loop, -1 for the whole loop */
    char reason[96];
} ag_plan_fix;

typedef struct {
    size_t n, cap;
    ag_plan_fix *fixes;
} ag_plan_fixes;

void ag_plan_fixes_free(ag_plan_fixes *f);

/* Validates and cleans the plan in place. Duplicate, collinear (same profile on both
 * sides) and spike corners are removed and loops are re-oriented (outer rings CCW,
 * holes CW by nesting depth), each change recorded in fixes (may be NULL). Fails with
 * AG_ERR_INVALID naming loop and corner for: NaN/inf coordinates, a profile index out
 * of range, two edges that cross or touch, a loop left with fewer than 3 corners when
 * it is the only one; AG_ERR_EMPTY when no loop is left. `extent` (may be NULL) gets
 * the plan's bounding-box diagonal. */
ag_status ag_plan_validate(ag_plan *p, ag_plan_fixes *fixes, double *extent, ag_error *err);

/* Signed area of a loop (positive = counter-clockwise). */
double ag_plan_loop_area(const ag_plan_loop *l);

#endif
