#include "building.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "simplify.h"
#include "verify.h"

/* Simplification thresholds tried in turn (m² of a corner's triangle). */
static const double simplify_areas[] = {0.01, 0.1, 0.5};

const char *ag_built_name(ag_built b)
{
    switch (b) {
    case AG_BUILT_STYLED:
        return "styled";
    case AG_BUILT_SIMPLIFIED:
        return "simplified";
    case AG_BUILT_FLAT:
        return "flat";
    case AG_BUILT_BLOCK:
        return "block";
    default:
        return "none";
    }
}

typedef struct {
    size_t nverts, ntris, ncomponents;
} mark;

static mark mark_of(const ag_mesh *m)
{
    return (mark){m->nverts, m->ntris, m->ncomponents};
}

/* Drops what was appended to m since k (the arrays keep their capacity). */
static void roll_back(ag_mesh *m, mark k)
{
    m->nverts = k.nverts;
    m->ntris = k.ntris;
    m->ncomponents = k.ncomponents;
}

static void note_fixes(ag_building_result *out, const ag_plan_fixes *fx)
{
    out->nfixes = fx->n;
    out->fixes[0] = 0;
    size_t len = 0;
    for (size_t i = 0; i < fx->n && len + 1 < sizeof out->fixes; i++) {
        const ag_plan_fix *f = &fx->fixes[i];
        int w = f->corner >= 0
                    ? snprintf(out->fixes + len, sizeof out->fixes - len, "%sloop %ld corner %ld: %s",
                               i ? "; " : "", f->loop, f->corner, f->reason)
                    : snprintf(out->fixes + len, sizeof out->fixes - len, "%sloop %ld: %s",
                               i ? "; " : "", f->loop, f->reason);
        if (w < 0)
            break;
        len += (size_t)w;
    }
}

enum { GOOD = 1, NOT_GOOD = 0, REFUSED = -1 };

/* Extrudes one plan (taking it). Returns GOOD (added to m), NOT_GOOD (why set, m
 * unchanged), REFUSED (validation: why set), or -2 with *st an error to pass on. */
static int extrude_one(ag_plan *plan, const ag_extrude_options *opt, ag_mesh *m, int32_t group,
                       ag_building_result *out, int record_fixes, char *why, size_t nwhy,
                       ag_status *st)
{
    ag_error e = {0};
    ag_plan_fixes fixes = {0};
    ag_extrude_options o = opt ? *opt : (ag_extrude_options){0};
    o.fixes = &fixes;
    mark k = mark_of(m);
    ag_extrude_result r;
    ag_status s = ag_extrude_plan_with(plan, &o, m, group, &r, NULL, &e);
    if (record_fixes)
        note_fixes(out, &fixes);
    ag_plan_fixes_free(&fixes);
    out->events += r.stats.events;
    *st = AG_OK;
    if (s == AG_ERR_NOMEM || s == AG_ERR_CANCELLED) {
        *st = s;
        snprintf(why, nwhy, "%s", e.text);
        return -2;
    }
    if (s == AG_ERR_INVALID || s == AG_ERR_EMPTY) {
        snprintf(why, nwhy, "%s", e.text[0] ? e.text : ag_status_message(s));
        return REFUSED;
    }
    if (s != AG_OK) {
        snprintf(why, nwhy, "%s", e.text[0] ? e.text : ag_status_message(s));
        return NOT_GOOD;
    }
    if (!ag_extrude_result_ok(&r)) {
        if (r.failing_faces)
            snprintf(why, nwhy, "%zu face(s) fail; face %d: %s", r.failing_faces,
                     (int)r.problems[0].face, r.problems[0].reason);
        else
            snprintf(why, nwhy, "%s", r.defect);
        roll_back(m, k);
        return NOT_GOOD;
    }
    out->triangles = r.triangles;
    return GOOD;
}

/* Styles and extrudes one set of loops: extrude_one's answers. */
static int attempt(const ag_style *style, const double *const *loops, const size_t *sizes,
                   size_t nloops, double height, size_t index, const ag_extrude_options *opt,
                   ag_mesh *m, int32_t group, ag_building_result *out, int record_fixes,
                   char *why, size_t nwhy, ag_status *st)
{
    ag_error e = {0};
    ag_plan *plan = NULL;
    *st = ag_style_apply(style, loops, sizes, nloops, height, index, &plan, &e);
    if (*st == AG_ERR_NOMEM)
        return -2;
    if (*st != AG_OK) {
        snprintf(why, nwhy, "%s", e.text[0] ? e.text : ag_status_message(*st));
        *st = AG_OK;
        return REFUSED;
    }
    int r = extrude_one(plan, opt, m, group, out, record_fixes, why, nwhy, st);
    ag_plan_free(plan);
    return r;
}

/* Copies of the loops that simplification may shorten. */
static double **copy_loops(const double *const *loops, const size_t *sizes, size_t nloops)
{
    double **c = calloc(nloops ? nloops : 1, sizeof *c);
    for (size_t L = 0; c && L < nloops; L++) {
        c[L] = malloc((2 * sizes[L] + 1) * sizeof **c);
        if (!c[L]) {
            for (size_t k = 0; k < L; k++)
                free(c[k]);
            free(c);
            return NULL;
        }
        memcpy(c[L], loops[L], 2 * sizes[L] * sizeof **c);
    }
    return c;
}

static void free_loops(double **c, size_t nloops)
{
    for (size_t L = 0; c && L < nloops; L++)
        free(c[L]);
    free(c);
}

/* --- the last resort: a block on the convex hull ------------------------------------------ */

static int cmp_pt(const void *a, const void *b)
{
    const double *p = a, *q = b;
    if (p[0] != q[0])
        return p[0] < q[0] ? -1 : 1;
    return p[1] < q[1] ? -1 : p[1] > q[1];
}

static double cross(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Convex hull (Andrew's monotone chain), counter-clockwise, into hull (2 * n); returns
 * its number of corners. pts is sorted in place. */
static size_t convex_hull(double *pts, size_t n, double *hull)
{
    qsort(pts, n, 2 * sizeof *pts, cmp_pt);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        while (k >= 2 && cross(&hull[2 * (k - 2)], &hull[2 * (k - 1)], &pts[2 * i]) <= 0)
            k--;
        hull[2 * k] = pts[2 * i];
        hull[2 * k + 1] = pts[2 * i + 1];
        k++;
    }
    for (size_t i = n - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(&hull[2 * (k - 2)], &hull[2 * (k - 1)], &pts[2 * i]) <= 0)
            k--;
        hull[2 * k] = pts[2 * i];
        hull[2 * k + 1] = pts[2 * i + 1];
        k++;
    }
    return k > 1 ? k - 1 : k;
}

static ag_status block(const double *const *loops, const size_t *sizes, size_t nloops,
                       double height, ag_mesh *m, int32_t group, size_t *ntris, int *made)
{
    *made = 0;
    size_t n = 0;
    for (size_t L = 0; L < nloops; L++)
        n += sizes[L];
    double *pts = malloc((2 * n + 2) * sizeof *pts), *hull = malloc((4 * n + 4) * sizeof *hull);
    ag_status st = pts && hull ? AG_OK : AG_ERR_NOMEM;
    size_t k = 0;
    for (size_t L = 0; st == AG_OK && L < nloops; L++)
        for (size_t i = 0; i < sizes[L]; i++) {
            if (!isfinite(loops[L][2 * i]) || !isfinite(loops[L][2 * i + 1]))
                continue;
            pts[2 * k] = loops[L][2 * i];
            pts[2 * k + 1] = loops[L][2 * i + 1];
            k++;
        }
    size_t h = st == AG_OK && k >= 3 ? convex_hull(pts, k, hull) : 0;
    double area = 0;
    for (size_t i = 0; i < h; i++)
        area += cross(&hull[0], &hull[2 * i], &hull[2 * ((i + 1) % h)]);
    if (st == AG_OK && h >= 3 && area > 0 && height > 0) {
        size_t comp = 0;
        uint32_t v0 = (uint32_t)m->nverts;
        st = ag_mesh_add_component(m, group, &comp);
        for (size_t i = 0; st == AG_OK && i < h; i++)
            st = ag_mesh_add_vertex(m, hull[2 * i], hull[2 * i + 1], 0);
        for (size_t i = 0; st == AG_OK && i < h; i++)
            st = ag_mesh_add_vertex(m, hull[2 * i], hull[2 * i + 1], height);
        size_t t0 = m->ntris;
        for (uint32_t i = 1; st == AG_OK && i + 1 < h; i++) {
            st = ag_mesh_add_triangle(m, v0, v0 + i + 1, v0 + i, (uint32_t)comp);
            if (st == AG_OK)
                st = ag_mesh_add_triangle(m, v0 + (uint32_t)h, v0 + (uint32_t)h + i,
                                          v0 + (uint32_t)h + i + 1, (uint32_t)comp);
        }
        for (uint32_t i = 0; st == AG_OK && i < h; i++) {
            uint32_t j = (uint32_t)((i + 1) % h), H = (uint32_t)h;
            st = ag_mesh_add_triangle(m, v0 + i, v0 + j, v0 + H + j, (uint32_t)comp);
            if (st == AG_OK)
                st = ag_mesh_add_triangle(m, v0 + i, v0 + H + j, v0 + H + i, (uint32_t)comp);
        }
        *ntris = m->ntris - t0;
        *made = st == AG_OK;
    }
    free(pts);
    free(hull);
    return st;
}

/* The last resort: the block, recorded in out (nothing added when none can be made). */
static ag_status block_fallback(const double *const *loops, const size_t *sizes, size_t nloops,
                                double height, ag_mesh *m, int32_t group, ag_building_result *out,
                                ag_error *err)
{
    int made = 0;
    mark k = mark_of(m);
    ag_status st = block(loops, sizes, nloops, height, m, group, &out->triangles, &made);
    if (st != AG_OK)
        ag_error_set(err, st, 0, "out of memory");
    if (st == AG_OK && made)
        out->built = AG_BUILT_BLOCK;
    if (st != AG_OK || !made)
        roll_back(m, k);
    return st;
}

ag_status ag_building_extrude(const ag_style *style, const double *const *loops,
                              const size_t *sizes, size_t nloops, double height, size_t index,
                              const ag_extrude_options *opt, ag_mesh *m, int32_t group,
                              ag_building_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    out->built = AG_BUILT_NONE;
    double h = height > 0 ? height : style->height;
    char why[sizeof out->reason];
    ag_status st = AG_OK;
    ag_budget clock;
    ag_budget_start(&clock, NULL, 0);
    int r = attempt(style, loops, sizes, nloops, height, index, opt, m, group, out, 1,
                    out->reason, sizeof out->reason, &st);
    if (r == GOOD)
        out->built = AG_BUILT_STYLED;
    if (r != NOT_GOOD)
        goto done; /* built, refused, or an error to pass on */
    /* 1. simplified */
    size_t *sz = malloc((nloops ? nloops : 1) * sizeof *sz);
    double **cp = NULL;
    for (size_t i = 0; sz && r == NOT_GOOD && i < sizeof simplify_areas / sizeof *simplify_areas;
         i++) {
        free_loops(cp, nloops);
        cp = copy_loops(loops, sizes, nloops);
        if (!cp)
            break;
        memcpy(sz, sizes, nloops * sizeof *sz);
        double moved = 0;
        size_t removed = 0;
        if (ag_simplify_loops(cp, sz, nloops, simplify_areas[i], &moved, &removed) != AG_OK)
            break;
        if (!removed)
            continue;
        r = attempt(style, (const double *const *)cp, sz, nloops, height, index, opt, m, group,
                    out, 0, why, sizeof why, &st);
        if (r == GOOD) {
            out->built = AG_BUILT_SIMPLIFIED;
            out->moved = moved;
        } else if (r == REFUSED) {
            r = NOT_GOOD; /* that simplification crossed itself: try the next */
        }
    }
    if (!sz || (r == NOT_GOOD && !cp && nloops))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    /* 2. a flat roof */
    ag_style flat;
    if (r == NOT_GOOD && st == AG_OK && ag_style_builtin("flat", &flat, NULL) == AG_OK) {
        r = attempt(&flat, loops, sizes, nloops, h, index, opt, m, group, out, 0, why,
                    sizeof why, &st);
        if (r == GOOD)
            out->built = AG_BUILT_FLAT;
    }
    free_loops(cp, nloops);
    free(sz);
    /* 3. a block */
    if ((r == NOT_GOOD || r == REFUSED) && st == AG_OK)
        st = block_fallback(loops, sizes, nloops, h, m, group, out, err);
done:
    if (r == -2 && st != AG_OK)
        ag_error_set(err, st, 0, "%s", out->reason[0] ? out->reason : why);
    out->seconds = ag_budget_elapsed(&clock);
    return st;
}

double ag_building_plan_height(const ag_plan *plan)
{
    if (plan->cap_height > 0)
        return plan->cap_height;
    double eave = 0, top = 0;
    for (size_t L = 0; L < plan->nloops; L++)
        for (size_t i = 0; i < plan->loops[L].n; i++) {
            int32_t k = plan->loops[L].profile[i];
            if (k < 0 || (size_t)k >= plan->nprofiles)
                continue;
            const ag_profile *pr = &plan->profiles[k];
            size_t j = 0;
            while (j + 1 < pr->npoints && pr->points[j + 1].w == 0)
                j++;
            if (pr->points[j].z > eave)
                eave = pr->points[j].z;
            if (pr->npoints && pr->points[pr->npoints - 1].z > top)
                top = pr->points[pr->npoints - 1].z;
        }
    return eave > 0 ? eave : top > 0 ? top : AG_BUILDING_FLAT_HEIGHT;
}

ag_status ag_building_extrude_plan(ag_plan *plan, const ag_extrude_options *opt, ag_mesh *m,
                                   int32_t group, ag_building_result *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    out->built = AG_BUILT_NONE;
    ag_budget clock;
    ag_budget_start(&clock, NULL, 0);
    ag_status st = AG_OK;
    double h = ag_building_plan_height(plan);
    char why[sizeof out->reason] = "";
    int r = extrude_one(plan, opt, m, group, out, 1, out->reason, sizeof out->reason, &st);
    if (r == GOOD)
        out->built = AG_BUILT_STYLED;
    if (r == NOT_GOOD) {
        /* the loops as validation left them (cleaned, oriented) */
        const double **loops = malloc((plan->nloops ? plan->nloops : 1) * sizeof *loops);
        size_t *sizes = malloc((plan->nloops ? plan->nloops : 1) * sizeof *sizes);
        ag_style flat;
        if (!loops || !sizes) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        } else if (ag_style_builtin("flat", &flat, NULL) == AG_OK) {
            for (size_t L = 0; L < plan->nloops; L++) {
                loops[L] = plan->loops[L].xy;
                sizes[L] = plan->loops[L].n;
            }
            r = attempt(&flat, (const double *const *)loops, sizes, plan->nloops, h, 0, opt, m,
                        group, out, 0, why, sizeof why, &st);
            if (r == GOOD)
                out->built = AG_BUILT_FLAT;
            if ((r == NOT_GOOD || r == REFUSED) && st == AG_OK)
                st = block_fallback((const double *const *)loops, sizes, plan->nloops, h, m,
                                    group, out, err);
        }
        free(loops);
        free(sizes);
    }
    if (r == -2 && st != AG_OK)
        ag_error_set(err, st, 0, "%s", why[0] ? why : out->reason);
    out->seconds = ag_budget_elapsed(&clock);
    return st;
}
