#include "upaxis.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/radix.h"

/* Map coordinates: a centre at least this far from the origin (metres), on two axes, and
 * the third axis's centre at most GEO_RATIO of the smaller of them. Ten kilometres is beyond
 * any building's own frame and below every UTM easting and national grid used for cities. */
#define GEO_MIN_CENTRE 1e4
#define GEO_RATIO 0.1
/* The ends of an axis: its lowest and highest twentieth. Levels within it are bins of
 * LEVEL_STEP of the diagonal (one storey's floor and the walls standing on it are one level
 * even where the floor is a few centimetres thick). */
#define END_SHARE 0.05
#define LEVEL_STEP 0.003
/* A top that supports more than the base by less than this (a share of the cross-section)
 * is the eaves' overhang of a flat roof, no sign that the axis points down. */
#define EAVES 0.25
/* A normal within this (its component along the axis, or off it) is perpendicular to the
 * axis or parallel to it: about 1.1 and 1.1 degrees. */
#define PERPENDICULAR 0.02
#define PARALLEL 0.9998
/* Differences of the vertical share below this are noise of plans aligned with the axes
 * (roof ridges along one axis favour it by up to about a tenth on the 0 A.D. meshes). */
#define VERTICAL_DEAD_ZONE 0.15
/* The roof cue counts only where sloped surfaces (normals neither along the axis nor across
 * it) make at least this share of the area. */
#define ROOF_MIN_SHARE 0.02
/* The roof cue decides alone when one axis's sloped surfaces face one way by at least
 * ROOF_CLEAR and by at least ROOF_RATIO times the other's: a clear roof. Less than that
 * (shallow or few roofs, battered walls facing one way along a horizontal axis) leaves the
 * decision to the score. */
#define ROOF_CLEAR 0.1
#define ROOF_RATIO 2.0
/* The origin cue needs both horizontal centres within this many half extents of 0. */
#define ORIGIN_CENTRED 0.15

typedef struct {
    double t;    /* coordinate along the axis */
    double u, v; /* the two other coordinates */
} lvpt;

/* Scratch of the sorts: records and a copy of the points. */
typedef struct {
    ag_radix_item *it;
    lvpt *tmp;
} sorter;

/* Sorts p stably by one coordinate (0 t, 1 u, 2 v), a radix sort: the level sorts took a
 * tenth of reading a large mesh through qsort. */
static int sort_by(lvpt *p, size_t n, int field, sorter *s)
{
    for (size_t i = 0; i < n; i++) {
        s->it[i].key = ag_radix_key_double(field == 0 ? p[i].t : field == 1 ? p[i].u : p[i].v);
        s->it[i].val = (uint32_t)i;
    }
    if (ag_radix_sort(s->it, n))
        return -1;
    for (size_t i = 0; i < n; i++)
        s->tmp[i] = p[s->it[i].val];
    memcpy(p, s->tmp, n * sizeof *p);
    return 0;
}

static double cross(const lvpt *o, const lvpt *a, const lvpt *b)
{
    return (a->u - o->u) * (b->v - o->v) - (a->v - o->v) * (b->u - o->u);
}

/* Area of the convex hull of p[0..n) in (u, v) (monotone chain; p is reordered, h holds
 * 2n + 1 points). */
static double hull_area(lvpt *p, size_t n, lvpt *h, sorter *s)
{
    if (n < 3)
        return 0;
    /* by (u, v): v, then u stably */
    if (sort_by(p, n, 2, s) || sort_by(p, n, 1, s))
        return -1;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        while (k >= 2 && cross(&h[k - 2], &h[k - 1], &p[i]) <= 0)
            k--;
        h[k++] = p[i];
    }
    for (size_t i = n - 1, lo = k + 1; i-- > 0;) {
        while (k >= lo && cross(&h[k - 2], &h[k - 1], &p[i]) <= 0)
            k--;
        h[k++] = p[i];
    }
    double a = 0;
    for (size_t i = 0; i + 1 < k; i++)
        a += h[i].u * h[i + 1].v - h[i + 1].u * h[i].v;
    return fabs(a) / 2;
}

/* Largest level hull in [lo, lo + band] (low end) or [hi - band, hi] (high end) of the
 * points p (sorted by t), as a share of cross. */
static double end_support(lvpt *p, size_t n, double step, double cross_area, lvpt *h,
                          sorter *s)
{
    double best = 0;
    for (size_t i = 0, j; i < n; i = j) {
        double level = floor(p[i].t / step);
        for (j = i + 1; j < n && floor(p[j].t / step) == level; j++)
            ;
        double a = hull_area(p + i, j - i, h, s);
        if (a < 0)
            return -1;
        if (a > best)
            best = a;
    }
    return cross_area > 0 ? fmin(best / cross_area, 1.0) : 0;
}

ag_status ag_upaxis_decide(const ag_mesh *m, ag_upaxis_evidence *ev, ag_error *err)
{
    memset(ev, 0, sizeof *ev);
    if (!m || !m->ntris)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the mesh has no triangles");
    ag_box b = ag_mesh_bounds(m);
    double ext[3], diag = ag_box_diagonal(&b);
    ag_box_extents(&b, ext);
    ag_box_centre(&b, ev->centre);
    if (!(diag > 0))
        return AG_OK; /* a point decides nothing */

    /* georeferenced: exactly one candidate axis is not a map coordinate */
    int big[3];
    for (int a = 0; a < 3; a++)
        big[a] = fabs(ev->centre[a]) >= GEO_MIN_CENTRE;
    for (int a = 1; a < 3; a++) {
        int o1 = (a + 1) % 3, o2 = (a + 2) % 3;
        double smaller = fmin(fabs(ev->centre[o1]), fabs(ev->centre[o2]));
        if (big[o1] && big[o2] && !big[a] && fabs(ev->centre[a]) <= GEO_RATIO * smaller) {
            ev->georeferenced = 1;
            ev->axis = a;
            ev->score = a == 2 ? 1 : -1;
        }
    }

    /* vertical share per axis */
    double area = 0, aligned[3] = {0, 0, 0}, sloped[3] = {0, 0, 0}, facing[3] = {0, 0, 0};
    double strict_sloped[3] = {0, 0, 0}, strict_facing[3] = {0, 0, 0}, strict_area[3] = {0, 0, 0};
    uint8_t *used = calloc(m->nverts + 1, 1);
    if (!used)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory deciding the up axis");
    for (size_t t = 0; t < m->ntris; t++) {
        const uint32_t *q = m->tri + 3 * t;
        const double *p0 = m->pos + 3 * q[0], *p1 = m->pos + 3 * q[1], *p2 = m->pos + 3 * q[2];
        used[q[0]] = used[q[1]] = used[q[2]] = 1;
        double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(l > 0))
            continue;
        area += l;
        for (int a = 0; a < 3; a++) {
            double c = fabs(n[a]) / l;
            if (c < PERPENDICULAR || c > PARALLEL) {
                aligned[a] += l;
            } else {
                sloped[a] += fabs(n[a]);
                facing[a] += n[a];
                /* the strict reading: a surface upright about the other candidate is that
                 * axis's wall, so it is no roof for this one (a plan turned off the axes
                 * makes walls sloped about the horizontal axis) */
                if (a > 0 && fabs(n[3 - a]) / l >= PERPENDICULAR) {
                    strict_sloped[a] += fabs(n[a]);
                    strict_facing[a] += n[a];
                    strict_area[a] += l;
                }
            }
        }
    }

    /* support at both ends of y and z */
    size_t nused = 0;
    for (size_t i = 0; i < m->nverts; i++)
        nused += used[i];
    lvpt *lo = malloc((nused + 1) * sizeof *lo), *hi = malloc((nused + 1) * sizeof *hi);
    lvpt *h = malloc((2 * nused + 2) * sizeof *h);
    sorter so = {malloc((nused + 1) * sizeof *so.it), malloc((nused + 1) * sizeof *so.tmp)};
    int nomem = !lo || !hi || !h || !so.it || !so.tmp;
    double step = LEVEL_STEP * diag;
    for (int a = 1; a < 3 && !nomem; a++) {
        int o1 = (a + 1) % 3, o2 = (a + 2) % 3;
        double band = END_SHARE * ext[a];
        size_t nl = 0, nh = 0;
        for (size_t i = 0; i < m->nverts; i++) {
            if (!used[i])
                continue;
            const double *p = m->pos + 3 * i;
            lvpt x = {p[a] - b.min[a], p[o1], p[o2]};
            if (x.t <= band)
                lo[nl++] = x;
            if (b.max[a] - p[a] <= band) {
                x.t = b.max[a] - p[a]; /* levels counted from the high end */
                hi[nh++] = x;
            }
        }
        /* by t (the levels; each level's hull sorts its own points) */
        int fail = sort_by(lo, nl, 0, &so) || sort_by(hi, nh, 0, &so);
        double cross_area = ext[o1] * ext[o2];
        ag_upaxis_cues *c = &ev->cue[a - 1];
        double bottom = fail ? -1 : end_support(lo, nl, step, cross_area, h, &so);
        c->top = fail ? -1 : end_support(hi, nh, step, cross_area, h, &so);
        if (bottom < 0 || c->top < 0) {
            nomem = 1;
            break;
        }
        c->base = bottom - c->top;
        if (c->base < 0)
            c->base = fmin(c->base + EAVES, 0);
        c->vertical = area > 0 ? aligned[a] / area : 0;
        /* sign-free: a file's winding may face every surface inwards */
        c->roof = sloped[a] > 0 && area - aligned[a] >= ROOF_MIN_SHARE * area
                      ? fabs(facing[a]) / sloped[a]
                      : 0;
        c->roof_strict = strict_sloped[a] > 0 && strict_area[a] >= ROOF_MIN_SHARE * area
                             ? fabs(strict_facing[a]) / strict_sloped[a]
                             : 0;
        double half[3];
        for (int k = 0; k < 3; k++)
            half[k] = ext[k] > 0 ? ext[k] / 2 : 1;
        if (fabs(ev->centre[o1]) <= ORIGIN_CENTRED * half[o1] &&
            fabs(ev->centre[o2]) <= ORIGIN_CENTRED * half[o2])
            c->origin = fmin(fmax(ev->centre[a] / half[a], 0), 1);
    }
    free(used);
    free(lo);
    free(hi);
    free(h);
    free(so.it);
    free(so.tmp);
    if (nomem)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory deciding the up axis");
    ev->cue[0].extent = ext[1];
    ev->cue[1].extent = ext[2];
    if (ev->georeferenced)
        return AG_OK;
    if ((ext[1] < AG_UPAXIS_MIN_HEIGHT) != (ext[2] < AG_UPAXIS_MIN_HEIGHT)) {
        ev->storey = 1;
        ev->axis = ext[2] < AG_UPAXIS_MIN_HEIGHT ? 1 : 2;
        ev->score = ev->axis == 2 ? 1 : -1;
        return AG_OK;
    }

    const ag_upaxis_cues *y = &ev->cue[0], *z = &ev->cue[1];
    for (int a = 1; a < 3; a++) {
        const ag_upaxis_cues *c = &ev->cue[a - 1], *o = &ev->cue[2 - a];
        if (c->roof >= ROOF_CLEAR && c->roof >= ROOF_RATIO * o->roof &&
            c->roof_strict >= ROOF_CLEAR && c->roof_strict >= ROOF_RATIO * o->roof_strict) {
            ev->roof = 1;
            ev->axis = a;
            ev->score = a == 2 ? 1 : -1;
            return AG_OK;
        }
    }
    double dv = z->vertical - y->vertical;
    double vertical = dv > VERTICAL_DEAD_ZONE ? dv - VERTICAL_DEAD_ZONE
                      : dv < -VERTICAL_DEAD_ZONE ? dv + VERTICAL_DEAD_ZONE
                                                 : 0;
    ev->score = (z->base - y->base) + vertical + 0.5 * (z->origin - y->origin);
    ev->axis = ev->score >= AG_UPAXIS_UNDECIDED ? 2 : ev->score <= -AG_UPAXIS_UNDECIDED ? 1 : 0;
    return AG_OK;
}

void ag_upaxis_turn_y_to_z(ag_mesh *m)
{
    for (size_t i = 0; i < m->nverts; i++) {
        double *p = m->pos + 3 * i;
        double y = p[1];
        p[1] = -p[2];
        p[2] = y;
    }
}
