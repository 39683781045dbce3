/* A building plan for extrusion: polygons (outer rings counter-clockwise, holes
 * clockwise, inside on the left of every edge) with one profile per edge.
 *
 * A profile is a polyline (w, z) monotone in z, starting at (0, 0): w is the horizontal
 * offset towards the inside of the plan, z the height above the plan. Each segment is
 * a direction plane through the edge; its slope is dw/dz (0 = vertical wall, 1 = 45°,
 * negative = leaning outwards). A horizontal segment (equal z) offsets its edges by its
 * width at that height, making flat faces (a soffit when outwards, a terrace when
 * inwards) while the edges of other profiles wait. The last segment must rise; it
 * continues upwards until the roof closes or the plan's cap height is reached, where
 * what is left is closed flat. */
#ifndef AG_EXTRUDE_PLAN_H
#define AG_EXTRUDE_PLAN_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
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
    /* Ambiguity priority tag: when collinear neighbours with different slopes must
     * merge, the higher priority wins; equal priorities fall back to the plan's scheme. */
    int32_t priority;
    /* Per-segment priority tags (npoints - 1 entries) or NULL: the segment an edge is on
     * when the merge happens decides, overriding `priority`. */
    int32_t *seg_priority;
} ag_profile;

typedef struct {
    size_t n;
    double *xy;        /* 2 * n corner coordinates */
    int32_t *profile;  /* n: profile of the edge from corner i to corner i+1 */
} ag_plan_loop;

/* An anchor (a point to attach a mesh or a feature to): on plan edge `edge` of loop
 * `loop` (indices of the validated plan) at height z above the plan. Relative: at
 * fraction `along` of the edge as it is in the active plan at that height. Absolute: on
 * the plane perpendicular to the input edge at `along` metres from its first corner,
 * wherever the active edge is at that height (it may lie beyond the input edge's ends).
 * Not instanced when the edge no longer exists there or the point falls off it. */
typedef struct {
    char name[32];
    int32_t loop, edge;
    int absolute;
    double along, z;
    /* result of the extrusion */
    int found;
    double pos[3];
    double normal[3]; /* outward normal of the face there */
    int32_t face;     /* shell face holding the point */
    /* input: 1 + index into the plan's meshes of a mesh to place here, 0 = none */
    int32_t mesh;
    /* result: the active edge's direction there (horizontal, unit) */
    double tangent[3];
} ag_anchor;

/* A named mesh (a window, a door, an ornament) that anchors place on the shell. */
typedef struct {
    char name[32];
    ag_mesh *mesh; /* owned by the plan */
} ag_plan_mesh;

/* A plan edit made as a natural step: at anchor `at` (its height is the step's height)
 * a rectangle `width` wide and `depth` deep is added to the active plan (depth > 0:
 * protruding outwards, e.g. a dormer or a bay; depth < 0: a recess). Its new edges take
 * `profile`, whose heights count from the step's height. It grows from a tiny seed so it
 * meets the rest of the plan through ordinary events (never self-intersecting). */
typedef struct {
    char name[32];
    ag_anchor at;
    double width, depth;
    int32_t profile;
    /* A forced step when npoints > 0: the polygon `points` (2 * npoints) is united with
     * the active plan at the step's height, as it is, without growing (width and depth
     * are unused). Coordinates are in the anchor's frame (x along the active edge from
     * the anchor's point, y outwards, away from the inside) or, when `plan_frame` is set,
     * plan coordinates (then only at.z is used). The new boundary takes `profile`; the
     * part of the polygon outside the active plan gets a floor face. A polygon that
     * comes closer than 0.1 mm to the active boundary without crossing it cleanly, or
     * lies wholly inside the active plan, is skipped and counted. */
    size_t npoints;
    double *points;
    int plan_frame;
} ag_plan_step;

/* One edge's part in a profile offset event (§4.6's per-edge tuple). */
typedef struct {
    int32_t loop, edge; /* edge of the validated plan */
    int disabled;       /* no offset region on this edge: it waits (a gable end) */
    int has_outside;    /* use `outside` below instead of the event's */
    double outside;
    int32_t profile;    /* profile after the event, -1: the event's */
    /* the inside boundary (only with an event that has one): this edge's gap instead of
     * the event's, and its profiles as 1 + index (0: the event's) */
    int has_gap;
    double gap_from, gap_to;
    int32_t inside, inner;
} ag_offset_edge;

/* A profile offset event: at height z every active edge moves `outside` metres outwards
 * (negative: inwards) in one step, making a flat face (a soffit, a terrace), while the
 * disabled edges wait; then the moved edges take `profile` (heights from z; -1: they carry
 * on with their own profile). Where a moved edge meets a disabled one, the offset region
 * is cut along the mitre between the two by a new `side` edge that then follows the side
 * profile (-1: no side edge, the disabled edge's line is extended instead). Edges made by
 * plan edits take the event's defaults. */
typedef struct {
    double z;
    double outside;
    int32_t profile;
    int32_t side;
    size_t nedges;
    ag_offset_edge *edges; /* overrides, owned by the plan */
    /* An inside boundary (§4.6's dist_inside): when has_gap, at the end of the event's
     * interval a gap opens between gap_from and gap_to metres inside the active plan
     * (0 < gap_from < gap_to, per edge). The ring outside it is the outer shell (a
     * parapet, walls around a roof): its gap-facing edges take `inside`. What is inside
     * the gap is the inner shell: its edges take `inner` (-1: each carries on with the
     * profile of the edge it was inset from). The gap gets a flat floor facing up. */
    int has_gap;
    double gap_from, gap_to;
    int32_t inside, inner;
} ag_plan_offset;

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
    size_t nanchors;
    ag_anchor *anchors; /* located by the extrusion (found, pos, normal, face) */
    size_t nsteps;
    ag_plan_step *steps;
    size_t cap_loops, cap_profiles, cap_anchors, cap_steps; /* private */
    size_t nmeshes;
    ag_plan_mesh *meshes;
    size_t cap_meshes; /* private */
    size_t noffsets;
    ag_plan_offset *offsets;
    size_t cap_offsets; /* private */
} ag_plan;

ag_plan *ag_plan_create(void);
void ag_plan_free(ag_plan *p);

/* Adds a profile (points copied); fails with AG_ERR_INVALID when the points are not
 * monotone in z, do not start at (0, 0), hold NaN/inf, are fewer than two, end with a
 * segment that does not rise or hold two horizontal segments in a row. */
ag_status ag_plan_add_profile(ag_plan *p, const char *name, const ag_profile_point *pts,
                              size_t n, const char *tag, size_t *index, ag_error *err);
/* Adds a loop of n corners (xy copied); profiles may be NULL (all edges profile 0). */
ag_status ag_plan_add_loop(ag_plan *p, const double *xy, size_t n, const int32_t *profiles,
                           ag_error *err);
/* Adds an anchor (copied; name may be NULL). */
ag_status ag_plan_add_anchor(ag_plan *p, const ag_anchor *a, ag_error *err);
/* Adds a natural step (or a forced one, npoints > 0; the points are copied); fails with
 * AG_ERR_INVALID for a width or depth below 2 mm, a bad anchor, an unknown profile (add
 * the profile first), a forced polygon with fewer than 3 corners, non-finite or
 * self-intersecting, or a forced step's profile with a horizontal segment. */
ag_status ag_plan_add_step(ag_plan *p, const ag_plan_step *s, ag_error *err);
/* Tags segment `segment` of profile `profile` with an ambiguity priority (§4.8's
 * user-defined scheme); fails with AG_ERR_INVALID for an unknown profile or segment. */
ag_status ag_plan_set_segment_priority(ag_plan *p, size_t profile, size_t segment,
                                       int32_t priority, ag_error *err);
/* The priority in effect for an edge on `segment` of pr. */
int32_t ag_profile_priority(const ag_profile *pr, int32_t segment);
/* Adds a profile offset event (edges copied); fails with AG_ERR_INVALID for a height
 * that is not > 0, a non-finite distance, an unknown profile or one with a horizontal
 * segment (after, side, inside, inner), an edge override naming no loop/edge of the plan
 * as it is, or a gap that is not 0 < gap_from < gap_to (an edge's gap without the
 * event's, an event gap without an `inside` profile). */
ag_status ag_plan_add_offset(ag_plan *p, const ag_plan_offset *o, ag_error *err);
/* Adds a named mesh for anchors to place; the plan takes ownership of mesh (also on
 * failure). *index (may be NULL) gets its index; anchors refer to it as index + 1. */
ag_status ag_plan_add_mesh(ag_plan *p, const char *name, ag_mesh *mesh, size_t *index,
                           ag_error *err);
/* Index of the mesh with this name, or -1. */
int32_t ag_plan_find_mesh(const ag_plan *p, const char *name);
/* Index of the profile with this name, or -1. */
int32_t ag_plan_find_profile(const ag_plan *p, const char *name);

/* What validation changed, one entry per cleaned corner or loop. */
typedef enum {
    AG_PLAN_FIX_DUPLICATE = 1, /* corner equal to the previous one: removed */
    AG_PLAN_FIX_COLLINEAR,     /* corner on a straight line with equal profiles: removed */
    AG_PLAN_FIX_SPIKE,         /* corner where the boundary turns back on itself: removed */
    AG_PLAN_FIX_REVERSED,      /* loop with the wrong orientation: reversed */
    AG_PLAN_FIX_DROPPED,       /* loop with no area left: removed */
    AG_PLAN_FIX_TOUCH,         /* a corner on another loop: moved a hair off it */
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
 * holes CW by nesting depth), each change recorded in fixes (may be NULL). Two loops
 * may touch at single points (a hole touching the outer ring, parts meeting at a corner,
 * as OGC allows): the touching corner is moved AG_EXTRUDE_TOUCH_GAP (relative) off the
 * other loop, into its own loop's region, so walls on both never share an edge (recorded). Fails
 * with AG_ERR_INVALID naming loop and edges for: NaN/inf coordinates, a profile index out
 * of range, two edges that cross (also two loops crossing at a shared point), edges that
 * overlap, a loop touching itself; AG_ERR_EMPTY when no loop is left ("edge 1 crosses
 * edge 3" for a bow tie, which has no area). Decisions use the exact predicates.
 * `extent` (may be NULL) gets the plan's bounding-box diagonal. */
ag_status ag_plan_validate(ag_plan *p, ag_plan_fixes *fixes, double *extent, ag_error *err);

/* Signed area of a loop (positive = counter-clockwise). */
double ag_plan_loop_area(const ag_plan_loop *l);

#endif
