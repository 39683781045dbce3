#include "footprints.h"

#include <ctype.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "../core/base/search.h"
#include "../core/extrude/building.h"
#include "../core/extrude/extrude.h"
#include "../core/extrude/predicates.h"
#include "jsondoc.h"

#define EARTH_RADIUS 6371008.8

void ag_footprints_free(ag_footprints *f)
{
    if (!f)
        return;
    for (size_t i = 0; i < f->n; i++) {
        ag_footprint *p = &f->items[i];
        free(p->id);
        for (size_t j = 0; j < p->nloops; j++)
            free(p->loops[j]);
        free(p->loops);
        free(p->sizes);
    }
    free(f->items);
    free(f);
}

static void skip(ag_footprints *f, size_t index, const char *why)
{
    if (!f->skipped)
        snprintf(f->first_skip, sizeof f->first_skip, "feature %zu: %s", index, why);
    f->skipped++;
}

/* An [x, y, ...] position: its x and y when both are finite numbers. */
static int position(const ag_jsondoc *d, uint32_t pt, double *x, double *y)
{
    if (ag_jsondoc_type(d, pt) != AG_JSON_ARRAY || ag_jsondoc_size(d, pt) < 2)
        return 0;
    uint32_t a = ag_jsondoc_first(d, pt), b = ag_jsondoc_next(d, a);
    if (ag_jsondoc_type(d, a) != AG_JSON_NUMBER || ag_jsondoc_type(d, b) != AG_JSON_NUMBER)
        return 0;
    *x = ag_jsondoc_number(d, a);
    *y = ag_jsondoc_number(d, b);
    return isfinite(*x) && isfinite(*y);
}

/* Visits every coordinate pair of a Polygon/MultiPolygon's rings. */
static int ring_ok(const ag_jsondoc *d, uint32_t ring)
{
    if (ag_jsondoc_type(d, ring) != AG_JSON_ARRAY || ag_jsondoc_size(d, ring) < 3)
        return 0;
    double x, y;
    for (uint32_t pt = ag_jsondoc_first(d, ring); pt != AG_JSONDOC_NONE;
         pt = ag_jsondoc_next(d, pt))
        if (!position(d, pt, &x, &y))
            return 0;
    return 1;
}

/* Appends a ring; *cap is the capacity of fp->sizes and fp->loops, grown by doubling (one
 * ring at a time copied both arrays once per ring: quadratic in a polygon's holes). */
static ag_status add_ring(ag_footprint *fp, size_t *cap, const ag_jsondoc *d, uint32_t ring)
{
    if (fp->nloops == *cap) {
        size_t nc;
        if (ag_array_capacity(*cap, fp->nloops + 1, sizeof *fp->sizes + sizeof *fp->loops, &nc))
            return AG_ERR_NOMEM;
        size_t *ns = realloc(fp->sizes, nc * sizeof *ns);
        if (ns)
            fp->sizes = ns;
        double **nl = realloc(fp->loops, nc * sizeof *nl);
        if (nl)
            fp->loops = nl;
        if (!ns || !nl)
            return AG_ERR_NOMEM;
        *cap = nc;
    }
    size_t n = ag_jsondoc_size(d, ring);
    double *xy = malloc(2 * n * sizeof *xy);
    if (!xy)
        return AG_ERR_NOMEM;
    size_t k = 0;
    for (uint32_t pt = ag_jsondoc_first(d, ring); pt != AG_JSONDOC_NONE && k < n;
         pt = ag_jsondoc_next(d, pt)) {
        position(d, pt, &xy[2 * k], &xy[2 * k + 1]);
        k++;
    }
    if (k > 1 && xy[0] == xy[2 * (k - 1)] && xy[1] == xy[2 * (k - 1) + 1])
        k--; /* GeoJSON closes rings by repeating the first position */
    fp->sizes[fp->nloops] = k;
    fp->loops[fp->nloops] = xy;
    fp->nloops++;
    return AG_OK;
}

static double ring_area(const double *xy, size_t n)
{
    double a = 0;
    for (size_t i = 0, j = n - 1; i < n; j = i++)
        a += (xy[2 * j] - xy[0]) * (xy[2 * i + 1] - xy[1]) - (xy[2 * i] - xy[0]) * (xy[2 * j + 1] - xy[1]);
    return a / 2;
}

static void reverse(double *xy, size_t n)
{
    for (size_t i = 0; i < n / 2; i++) {
        size_t j = n - 1 - i;
        double tx = xy[2 * i], ty = xy[2 * i + 1];
        xy[2 * i] = xy[2 * j];
        xy[2 * i + 1] = xy[2 * j + 1];
        xy[2 * j] = tx;
        xy[2 * j + 1] = ty;
    }
}

/* Appends a note to what reading changed in this footprint. */
static void note(ag_footprint *fp, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void note(ag_footprint *fp, const char *fmt, ...)
{
    size_t len = strlen(fp->fixes);
    if (len + 3 >= sizeof fp->fixes)
        return;
    if (len) {
        memcpy(fp->fixes + len, "; ", 3);
        len += 2;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(fp->fixes + len, sizeof fp->fixes - len, fmt, ap);
    va_end(ap);
}

/* One polygon (part `part` of the feature, or -1 for a Polygon): rings oriented outer
 * counter-clockwise, holes clockwise, each reversal noted. */
static ag_status add_polygon(ag_footprint *fp, size_t *cap, const ag_jsondoc *d, uint32_t rings,
                             size_t fi, long part, ag_error *err)
{
    if (ag_jsondoc_type(d, rings) != AG_JSON_ARRAY || ag_jsondoc_size(d, rings) == 0)
        return ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                            "feature %zu: a polygon needs an array of rings", fi);
    size_t i = 0;
    for (uint32_t ring = ag_jsondoc_first(d, rings); ring != AG_JSONDOC_NONE;
         ring = ag_jsondoc_next(d, ring), i++) {
        if (!ring_ok(d, ring))
            return ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                                "feature %zu: ring %zu is not an array of at least 3 finite "
                                "[x, y] positions", fi, i);
        size_t first = fp->nloops;
        if (add_ring(fp, cap, d, ring) != AG_OK)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        double a = ring_area(fp->loops[first], fp->sizes[first]);
        if ((i == 0 && a < 0) || (i > 0 && a > 0)) {
            reverse(fp->loops[first], fp->sizes[first]);
            char where[32] = "";
            if (part >= 0)
                snprintf(where, sizeof where, " of part %ld", part);
            if (i == 0)
                note(fp, "outer ring%s was clockwise: reversed", where);
            else
                note(fp, "hole %zu%s was counter-clockwise: reversed", i - 1, where);
        }
    }
    return AG_OK;
}

/* --- dissolving parts that share edges ---------------------------------------------------- */

/* Corners tested against the edges whose x range holds them, in one footprint's dissolve
 * (a fraction of a second): a grid of n x n squares of two triangles each takes about
 * 10 n^3, so 170 x 170 (57 800 triangles) is within it. */
#define DISSOLVE_MAX_TESTS 50000000ull

typedef struct {
    double x, y;
} pt;

typedef struct {
    uint32_t a, b; /* point indices */
    uint8_t dead;
} dedge;

static int cmp_pt(const void *p, const void *q)
{
    const pt *a = p, *b = q;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    return a->y < b->y ? -1 : a->y > b->y;
}

static int cmp_dedge(const void *p, const void *q)
{
    const dedge *a = p, *b = q;
    if (a->a != b->a)
        return a->a < b->a ? -1 : 1;
    return a->b < b->b ? -1 : a->b > b->b;
}

static uint32_t pt_index(const pt *u, size_t n, double x, double y)
{
    pt key = {x, y};
    const pt *f = bsearch(&key, u, n, sizeof *u, cmp_pt);
    return (uint32_t)(f - u);
}

typedef struct {
    double t;
    uint32_t p;
} along;

static int cmp_along(const void *p, const void *q)
{
    double a = ((const along *)p)->t, b = ((const along *)q)->t;
    return a < b ? -1 : a > b;
}

/* Angle order of direction (dx, dy) counter-clockwise from direction (rx, ry), in [0, 2pi). */
static double turn_from(double rx, double ry, double dx, double dy)
{
    double a = atan2(rx * dy - ry * dx, rx * dx + ry * dy);
    return a <= 0 ? a + 2 * M_PI : a;
}

/* The loops of a MultiPolygon whose parts share edges (a triangulated ground surface)
 * become the boundary of their union: every edge is split where another corner lies on
 * it, edges used both ways cancel, and what is left is linked into loops, turning at
 * shared corners so that each loop keeps the inside on its left. Parts that only touch
 * are left alone. Returns AG_OK (and *dissolved 0 when no edge was shared), AG_ERR_NOMEM,
 * or AG_ERR_TOO_LARGE past DISSOLVE_MAX_TESTS (the footprint is left as it was). */
static ag_status dissolve(ag_footprint *fp, size_t nparts, int *dissolved)
{
    *dissolved = 0;
    size_t np = 0, ne = 0;
    for (size_t L = 0; L < fp->nloops; L++)
        np += fp->sizes[L];
    pt *u = malloc((np + 1) * sizeof *u);
    if (!u)
        return AG_ERR_NOMEM;
    size_t k = 0;
    for (size_t L = 0; L < fp->nloops; L++)
        for (size_t i = 0; i < fp->sizes[L]; i++)
            u[k++] = (pt){fp->loops[L][2 * i], fp->loops[L][2 * i + 1]};
    qsort(u, np, sizeof *u, cmp_pt);
    size_t nu = 0;
    for (size_t i = 0; i < np; i++)
        if (!nu || cmp_pt(&u[nu - 1], &u[i]))
            u[nu++] = u[i];
    /* edges, split at every point inside them (T-junctions of the triangulation) */
    size_t cap = 2 * np + 16;
    dedge *e = malloc(cap * sizeof *e);
    along *on = malloc((nu + 2) * sizeof *on);
    ag_status st = e && on ? AG_OK : AG_ERR_NOMEM;
    uint64_t tests = 0; /* corners tested against edges */
    for (size_t L = 0; st == AG_OK && L < fp->nloops; L++) {
        size_t n = fp->sizes[L];
        const double *xy = fp->loops[L];
        for (size_t i = 0; st == AG_OK && i < n; i++) {
            const double *a = &xy[2 * i], *b = &xy[2 * ((i + 1) % n)];
            size_t non = 0;
            on[non++] = (along){0, pt_index(u, nu, a[0], a[1])};
            double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
            /* the corners sorted by x between the edge's ends: not every corner of the
             * footprint (quadratic in its parts), and within a budget */
            double x1 = fmax(a[0], b[0]);
            for (size_t q = ag_search_lower_double(&u[0].x, nu, sizeof *u, fmin(a[0], b[0]));
                 q < nu && u[q].x <= x1 && l2 > 0; q++) {
                if (++tests > DISSOLVE_MAX_TESTS) {
                    st = AG_ERR_TOO_LARGE;
                    break;
                }
                const double p[2] = {u[q].x, u[q].y};
                if ((p[0] == a[0] && p[1] == a[1]) || (p[0] == b[0] && p[1] == b[1]) ||
                    p[1] < fmin(a[1], b[1]) || p[1] > fmax(a[1], b[1]) ||
                    ag_pred_orient2d(a, b, p) != 0)
                    continue;
                on[non++] = (along){((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2, (uint32_t)q};
            }
            qsort(on + 1, non - 1, sizeof *on, cmp_along);
            on[non++] = (along){1, pt_index(u, nu, b[0], b[1])};
            for (size_t q = 0; q + 1 < non; q++) {
                if (on[q].p == on[q + 1].p)
                    continue;
                if (ne == cap) {
                    dedge *ng = realloc(e, 2 * cap * sizeof *e);
                    if (!ng) {
                        st = AG_ERR_NOMEM;
                        break;
                    }
                    e = ng;
                    cap *= 2;
                }
                e[ne++] = (dedge){on[q].p, on[q + 1].p, 0};
            }
        }
    }
    /* edges used both ways are inside the union */
    size_t shared = 0;
    if (st == AG_OK) {
        qsort(e, ne, sizeof *e, cmp_dedge);
        for (size_t i = 0; i < ne; i++) {
            if (e[i].dead || e[i].a > e[i].b)
                continue;
            dedge key = {e[i].b, e[i].a, 0};
            dedge *r = bsearch(&key, e, ne, sizeof *e, cmp_dedge);
            if (!r)
                continue;
            while (r > e && !cmp_dedge(r - 1, &key))
                r--;
            for (; r < e + ne && !cmp_dedge(r, &key); r++)
                if (!r->dead) {
                    r->dead = 1;
                    e[i].dead = 1;
                    shared++;
                    break;
                }
        }
    }
    if (st != AG_OK || !shared) {
        free(u);
        free(e);
        free(on);
        return st;
    }
    /* link what is left into loops; at a corner with several ways on, turn as far left as
     * possible (the largest angle counter-clockwise from the way back): each loop keeps
     * the inside on its left and loops that meet at a corner stay two loops */
    size_t *start = calloc(nu + 1, sizeof *start);
    double **loops = NULL;
    size_t *sizes = NULL, nl = 0;
    uint8_t *used = calloc(ne ? ne : 1, 1);
    double *ring = malloc((ne + 1) * 2 * sizeof *ring);
    if (!start || !used || !ring)
        st = AG_ERR_NOMEM;
    for (size_t i = 0; st == AG_OK && i < ne; i++)
        start[e[i].a + 1]++;
    for (size_t i = 0; st == AG_OK && i < nu; i++)
        start[i + 1] += start[i];
    for (size_t s = 0; st == AG_OK && s < ne; s++) {
        if (e[s].dead || used[s])
            continue;
        size_t n = 0, cur = s;
        int closed = 0;
        while (!used[cur]) {
            used[cur] = 1;
            ring[2 * n] = u[e[cur].a].x;
            ring[2 * n + 1] = u[e[cur].a].y;
            n++;
            uint32_t v = e[cur].b;
            if (v == e[s].a) {
                closed = 1;
                break;
            }
            double rx = u[e[cur].a].x - u[v].x, ry = u[e[cur].a].y - u[v].y;
            size_t best = ne;
            double ba = -INFINITY;
            for (size_t j = start[v]; j < start[v + 1]; j++) {
                if (e[j].dead || used[j])
                    continue;
                double a = turn_from(rx, ry, u[e[j].b].x - u[v].x, u[e[j].b].y - u[v].y);
                if (a > ba) {
                    ba = a;
                    best = j;
                }
            }
            if (best == ne)
                break;
            cur = best;
        }
        if (!closed || n < 3)
            continue; /* an open chain cannot happen for parts that tile; dropped */
        double **nlp = realloc(loops, (nl + 1) * sizeof *nlp);
        size_t *nsz = realloc(sizes, (nl + 1) * sizeof *nsz);
        if (nlp)
            loops = nlp;
        if (nsz)
            sizes = nsz;
        double *copy = malloc(2 * n * sizeof *copy);
        if (!nlp || !nsz || !copy) {
            free(copy);
            st = AG_ERR_NOMEM;
            break;
        }
        memcpy(copy, ring, 2 * n * sizeof *copy);
        loops[nl] = copy;
        sizes[nl++] = n;
    }
    if (st == AG_OK && nl) {
        for (size_t L = 0; L < fp->nloops; L++)
            free(fp->loops[L]);
        free(fp->loops);
        free(fp->sizes);
        fp->loops = loops;
        fp->sizes = sizes;
        fp->nloops = nl;
        *dissolved = 1;
        note(fp, "%zu parts sharing %zu edge(s) dissolved into %zu loop(s)", nparts, shared, nl);
    } else {
        for (size_t L = 0; L < nl; L++)
            free(loops[L]);
        free(loops);
        free(sizes);
    }
    free(start);
    free(used);
    free(ring);
    free(u);
    free(e);
    free(on);
    return st;
}

static char *dupstr(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static char *id_text(const ag_jsondoc *d, uint32_t v)
{
    char buf[64];
    int64_t i;
    if (ag_jsondoc_type(d, v) == AG_JSON_STRING)
        return dupstr(ag_jsondoc_string(d, v));
    if (ag_jsondoc_integer(d, v, &i)) {
        snprintf(buf, sizeof buf, "%lld", (long long)i);
        return dupstr(buf);
    }
    if (ag_jsondoc_type(d, v) == AG_JSON_NUMBER) {
        snprintf(buf, sizeof buf, "%.17g", ag_jsondoc_number(d, v));
        return dupstr(buf);
    }
    return NULL;
}

static int crs_is_lonlat(const ag_jsondoc *d, uint32_t root)
{
    uint32_t name = ag_jsondoc_get(
        d, ag_jsondoc_get(d, ag_jsondoc_get(d, root, "crs"), "properties"), "name");
    const char *s = ag_jsondoc_string(d, name);
    if (!s)
        return -1; /* no crs member */
    return strstr(s, "CRS84") || strstr(s, "4326") ? 1 : 0;
}

/* The height member key of props: 1 when it gives a height (a number, or a string holding
 * one, as files converted from tables have), 0 when it is absent or null, -1 when it holds
 * something else (a word, a negative or non-finite number, true): noted on fp, so that the
 * report says the style's height stood in for it. */
static int height_of(const ag_jsondoc *d, uint32_t props, const char *key, ag_footprint *fp)
{
    uint32_t v = ag_jsondoc_get(d, props, key);
    ag_json_type t = ag_jsondoc_type(d, v);
    double h = NAN;
    if (v == AG_JSONDOC_NONE || t == AG_JSON_NULL)
        return 0;
    if (t == AG_JSON_NUMBER) {
        h = ag_jsondoc_number(d, v);
    } else if (t == AG_JSON_STRING) {
        const char *text = ag_jsondoc_string(d, v);
        char *end;
        h = strtod(text, &end);
        while (end != text && isspace((unsigned char)*end))
            end++;
        if (end == text || *end)
            h = NAN;
        else if (isfinite(h) && h >= 0)
            note(fp, "%s read from the text \"%.20s\"", key, text);
    }
    if (!isfinite(h) || h < 0) {
        if (t == AG_JSON_STRING)
            note(fp, "%s \"%.20s\" is not a height in metres: the style's height used", key,
                 ag_jsondoc_string(d, v));
        else if (t == AG_JSON_NUMBER)
            note(fp, "%s %g is not a height in metres: the style's height used", key, h);
        else
            note(fp, "%s is not a number: the style's height used", key);
        return -1;
    }
    fp->height = h;
    return 1;
}

ag_status ag_footprints_read_buffer(const char *data, size_t len, const ag_footprints_options *opt,
                                    ag_footprints **out, ag_error *err)
{
    *out = NULL;
    ag_jsondoc *doc = NULL;
    ag_error pe = {0};
    ag_status ps = ag_jsondoc_parse(data, len, &doc, &pe);
    if (ps == AG_ERR_NOMEM)
        return ag_error_set(err, ps, 0, "out of memory");
    if (ps != AG_OK)
        return ag_error_set(err, AG_ERR_PARSE, pe.element, "GeoJSON: %s", pe.text);
    uint32_t root = ag_jsondoc_root(doc);
    uint32_t features = AG_JSONDOC_NONE, first = AG_JSONDOC_NONE;
    size_t nf = 0;
    const char *type = ag_jsondoc_string(doc, ag_jsondoc_get(doc, root, "type"));
    if (type && strcmp(type, "FeatureCollection") == 0) {
        features = ag_jsondoc_get(doc, root, "features");
        if (ag_jsondoc_type(doc, features) != AG_JSON_ARRAY) {
            ag_jsondoc_free(doc);
            return ag_error_set(err, AG_ERR_PARSE, 0, "GeoJSON: \"features\" must be an array");
        }
        first = ag_jsondoc_first(doc, features);
        nf = ag_jsondoc_size(doc, features);
    } else if (type && strcmp(type, "Feature") == 0) {
        first = root; /* a lone Feature: the root is the only one (it has no sibling) */
        nf = 1;
    } else {
        int cityjson = type && !strcmp(type, "CityJSON");
        ag_jsondoc_free(doc);
        if (cityjson)
            return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                                "a CityJSON file, not GeoJSON: extrude reads footprints as a "
                                "GeoJSON FeatureCollection of Polygon or MultiPolygon features");
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "GeoJSON: expected a FeatureCollection or a Feature");
    }
    ag_footprints *f = calloc(1, sizeof *f);
    if (f)
        f->items = calloc(nf ? nf : 1, sizeof *f->items);
    ag_status st = AG_OK;
    if (!f || !f->items) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    const char *hp[] = {"height", "building:height", "measuredHeight", NULL};
    size_t fi = 0;
    for (uint32_t feat = first; feat != AG_JSONDOC_NONE && fi < nf;
         feat = ag_jsondoc_next(doc, feat), fi++) {
        uint32_t geom = ag_jsondoc_get(doc, feat, "geometry");
        const char *gt = ag_jsondoc_string(doc, ag_jsondoc_get(doc, geom, "type"));
        uint32_t coords = ag_jsondoc_get(doc, geom, "coordinates");
        if (!gt || (strcmp(gt, "Polygon") != 0 && strcmp(gt, "MultiPolygon") != 0)) {
            skip(f, fi, "geometry is not a Polygon or MultiPolygon");
            continue;
        }
        ag_footprint *fp = &f->items[f->n];
        memset(fp, 0, sizeof *fp);
        uint32_t props = ag_jsondoc_get(doc, feat, "properties");
        fp->id = id_text(doc, ag_jsondoc_get(doc, feat, "id"));
        if (!fp->id)
            fp->id = id_text(doc, ag_jsondoc_get(doc, props, "id"));
        if (!fp->id) {
            char buf[32];
            snprintf(buf, sizeof buf, "%zu", fi);
            fp->id = dupstr(buf);
        }
        if (opt && opt->height_property) {
            height_of(doc, props, opt->height_property, fp);
        } else {
            for (int k = 0; hp[k]; k++)
                if (height_of(doc, props, hp[k], fp))
                    break;
        }
        size_t cap = 0; /* of fp->sizes and fp->loops */
        if (strcmp(gt, "Polygon") == 0) {
            st = add_polygon(fp, &cap, doc, coords, fi, -1, err);
        } else if (ag_jsondoc_type(doc, coords) != AG_JSON_ARRAY) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                              "feature %zu: MultiPolygon coordinates must be an array", fi);
        } else {
            long pi = 0;
            for (uint32_t poly = ag_jsondoc_first(doc, coords); poly != AG_JSONDOC_NONE;
                 poly = ag_jsondoc_next(doc, poly), pi++) {
                st = add_polygon(fp, &cap, doc, poly, fi, pi, err);
                if (st != AG_OK)
                    break;
            }
            int dissolved = 0;
            size_t nparts = ag_jsondoc_size(doc, coords);
            ag_status ds = st == AG_OK && nparts > 1 ? dissolve(fp, nparts, &dissolved) : AG_OK;
            if (ds == AG_ERR_TOO_LARGE)
                st = ag_error_set(err, ds, (long)fi + 1,
                                  "feature %zu: its %zu parts share too many corners to "
                                  "dissolve within %llu tests; split it into several features",
                                  fi, nparts, DISSOLVE_MAX_TESTS);
            else if (ds != AG_OK)
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        f->n++; /* counted even on error so that free() releases it */
        if (st != AG_OK)
            goto done;
        if (!fp->nloops) {
            skip(f, fi, "empty polygon");
            f->n--;
            free(fp->id);
            free(fp->loops);
            free(fp->sizes);
        }
    }
    /* frame */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < f->n; i++)
        for (size_t j = 0; j < f->items[i].nloops; j++)
            for (size_t k = 0; k < f->items[i].sizes[j]; k++) {
                double x = f->items[i].loops[j][2 * k], y = f->items[i].loops[j][2 * k + 1];
                lo[0] = fmin(lo[0], x);
                lo[1] = fmin(lo[1], y);
                hi[0] = fmax(hi[0], x);
                hi[1] = fmax(hi[1], y);
            }
    if (!f->n) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0, "GeoJSON: no Polygon or MultiPolygon feature%s%s",
                          f->skipped ? "; " : "", f->skipped ? f->first_skip : "");
        goto done;
    }
    int ll = opt && opt->lonlat ? opt->lonlat > 0 : 0;
    if (!opt || !opt->lonlat) {
        int c = crs_is_lonlat(doc, root);
        ll = c == 1 || (c == -1 && lo[0] >= -180 && hi[0] <= 180 && lo[1] >= -90 && hi[1] <= 90);
    }
    f->lonlat = ll;
    if (ll) {
        double lon0 = (lo[0] + hi[0]) / 2, lat0 = (lo[1] + hi[1]) / 2;
        double kx = EARTH_RADIUS * cos(lat0 * M_PI / 180) * M_PI / 180, ky = EARTH_RADIUS * M_PI / 180;
        f->origin[0] = lon0;
        f->origin[1] = lat0;
        for (size_t i = 0; i < f->n; i++)
            for (size_t j = 0; j < f->items[i].nloops; j++)
                for (size_t k = 0; k < f->items[i].sizes[j]; k++) {
                    double *p = &f->items[i].loops[j][2 * k];
                    p[0] = (p[0] - lon0) * kx;
                    p[1] = (p[1] - lat0) * ky;
                }
    } else {
        f->origin[0] = round((lo[0] + hi[0]) / 2);
        f->origin[1] = round((lo[1] + hi[1]) / 2);
        for (size_t i = 0; i < f->n; i++)
            for (size_t j = 0; j < f->items[i].nloops; j++)
                for (size_t k = 0; k < f->items[i].sizes[j]; k++) {
                    double *p = &f->items[i].loops[j][2 * k];
                    p[0] -= f->origin[0];
                    p[1] -= f->origin[1];
                }
    }
done:
    ag_jsondoc_free(doc);
    if (st != AG_OK) {
        ag_footprints_free(f);
        return st;
    }
    *out = f;
    return AG_OK;
}

ag_status ag_footprints_read_file(const char *path, const ag_footprints_options *opt,
                                  ag_footprints **out, ag_error *err)
{
    *out = NULL;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot open %s", path);
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (AG_ARRAY_RESERVE_MORE(buf, cap, len, 65536)) { /* room for a read of 64 KiB */
            free(buf);
            fclose(fp);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        size_t r = fread(buf + len, 1, cap - len, fp);
        len += r;
        if (r == 0)
            break;
    }
    int bad = ferror(fp);
    fclose(fp);
    if (bad) {
        free(buf);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot read %s", path);
    }
    ag_status st = ag_footprints_read_buffer(buf, len, opt, out, err);
    free(buf);
    return st;
}

static void free_issues(ag_footprint_issue *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(v[i].id);
    free(v);
}

void ag_footprints_report_free(ag_footprints_report *r)
{
    if (!r)
        return;
    free_issues(r->failed, r->nfailed);
    free_issues(r->fallbacks, r->nfallbacks);
    free_issues(r->not_watertight, r->nnot_watertight);
    free_issues(r->fixed, r->nfixed);
    memset(r, 0, sizeof *r);
}

static int add_issue(ag_footprint_issue **list, size_t *n, const char *id, const char *reason,
                     ag_built built, double moved)
{
    ag_footprint_issue *nl = realloc(*list, (*n + 1) * sizeof *nl);
    if (!nl)
        return 0;
    *list = nl;
    nl[*n].id = dupstr(id);
    if (!nl[*n].id)
        return 0;
    snprintf(nl[*n].reason, sizeof nl[*n].reason, "%s", reason);
    nl[*n].built = built;
    nl[*n].moved = moved;
    (*n)++;
    return 1;
}

ag_status ag_footprints_report_add_id(ag_footprints_report *r, const char *id,
                                      const char *read_fixes, const ag_building_result *b)
{
    int ok = 1;
    if (!read_fixes)
        read_fixes = "";
    if (b->built == AG_BUILT_STYLED)
        r->succeeded++;
    else if (b->built == AG_BUILT_NONE)
        ok = add_issue(&r->failed, &r->nfailed, id, b->reason, b->built, 0);
    else
        ok = add_issue(&r->fallbacks, &r->nfallbacks, id, b->reason, b->built, b->moved);
    if (ok && (b->nfixes || read_fixes[0])) {
        char text[sizeof r->fixed[0].reason];
        snprintf(text, sizeof text, "%.100s%s%.150s", read_fixes,
                 read_fixes[0] && b->nfixes ? "; " : "", b->nfixes ? b->fixes : "");
        ok = add_issue(&r->fixed, &r->nfixed, id, text, b->built, 0);
    }
    r->triangles += b->triangles;
    r->events += b->events;
    return ok ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_footprints_report_add(ag_footprints_report *r, const ag_footprint *fp,
                                   const ag_building_result *b)
{
    return ag_footprints_report_add_id(r, fp->id, fp->fixes, b);
}

static json_t *issues_json(const ag_footprint_issue *v, size_t n, int with_fallback)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++) {
        json_t *o = json_pack("{s:s,s:s}", "id", v[i].id, "reason", v[i].reason);
        if (o && with_fallback) {
            json_object_set_new(o, "fallback", json_string(ag_built_name(v[i].built)));
            if (v[i].built == AG_BUILT_SIMPLIFIED)
                json_object_set_new(o, "moved", json_real(v[i].moved));
        }
        if (!o || json_array_append_new(a, o) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

static json_t *fixes_json(const ag_footprint_issue *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++) {
        json_t *o = json_pack("{s:s,s:s}", "id", v[i].id, "fixes", v[i].reason);
        if (!o || json_array_append_new(a, o) != 0) {
            json_decref(a);
            return NULL;
        }
    }
    return a;
}

json_t *ag_footprints_report_json(const ag_footprints_report *r)
{
    return json_pack("{s:I,s:I,s:o*,s:o*,s:I,s:o*,s:o*,s:I,s:I}",
                     "footprints", (json_int_t)r->footprints,
                     "succeeded", (json_int_t)r->succeeded,
                     "fallbacks", issues_json(r->fallbacks, r->nfallbacks, 1),
                     "failed", issues_json(r->failed, r->nfailed, 0),
                     "not_watertight", (json_int_t)r->nnot_watertight,
                     "not_watertight_items", issues_json(r->not_watertight, r->nnot_watertight, 0),
                     "fixed", fixes_json(r->fixed, r->nfixed),
                     "triangles", (json_int_t)r->triangles,
                     "events", (json_int_t)r->events);
}

ag_status ag_footprints_extrude_with(const ag_footprints *f, const ag_style *style,
                                     const ag_extrude_options *opt, ag_mesh *m,
                                     ag_footprints_report *report, ag_error *err)
{
    memset(report, 0, sizeof *report);
    report->footprints = f->n;
    for (size_t i = 0; i < f->n; i++) {
        const ag_footprint *fp = &f->items[i];
        size_t group = 0;
        ag_building_result b;
        ag_status st = ag_mesh_add_group(m, fp->id, &group);
        if (st == AG_OK)
            st = ag_building_extrude(style, (const double *const *)fp->loops, fp->sizes,
                                     fp->nloops, fp->height, i, opt, m, (int32_t)group, &b, err);
        if (st == AG_OK)
            st = ag_footprints_report_add(report, fp, &b);
        if (st == AG_ERR_NOMEM)
            return ag_error_set(err, st, 0, "out of memory");
        if (st != AG_OK)
            return st;
    }
    return AG_OK;
}

ag_status ag_footprints_extrude(const ag_footprints *f, const ag_style *style, ag_mesh *m,
                                ag_footprints_report *report, ag_error *err)
{
    return ag_footprints_extrude_with(f, style, NULL, m, report, err);
}
