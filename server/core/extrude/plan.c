#include "plan.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "predicates.h"
#include "../base/tolerance.h"

ag_plan *ag_plan_create(void)
{
    return calloc(1, sizeof(ag_plan));
}

void ag_plan_free(ag_plan *p)
{
    if (!p)
        return;
    for (size_t i = 0; i < p->nloops; i++) {
        free(p->loops[i].xy);
        free(p->loops[i].profile);
    }
    for (size_t i = 0; i < p->nprofiles; i++) {
        free(p->profiles[i].name);
        free(p->profiles[i].points);
        free(p->profiles[i].tag);
        free(p->profiles[i].seg_priority);
    }
    free(p->loops);
    free(p->profiles);
    free(p->anchors);
    for (size_t i = 0; i < p->nsteps; i++)
        free(p->steps[i].points);
    free(p->steps);
    for (size_t i = 0; i < p->nmeshes; i++)
        ag_mesh_free(p->meshes[i].mesh);
    free(p->meshes);
    for (size_t i = 0; i < p->noffsets; i++)
        free(p->offsets[i].edges);
    free(p->offsets);
    free(p);
}

void ag_plan_fixes_free(ag_plan_fixes *f)
{
    if (!f)
        return;
    free(f->fixes);
    f->fixes = NULL;
    f->n = f->cap = 0;
}

static char *dupstr(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

ag_status ag_plan_add_profile(ag_plan *p, const char *name, const ag_profile_point *pts,
                              size_t n, const char *tag, size_t *index, ag_error *err)
{
    long idx = (long)p->nprofiles;
    if (n < 2)
        return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                            "profile %s: needs at least two points", name ? name : "");
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(pts[i].w) || !isfinite(pts[i].z))
            return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                                "profile %s: point %zu is not finite", name ? name : "", i);
        if (i > 0 && pts[i].z < pts[i - 1].z)
            return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                                "profile %s: point %zu is lower than point %zu (profiles must "
                                "be monotone in z)", name ? name : "", i, i - 1);
    }
    if (pts[0].w != 0.0 || pts[0].z != 0.0)
        return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                            "profile %s: must start at (0, 0)", name ? name : "");
    if (pts[n - 1].z <= pts[n - 2].z)
        return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                            "profile %s: the last segment must rise (it continues upwards)",
                            name ? name : "");
    for (size_t i = 0; i + 2 < n; i++)
        if (pts[i + 1].z == pts[i].z && pts[i + 2].z == pts[i + 1].z)
            return ag_error_set(err, AG_ERR_INVALID, idx + 1,
                                "profile %s: segments %zu and %zu are both horizontal (join them)",
                                name ? name : "", i, i + 1);
    if (AG_ARRAY_RESERVE(p->profiles, p->cap_profiles, p->nprofiles + 1) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_profile *pr = &p->profiles[p->nprofiles];
    memset(pr, 0, sizeof *pr);
    pr->points = malloc(n * sizeof *pr->points);
    pr->name = dupstr(name ? name : "");
    pr->tag = dupstr(tag);
    if (!pr->points || !pr->name || (tag && !pr->tag)) {
        free(pr->points);
        free(pr->name);
        free(pr->tag);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    memcpy(pr->points, pts, n * sizeof *pts);
    pr->npoints = n;
    if (index)
        *index = p->nprofiles;
    p->nprofiles++;
    return AG_OK;
}

ag_status ag_plan_add_loop(ag_plan *p, const double *xy, size_t n, const int32_t *profiles,
                           ag_error *err)
{
    if (AG_ARRAY_RESERVE(p->loops, p->cap_loops, p->nloops + 1) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_plan_loop *l = &p->loops[p->nloops];
    l->n = n;
    l->xy = malloc((n ? n : 1) * 2 * sizeof(double));
    l->profile = malloc((n ? n : 1) * sizeof(int32_t));
    if (!l->xy || !l->profile) {
        free(l->xy);
        free(l->profile);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (n)
        memcpy(l->xy, xy, n * 2 * sizeof(double));
    for (size_t i = 0; i < n; i++)
        l->profile[i] = profiles ? profiles[i] : 0;
    p->nloops++;
    return AG_OK;
}

static int profile_ok(const ag_plan *p, int32_t k, int allow_none)
{
    if (k < 0)
        return allow_none && k == -1;
    if ((size_t)k >= p->nprofiles)
        return 0;
    const ag_profile *pr = &p->profiles[k];
    for (size_t i = 0; i + 1 < pr->npoints; i++)
        if (pr->points[i].z == pr->points[i + 1].z)
            return 0;
    return 1;
}

static int gap_ok(double from, double to)
{
    return isfinite(from) && isfinite(to) && from > 0 && to > from;
}

ag_status ag_plan_add_offset(ag_plan *p, const ag_plan_offset *o, ag_error *err)
{
    long idx = (long)p->noffsets + 1;
    if (!isfinite(o->z) || o->z <= 0 || !isfinite(o->outside))
        return ag_error_set(err, AG_ERR_INVALID, idx,
                            "offset %zu: height must be > 0 and the distance finite", p->noffsets);
    if (!profile_ok(p, o->profile, 1) || !profile_ok(p, o->side, 1))
        return ag_error_set(err, AG_ERR_INVALID, idx,
                            "offset %zu: unknown profile, or one with a horizontal segment (its "
                            "heights count from the event)", p->noffsets);
    for (size_t i = 0; i < o->nedges; i++) {
        const ag_offset_edge *e = &o->edges[i];
        if (e->loop < 0 || (size_t)e->loop >= p->nloops || e->edge < 0 ||
            (size_t)e->edge >= p->loops[e->loop].n)
            return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: edges[%zu] names no edge "
                                "of the plan (loop %d, edge %d)", p->noffsets, i, (int)e->loop,
                                (int)e->edge);
        if ((e->has_outside && !isfinite(e->outside)) || !profile_ok(p, e->profile, 1) ||
            !profile_ok(p, e->inside - 1, 1) || !profile_ok(p, e->inner - 1, 1))
            return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: edges[%zu] has a bad "
                                "distance or profile", p->noffsets, i);
        if ((e->has_gap || e->inside || e->inner) && !o->has_gap)
            return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: edges[%zu] has an inside "
                                "boundary but the event has none", p->noffsets, i);
        if (e->has_gap && !gap_ok(e->gap_from, e->gap_to))
            return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: edges[%zu] needs a gap "
                                "0 < from < to", p->noffsets, i);
    }
    if (o->has_gap && !gap_ok(o->gap_from, o->gap_to))
        return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: the inside boundary needs a "
                            "gap 0 < from < to", p->noffsets);
    if (o->has_gap && (o->inside < 0 || !profile_ok(p, o->inside, 0) || !profile_ok(p, o->inner, 1)))
        return ag_error_set(err, AG_ERR_INVALID, idx, "offset %zu: the inside boundary needs an "
                            "inside profile, and profiles without horizontal segments", p->noffsets);
    if (AG_ARRAY_RESERVE(p->offsets, p->cap_offsets, p->noffsets + 1) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_plan_offset *d = &p->offsets[p->noffsets];
    *d = *o;
    d->edges = NULL;
    if (o->nedges) {
        d->edges = malloc(o->nedges * sizeof *d->edges);
        if (!d->edges)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        memcpy(d->edges, o->edges, o->nedges * sizeof *d->edges);
    }
    p->noffsets++;
    return AG_OK;
}

ag_status ag_plan_add_mesh(ag_plan *p, const char *name, ag_mesh *mesh, size_t *index,
                           ag_error *err)
{
    if (!mesh)
        return ag_error_set(err, AG_ERR_INVALID, 0, "mesh %s: no mesh", name ? name : "");
    if (AG_ARRAY_RESERVE(p->meshes, p->cap_meshes, p->nmeshes + 1) != AG_OK) {
        ag_mesh_free(mesh);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_plan_mesh *d = &p->meshes[p->nmeshes];
    snprintf(d->name, sizeof d->name, "%s", name ? name : "");
    d->mesh = mesh;
    if (index)
        *index = p->nmeshes;
    p->nmeshes++;
    return AG_OK;
}

int32_t ag_plan_find_mesh(const ag_plan *p, const char *name)
{
    for (size_t i = 0; i < p->nmeshes; i++)
        if (strcmp(p->meshes[i].name, name) == 0)
            return (int32_t)i;
    return -1;
}

ag_status ag_plan_add_anchor(ag_plan *p, const ag_anchor *a, ag_error *err)
{
    if (a->mesh < 0 || (size_t)a->mesh > p->nmeshes)
        return ag_error_set(err, AG_ERR_INVALID, (long)p->nanchors + 1,
                            "anchor %zu: mesh %d is not one of the plan's %zu meshes", p->nanchors,
                            (int)a->mesh - 1, p->nmeshes);
    if (!isfinite(a->along) || !isfinite(a->z) || a->z < 0 || (!a->absolute && (a->along < 0 || a->along > 1)))
        return ag_error_set(err, AG_ERR_INVALID, (long)p->nanchors + 1,
                            "anchor %zu: height must be >= 0 and a relative position in [0, 1]",
                            p->nanchors);
    if (AG_ARRAY_RESERVE(p->anchors, p->cap_anchors, p->nanchors + 1) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_anchor *d = &p->anchors[p->nanchors++];
    *d = *a;
    d->name[sizeof d->name - 1] = 0;
    d->found = 0;
    d->face = -1;
    return AG_OK;
}

/* A forced step's polygon: enough finite corners, simple, with area; its profile
 * without horizontal segments (their heights would not follow the step's). */
static ag_status check_forced(const ag_plan *p, const ag_plan_step *s, ag_error *err)
{
    long idx = (long)p->nsteps + 1;
    size_t n = s->npoints;
    const double *q = s->points;
    if (n < 3 || !q)
        return ag_error_set(err, AG_ERR_INVALID, idx, "step %zu: a forced step needs at least 3 "
                            "corners", p->nsteps);
    for (size_t i = 0; i < 2 * n; i++)
        if (!isfinite(q[i]))
            return ag_error_set(err, AG_ERR_INVALID, idx, "step %zu: corner %zu is not finite",
                                p->nsteps, i / 2);
    double area = 0, ext = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        area += q[2 * i] * q[2 * j + 1] - q[2 * j] * q[2 * i + 1];
        ext = fmax(ext, hypot(q[2 * j] - q[2 * i], q[2 * j + 1] - q[2 * i + 1]));
    }
    if (!(fabs(area) / 2 > 1e-6))
        return ag_error_set(err, AG_ERR_INVALID, idx, "step %zu: the forced polygon has no area",
                            p->nsteps);
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            size_t i2 = (i + 1) % n, j2 = (j + 1) % n;
            if (j == i2 || i == j2)
                continue; /* neighbours share a corner */
            if (ag_pred_segments_touch(&q[2 * i], &q[2 * i2], &q[2 * j], &q[2 * j2]))
                return ag_error_set(err, AG_ERR_INVALID, idx,
                                    "step %zu: forced polygon edges %zu and %zu cross or touch",
                                    p->nsteps, i, j);
        }
    if (s->profile >= 0 && (size_t)s->profile < p->nprofiles) {
        const ag_profile *pr = &p->profiles[s->profile];
        for (size_t k = 0; k + 1 < pr->npoints; k++)
            if (pr->points[k].z == pr->points[k + 1].z)
                return ag_error_set(err, AG_ERR_INVALID, idx,
                                    "step %zu: a forced step's profile (%s) must not have "
                                    "horizontal segments", p->nsteps, pr->name);
    }
    return AG_OK;
}

ag_status ag_plan_add_step(ag_plan *p, const ag_plan_step *s, ag_error *err)
{
    long idx = (long)p->nsteps + 1;
    int forced = s->npoints > 0;
    if (forced) {
        ag_status fs = check_forced(p, s, err);
        if (fs != AG_OK)
            return fs;
    } else if (!(s->width >= 2e-3) || !(fabs(s->depth) >= 2e-3) || !isfinite(s->width) ||
        !isfinite(s->depth))
        return ag_error_set(err, AG_ERR_INVALID, idx,
                            "step %zu: width and |depth| must be at least 2 mm", p->nsteps);
    if (s->profile < 0 || (size_t)s->profile >= p->nprofiles)
        return ag_error_set(err, AG_ERR_INVALID, idx, "step %zu: unknown profile %d", p->nsteps,
                            (int)s->profile);
    const ag_profile *pr = &p->profiles[s->profile];
    if (pr->points[1].z <= 0)
        return ag_error_set(err, AG_ERR_INVALID, idx,
                            "step %zu: the step's profile must rise from its first point",
                            p->nsteps);
    if (!isfinite(s->at.z) || s->at.z <= 0 ||
        (!(forced && s->plan_frame) &&
         (!isfinite(s->at.along) || (!s->at.absolute && (s->at.along < 0 || s->at.along > 1)))))
        return ag_error_set(err, AG_ERR_INVALID, idx,
                            "step %zu: height must be > 0 and a relative position in [0, 1]",
                            p->nsteps);
    if (AG_ARRAY_RESERVE(p->steps, p->cap_steps, p->nsteps + 1) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_plan_step *d = &p->steps[p->nsteps];
    *d = *s;
    d->name[sizeof s->name - 1] = 0;
    if (forced) {
        d->points = malloc(2 * s->npoints * sizeof *d->points);
        if (!d->points)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        memcpy(d->points, s->points, 2 * s->npoints * sizeof *d->points);
    } else {
        d->points = NULL;
    }
    p->nsteps++;
    return AG_OK;
}

ag_status ag_plan_set_segment_priority(ag_plan *p, size_t profile, size_t segment,
                                       int32_t priority, ag_error *err)
{
    if (profile >= p->nprofiles)
        return ag_error_set(err, AG_ERR_INVALID, 0, "segment priority: unknown profile %zu",
                            profile);
    ag_profile *pr = &p->profiles[profile];
    if (segment + 1 >= pr->npoints)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "profile %s: segment %zu does not exist (it has %zu)", pr->name,
                            segment, pr->npoints - 1);
    if (!pr->seg_priority) {
        pr->seg_priority = malloc((pr->npoints - 1) * sizeof *pr->seg_priority);
        if (!pr->seg_priority)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        for (size_t i = 0; i + 1 < pr->npoints; i++)
            pr->seg_priority[i] = pr->priority;
    }
    pr->seg_priority[segment] = priority;
    return AG_OK;
}

int32_t ag_profile_priority(const ag_profile *pr, int32_t segment)
{
    if (pr->seg_priority && segment >= 0 && (size_t)segment + 1 < pr->npoints)
        return pr->seg_priority[segment];
    return pr->priority;
}

int32_t ag_plan_find_profile(const ag_plan *p, const char *name)
{
    for (size_t i = 0; i < p->nprofiles; i++)
        if (p->profiles[i].name && strcmp(p->profiles[i].name, name) == 0)
            return (int32_t)i;
    return -1;
}

double ag_plan_loop_area(const ag_plan_loop *l)
{
    long double a = 0;
    for (size_t i = 0, j = l->n - 1; i < l->n; j = i++)
        a += (long double)l->xy[2 * j] * l->xy[2 * i + 1] -
             (long double)l->xy[2 * i] * l->xy[2 * j + 1];
    return (double)(a / 2);
}

static void add_fix(ag_plan_fixes *f, ag_plan_fix_kind kind, long loop, long corner,
                    const char *reason)
{
    if (!f)
        return;
    if (AG_ARRAY_RESERVE(f->fixes, f->cap, f->n + 1) != AG_OK)
        return; /* the record is informative; losing it under memory pressure is fine */
    ag_plan_fix *x = &f->fixes[f->n++];
    x->kind = kind;
    x->loop = loop;
    x->corner = corner;
    snprintf(x->reason, sizeof x->reason, "%s", reason);
}

/* Removes duplicate, collinear and spike corners of one loop; `orig` maps the kept
 * corners back to input indices for the messages. A spike is removed while it is no wider
 * than `narrow` (AG_VERIFY_WINDING_PROBE): its two walls could neither stay apart in the
 * shell nor be told apart by the building check. */
static void clean_loop(ag_plan_loop *l, long li, long *orig, double d2, double narrow,
                       ag_plan_fixes *fx)
{
    int changed = 1;
    while (changed && l->n >= 3) {
        changed = 0;
        for (size_t i = 0; i < l->n && l->n >= 3; i++) {
            size_t pi = (i + l->n - 1) % l->n, ni = (i + 1) % l->n;
            const double *a = &l->xy[2 * pi], *b = &l->xy[2 * i], *c = &l->xy[2 * ni];
            double abx = b[0] - a[0], aby = b[1] - a[1], bcx = c[0] - b[0], bcy = c[1] - b[1];
            double lab = hypot(abx, aby), lbc = hypot(bcx, bcy);
            ag_plan_fix_kind kind = 0;
            const char *why = NULL;
            if (lab <= d2) {
                kind = AG_PLAN_FIX_DUPLICATE;
                why = "duplicate corner (same position as the previous one) removed";
            } else if (lbc > d2) {
                double cr = abx * bcy - aby * bcx, dt = abx * bcx + aby * bcy;
                /* distance of b from the line ac, relative to the shorter edge */
                double h = fabs(cr) / (lab > lbc ? lab : lbc);
                if (h <= narrow && dt < 0) {
                    kind = AG_PLAN_FIX_SPIKE;
                    why = "spike (the boundary turns back on itself) removed";
                } else if (h <= d2 && l->profile[pi] == l->profile[i]) {
                    kind = AG_PLAN_FIX_COLLINEAR;
                    why = "collinear corner with the same profile on both edges removed";
                }
            }
            if (!kind)
                continue;
            add_fix(fx, kind, li, orig[i], why);
            /* drop corner i; the edge i (from i to i+1) goes, edge pi now reaches i+1 */
            memmove(&l->xy[2 * i], &l->xy[2 * (i + 1)], (l->n - i - 1) * 2 * sizeof(double));
            memmove(&l->profile[i], &l->profile[i + 1], (l->n - i - 1) * sizeof(int32_t));
            memmove(&orig[i], &orig[i + 1], (l->n - i - 1) * sizeof(long));
            l->n--;
            changed = 1;
            i = i > 0 ? i - 1 : 0;
        }
    }
}

typedef struct {
    double xmin, xmax;
    uint32_t loop, idx;
} seg_box;

static int cmp_seg(const void *a, const void *b)
{
    const seg_box *x = a, *y = b;
    return x->xmin < y->xmin ? -1 : x->xmin > y->xmin;
}

static int sgn(double v)
{
    return v > 0 ? 1 : v < 0 ? -1 : 0;
}

/* Which half of the plane around the origin direction d lies in (0: angle in [0, pi)). */
static int half(const double *d)
{
    return d[1] < 0 || (d[1] == 0 && d[0] < 0);
}

/* Exact angular order of two directions (counter-clockwise from +x). */
static int angle_before(const double *u, const double *v)
{
    int hu = half(u), hv = half(v);
    if (hu != hv)
        return hu < hv;
    return ag_pred_cross_sign(u[0], u[1], v[0], v[1]) > 0;
}

/* Do two loops that meet at point v cross there? a0, a1 are the points the first loop's
 * boundary goes to from v (its neighbours there), b0, b1 the second's: they cross when,
 * around v, the directions of one pair separate those of the other. */
static int cross_at(const double *v, const double *a0, const double *a1, const double *b0,
                    const double *b1)
{
    double d[4][2] = {{a0[0] - v[0], a0[1] - v[1]}, {a1[0] - v[0], a1[1] - v[1]},
                      {b0[0] - v[0], b0[1] - v[1]}, {b1[0] - v[0], b1[1] - v[1]}};
    /* a direction shared by both: they run along each other there, an overlap that the
     * overlapping segments themselves report */
    for (int i = 0; i < 2; i++)
        for (int j = 2; j < 4; j++)
            if (ag_pred_cross_sign(d[i][0], d[i][1], d[j][0], d[j][1]) == 0 &&
                d[i][0] * d[j][0] + d[i][1] * d[j][1] > 0)
                return 0;
    int who[4] = {0, 0, 1, 1}, order[4] = {0, 1, 2, 3};
    for (int i = 1; i < 4; i++)
        for (int j = i; j > 0 && angle_before(d[order[j]], d[order[j - 1]]); j--) {
            int x = order[j];
            order[j] = order[j - 1];
            order[j - 1] = x;
        }
    /* interleaved: A B A B around v */
    return who[order[0]] != who[order[1]] && who[order[1]] != who[order[2]] &&
           who[order[2]] != who[order[3]];
}

/* How segments a0-a1 and b0-b1 meet. */
typedef enum { MEET_NONE, MEET_CROSS, MEET_OVERLAP, MEET_POINT } meet;

static meet segments_meet(const double *a0, const double *a1, const double *b0,
                          const double *b1, double *at)
{
    int o1 = sgn(ag_pred_orient2d(a0, a1, b0)), o2 = sgn(ag_pred_orient2d(a0, a1, b1));
    int o3 = sgn(ag_pred_orient2d(b0, b1, a0)), o4 = sgn(ag_pred_orient2d(b0, b1, a1));
    if (o1 * o2 < 0 && o3 * o4 < 0) {
        double t = ag_pred_orient2d(b0, b1, a0) /
                   (ag_pred_orient2d(b0, b1, a0) - ag_pred_orient2d(b0, b1, a1));
        at[0] = a0[0] + t * (a1[0] - a0[0]);
        at[1] = a0[1] + t * (a1[1] - a0[1]);
        return MEET_CROSS;
    }
    if (!o1 && !o2) {
        /* collinear: along the longer axis, do the intervals share more than a point? */
        int k = fabs(a1[0] - a0[0]) + fabs(b1[0] - b0[0]) >= fabs(a1[1] - a0[1]) + fabs(b1[1] - b0[1])
                    ? 0 : 1;
        double alo = fmin(a0[k], a1[k]), ahi = fmax(a0[k], a1[k]);
        double blo = fmin(b0[k], b1[k]), bhi = fmax(b0[k], b1[k]);
        double lo = fmax(alo, blo), hi = fmin(ahi, bhi);
        if (lo > hi)
            return MEET_NONE;
        if (lo < hi) {
            const double *p = a0[k] == lo ? a0 : a1[k] == lo ? a1 : b0[k] == lo ? b0 : b1;
            at[0] = p[0];
            at[1] = p[1];
            return MEET_OVERLAP;
        }
        const double *p = alo == lo || ahi == lo ? (a0[k] == lo ? a0 : a1) : (b0[k] == lo ? b0 : b1);
        at[0] = p[0];
        at[1] = p[1];
        return MEET_POINT;
    }
    const double *pts[4] = {b0, b1, a0, a1};
    int os[4] = {o1, o2, o3, o4};
    for (int i = 0; i < 4; i++) {
        if (os[i])
            continue;
        const double *p = pts[i], *s0 = i < 2 ? a0 : b0, *s1 = i < 2 ? a1 : b1;
        if (p[0] >= fmin(s0[0], s1[0]) && p[0] <= fmax(s0[0], s1[0]) &&
            p[1] >= fmin(s0[1], s1[1]) && p[1] <= fmax(s0[1], s1[1])) {
            at[0] = p[0];
            at[1] = p[1];
            return MEET_POINT;
        }
    }
    return MEET_NONE;
}

/* The points loop l's boundary goes to from point v, where v is corner i (on_edge 0) or
 * lies inside edge i (on_edge 1). */
static void neighbours_at(const ag_plan_loop *l, size_t i, int on_edge, const double **n0,
                          const double **n1)
{
    size_t n = l->n;
    if (on_edge) {
        *n0 = &l->xy[2 * i];
        *n1 = &l->xy[2 * ((i + 1) % n)];
    } else {
        *n0 = &l->xy[2 * ((i + n - 1) % n)];
        *n1 = &l->xy[2 * ((i + 1) % n)];
    }
}

/* Where boundary `edge` of loop l meets point v: as its corner (v equals one end: the
 * corner's index and 0) or inside it (edge, 1). */
static void locate_on(const ag_plan_loop *l, size_t edge, const double *v, size_t *i, int *on_edge)
{
    const double *a = &l->xy[2 * edge], *b = &l->xy[2 * ((edge + 1) % l->n)];
    if (a[0] == v[0] && a[1] == v[1]) {
        *i = edge;
        *on_edge = 0;
    } else if (b[0] == v[0] && b[1] == v[1]) {
        *i = (edge + 1) % l->n;
        *on_edge = 0;
    } else {
        *i = edge;
        *on_edge = 1;
    }
}

/* Edges that cross, overlap, or touch (within one loop) are refused, naming both edges by
 * their input numbers; two loops may touch at single points (OGC-valid holes touching the
 * outer ring, parts of a MultiPolygon meeting at a corner) as long as they do not cross
 * there. `only` limits the check to loop `only` (>= 0) and to proper crossings. */
static ag_status check_crossings(const ag_plan *p, long **orig, const long *oloop, long only,
                                 ag_error *err)
{
    size_t total = 0;
    for (size_t i = 0; i < p->nloops; i++)
        if (only < 0 || (long)i == only)
            total += p->loops[i].n;
    seg_box *s = malloc((total ? total : 1) * sizeof *s);
    if (!s)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t k = 0;
    for (size_t i = 0; i < p->nloops; i++) {
        const ag_plan_loop *l = &p->loops[i];
        if (only >= 0 && (long)i != only)
            continue;
        for (size_t j = 0; j < l->n; j++) {
            double x0 = l->xy[2 * j], x1 = l->xy[2 * ((j + 1) % l->n)];
            s[k].xmin = x0 < x1 ? x0 : x1;
            s[k].xmax = x0 < x1 ? x1 : x0;
            s[k].loop = (uint32_t)i;
            s[k].idx = (uint32_t)j;
            k++;
        }
    }
    qsort(s, total, sizeof *s, cmp_seg);
    ag_status st = AG_OK;
    for (size_t i = 0; i < total && st == AG_OK; i++) {
        const ag_plan_loop *la = &p->loops[s[i].loop];
        size_t a0 = s[i].idx, a1 = (a0 + 1) % la->n;
        for (size_t j = i + 1; j < total && s[j].xmin <= s[i].xmax; j++) {
            const ag_plan_loop *lb = &p->loops[s[j].loop];
            size_t b0 = s[j].idx, b1 = (b0 + 1) % lb->n;
            int same = s[i].loop == s[j].loop;
            if (same && (a1 == b0 || b1 == a0))
                continue; /* neighbours share a corner */
            double at[2] = {0, 0};
            meet how = segments_meet(&la->xy[2 * a0], &la->xy[2 * a1], &lb->xy[2 * b0],
                                     &lb->xy[2 * b1], at);
            if (how == MEET_NONE || (only >= 0 && how != MEET_CROSS))
                continue;
            if (how == MEET_POINT && !same) {
                /* a touch between two loops: allowed unless they cross there */
                size_t ia, ib;
                int ea, eb;
                const double *pa0, *pa1, *pb0, *pb1;
                locate_on(la, a0, at, &ia, &ea);
                locate_on(lb, b0, at, &ib, &eb);
                neighbours_at(la, ia, ea, &pa0, &pa1);
                neighbours_at(lb, ib, eb, &pb0, &pb1);
                if (!cross_at(at, pa0, pa1, pb0, pb1))
                    continue;
                how = MEET_CROSS;
            }
            const char *verb = how == MEET_CROSS ? "crosses" : how == MEET_OVERLAP ? "overlaps"
                                                                                   : "touches";
            long ea_ = orig[s[i].loop][a0], eb_ = orig[s[j].loop][b0];
            long la_ = oloop[s[i].loop], lb_ = oloop[s[j].loop];
            if (same && ea_ > eb_) {
                long x = ea_;
                ea_ = eb_;
                eb_ = x;
            }
            /* (the rule, in the words earlier messages used, ends every message) */
            if (same && how == MEET_CROSS)
                st = ag_error_set(err, AG_ERR_INVALID, la_ + 1, "loop %ld: edge %ld crosses "
                                  "edge %ld at (%.6g, %.6g); an edge that crosses or touches "
                                  "another is refused", la_, ea_, eb_, at[0], at[1]);
            else if (same)
                st = ag_error_set(err, AG_ERR_INVALID, la_ + 1, "loop %ld: edge %ld %s edge %ld "
                                  "at (%.6g, %.6g); a ring may not touch itself: an edge that "
                                  "crosses or touches another is refused", la_, ea_, verb, eb_,
                                  at[0], at[1]);
            else
                st = ag_error_set(err, AG_ERR_INVALID, la_ + 1, "loop %ld edge %ld %s loop %ld "
                                  "edge %ld at (%.6g, %.6g); an edge that crosses or touches "
                                  "another is refused (loops may meet at single points)", la_,
                                  ea_, verb, lb_, eb_, at[0], at[1]);
            break;
        }
    }
    free(s);
    return st;
}

/* Is v inside segment a-b (not at its ends)? Exact. */
static int inside_segment(const double *a, const double *b, const double *v)
{
    if ((v[0] == a[0] && v[1] == a[1]) || (v[0] == b[0] && v[1] == b[1]))
        return 0;
    return ag_pred_orient2d(a, b, v) == 0 && v[0] >= fmin(a[0], b[0]) &&
           v[0] <= fmax(a[0], b[0]) && v[1] >= fmin(a[1], b[1]) && v[1] <= fmax(a[1], b[1]);
}

/* Where two loops touch at a point (a corner of one on the other's edge or corner), the
 * walls standing on both would share an edge, which no closed 2-manifold may: the touching
 * corner (of the later loop when both have one there) is moved AG_EXTRUDE_TOUCH_GAP into
 * the region its own loop encloses, so the two no longer meet. Recorded as a fix. */
static ag_status separate_touches(ag_plan *p, const long *oloop, long **orig, double gap,
                                  ag_plan_fixes *fixes)
{
    for (size_t b = 0; b < p->nloops; b++) {
        ag_plan_loop *lb = &p->loops[b];
        for (size_t i = 0; i < lb->n; i++) {
            double *v = &lb->xy[2 * i];
            long other = -1;
            for (size_t a = 0; a < p->nloops && other < 0; a++) {
                if (a == b)
                    continue;
                const ag_plan_loop *la = &p->loops[a];
                for (size_t e = 0; e < la->n && other < 0; e++) {
                    const double *q = &la->xy[2 * e], *r = &la->xy[2 * ((e + 1) % la->n)];
                    int corner = q[0] == v[0] && q[1] == v[1];
                    if ((corner && a < b) || inside_segment(q, r, v))
                        other = (long)a;
                }
            }
            if (other < 0)
                continue;
            const double *pv = &lb->xy[2 * ((i + lb->n - 1) % lb->n)];
            const double *nv = &lb->xy[2 * ((i + 1) % lb->n)];
            double ux = pv[0] - v[0], uy = pv[1] - v[1], wx = nv[0] - v[0], wy = nv[1] - v[1];
            double lu = hypot(ux, uy), lw = hypot(wx, wy);
            double bx = ux / lu + wx / lw, by = uy / lu + wy / lw, bl = hypot(bx, by);
            if (!(bl > 0)) {
                bx = -uy / lu; /* a straight corner: perpendicular */
                by = ux / lu;
                bl = 1;
            }
            double step = gap / fmax(bl / 2, 0.1); /* along the bisector: off both edges by gap */
            double cand[2] = {v[0] + step * bx / bl, v[1] + step * by / bl};
            if (!ag_pred_point_in_polygon(lb->xy, lb->n, cand[0], cand[1])) {
                cand[0] = v[0] - step * bx / bl;
                cand[1] = v[1] - step * by / bl;
            }
            char why[96];
            snprintf(why, sizeof why, "touches loop %ld at (%.6g, %.6g): moved %.2g m off it",
                     oloop[other], v[0], v[1], hypot(cand[0] - v[0], cand[1] - v[1]));
            add_fix(fixes, AG_PLAN_FIX_TOUCH, oloop[b], orig[b][i], why);
            v[0] = cand[0];
            v[1] = cand[1];
        }
    }
    return AG_OK;
}

/* A corner of loop l that is not on loop m's boundary (for testing nesting), or NULL. */
static const double *free_corner(const ag_plan_loop *l, const ag_plan_loop *m)
{
    for (size_t i = 0; i < l->n; i++) {
        const double *v = &l->xy[2 * i];
        int on = 0;
        for (size_t j = 0; j < m->n && !on; j++) {
            const double *a = &m->xy[2 * j], *b = &m->xy[2 * ((j + 1) % m->n)];
            on = ag_pred_orient2d(a, b, v) == 0 && v[0] >= fmin(a[0], b[0]) &&
                 v[0] <= fmax(a[0], b[0]) && v[1] >= fmin(a[1], b[1]) && v[1] <= fmax(a[1], b[1]);
        }
        if (!on)
            return v;
    }
    return NULL;
}

static void reverse_loop(ag_plan_loop *l, long *orig)
{
    /* corners reversed; edge i (i -> i+1) becomes the edge from i+1 to i */
    size_t n = l->n;
    for (size_t i = 0; i < n / 2; i++) {
        size_t j = n - 1 - i;
        double tx = l->xy[2 * i], ty = l->xy[2 * i + 1];
        l->xy[2 * i] = l->xy[2 * j];
        l->xy[2 * i + 1] = l->xy[2 * j + 1];
        l->xy[2 * j] = tx;
        l->xy[2 * j + 1] = ty;
        long to = orig[i];
        orig[i] = orig[j];
        orig[j] = to;
    }
    /* new edge i runs from new corner i (old n-1-i) to old n-2-i: old edge n-2-i */
    int32_t *np = malloc(n * sizeof *np);
    if (!np)
        return;
    for (size_t i = 0; i < n; i++)
        np[i] = l->profile[(2 * n - 2 - i) % n];
    memcpy(l->profile, np, n * sizeof *np);
    free(np);
}

ag_status ag_plan_validate(ag_plan *p, ag_plan_fixes *fixes, double *extent, ag_error *err)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < p->nloops; i++) {
        ag_plan_loop *l = &p->loops[i];
        for (size_t j = 0; j < l->n; j++) {
            double x = l->xy[2 * j], y = l->xy[2 * j + 1];
            if (!isfinite(x) || !isfinite(y))
                return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                    "loop %zu corner %zu is not finite", i, j);
            if (l->profile[j] < 0 || (size_t)l->profile[j] >= p->nprofiles)
                return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                    "loop %zu edge %zu has no valid profile (%d of %zu)", i, j,
                                    (int)l->profile[j], p->nprofiles);
            lo[0] = fmin(lo[0], x);
            lo[1] = fmin(lo[1], y);
            hi[0] = fmax(hi[0], x);
            hi[1] = fmax(hi[1], y);
        }
    }
    if (p->nloops == 0 || !(hi[0] >= lo[0]))
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the plan has no corners");
    double ext = hypot(hi[0] - lo[0], hi[1] - lo[1]);
    if (extent)
        *extent = ext;
    double mag = fmax(fmax(fabs(lo[0]), fabs(hi[0])), fmax(fabs(lo[1]), fabs(hi[1])));
    ag_extrude_tol tol = ag_extrude_tolerances(ext, mag);
    double d2 = tol.point;

    long **orig = calloc(p->nloops, sizeof *orig);
    long *oloop = malloc((p->nloops ? p->nloops : 1) * sizeof *oloop);
    if (!orig || !oloop) {
        free(orig);
        free(oloop);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_status st = AG_OK;
    size_t kept = 0;
    for (size_t i = 0; i < p->nloops; i++) {
        ag_plan_loop *l = &p->loops[i];
        oloop[i] = (long)i;
        orig[i] = malloc((l->n ? l->n : 1) * sizeof(long));
        if (!orig[i]) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        for (size_t j = 0; j < l->n; j++)
            orig[i][j] = (long)j;
        clean_loop(l, (long)i, orig[i], d2, AG_VERIFY_WINDING_PROBE * tol.size + d2, fixes);
        if (l->n < 3 || fabs(ag_plan_loop_area(l)) <= d2 * ext) {
            /* a loop without area that crosses itself is a bow tie, not nothing */
            if (l->n >= 3 && (st = check_crossings(p, orig, oloop, (long)i, err)) != AG_OK)
                goto done;
            add_fix(fixes, AG_PLAN_FIX_DROPPED, (long)i, -1,
                    "loop with fewer than 3 corners or no area removed");
            l->n = 0;
        } else {
            kept++;
        }
    }
    if (!kept) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0, "no loop of the plan has an area");
        goto done;
    }
    /* compact the loops (keeping orig and oloop aligned) */
    size_t w = 0;
    for (size_t i = 0; i < p->nloops; i++) {
        if (p->loops[i].n == 0) {
            free(p->loops[i].xy);
            free(p->loops[i].profile);
            free(orig[i]);
            continue;
        }
        p->loops[w] = p->loops[i];
        orig[w] = orig[i];
        oloop[w] = oloop[i];
        w++;
    }
    for (size_t i = w; i < p->nloops; i++)
        orig[i] = NULL;
    p->nloops = w;

    st = check_crossings(p, orig, oloop, -1, err);
    if (st == AG_OK && p->nloops > 1) {
        separate_touches(p, oloop, orig, AG_EXTRUDE_TOUCH_GAP * fmax(ext, AG_EXTRUDE_SIZE_MIN),
                         fixes);
        /* the moved corners must not have made anything cross (a gap wider than the
         * plan's features there) */
        st = check_crossings(p, orig, oloop, -1, err);
    }
    if (st != AG_OK)
        goto done;
    /* orientation by nesting depth: even depth = outer (CCW), odd = hole (CW); tested at
     * a corner that is not on the other loop (loops may touch at points) */
    for (size_t i = 0; i < p->nloops; i++) {
        ag_plan_loop *l = &p->loops[i];
        int depth = 0;
        for (size_t j = 0; j < p->nloops; j++) {
            if (j == i)
                continue;
            const double *v = free_corner(l, &p->loops[j]);
            if (v && ag_pred_point_in_polygon(p->loops[j].xy, p->loops[j].n, v[0], v[1]))
                depth++;
        }
        double a = ag_plan_loop_area(l);
        int want_ccw = depth % 2 == 0;
        if ((a > 0) != want_ccw) {
            reverse_loop(l, orig[i]);
            add_fix(fixes, AG_PLAN_FIX_REVERSED, oloop[i], -1,
                    want_ccw ? "outer loop was clockwise: reversed"
                             : "hole was counter-clockwise: reversed");
        }
    }
done:
    for (size_t i = 0; i < p->nloops; i++)
        free(orig[i]);
    free(orig);
    free(oloop);
    return st;
}
