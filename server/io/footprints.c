#include "footprints.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "../core/extrude/extrude.h"

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

/* Visits every coordinate pair of a Polygon/MultiPolygon's rings. */
static int ring_ok(json_t *ring)
{
    if (!json_is_array(ring) || json_array_size(ring) < 3)
        return 0;
    size_t i;
    json_t *pt;
    json_array_foreach(ring, i, pt)
    {
        if (!json_is_array(pt) || json_array_size(pt) < 2 ||
            !json_is_number(json_array_get(pt, 0)) || !json_is_number(json_array_get(pt, 1)))
            return 0;
        double x = json_number_value(json_array_get(pt, 0));
        double y = json_number_value(json_array_get(pt, 1));
        if (!isfinite(x) || !isfinite(y))
            return 0;
    }
    return 1;
}

static ag_status add_ring(ag_footprint *fp, json_t *ring, int hole)
{
    size_t n = json_array_size(ring);
    double *xy = malloc(2 * n * sizeof *xy);
    if (!xy)
        return AG_ERR_NOMEM;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        json_t *pt = json_array_get(ring, i);
        xy[2 * k] = json_number_value(json_array_get(pt, 0));
        xy[2 * k + 1] = json_number_value(json_array_get(pt, 1));
        k++;
    }
    if (k > 1 && xy[0] == xy[2 * (k - 1)] && xy[1] == xy[2 * (k - 1) + 1])
        k--; /* GeoJSON closes rings by repeating the first position */
    size_t *ns = realloc(fp->sizes, (fp->nloops + 1) * sizeof *ns);
    if (ns)
        fp->sizes = ns;
    double **nl = realloc(fp->loops, (fp->nloops + 1) * sizeof *nl);
    if (nl)
        fp->loops = nl;
    if (!ns || !nl) {
        free(xy);
        return AG_ERR_NOMEM;
    }
    (void)hole;
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

static ag_status add_polygon(ag_footprint *fp, json_t *rings, size_t fi, ag_error *err)
{
    if (!json_is_array(rings) || json_array_size(rings) == 0)
        return ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                            "feature %zu: a polygon needs an array of rings", fi);
    size_t i;
    json_t *ring;
    json_array_foreach(rings, i, ring)
    {
        if (!ring_ok(ring))
            return ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                                "feature %zu: ring %zu is not an array of at least 3 finite "
                                "[x, y] positions", fi, i);
        size_t first = fp->nloops;
        if (add_ring(fp, ring, i > 0) != AG_OK)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        double a = ring_area(fp->loops[first], fp->sizes[first]);
        if ((i == 0 && a < 0) || (i > 0 && a > 0))
            reverse(fp->loops[first], fp->sizes[first]);
    }
    return AG_OK;
}

static char *dupstr(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static char *id_text(json_t *v)
{
    char buf[64];
    if (json_is_string(v))
        return dupstr(json_string_value(v));
    if (json_is_integer(v)) {
        snprintf(buf, sizeof buf, "%lld", (long long)json_integer_value(v));
        return dupstr(buf);
    }
    if (json_is_real(v)) {
        snprintf(buf, sizeof buf, "%.17g", json_real_value(v));
        return dupstr(buf);
    }
    return NULL;
}

static int crs_is_lonlat(json_t *root)
{
    json_t *name = json_object_get(json_object_get(json_object_get(root, "crs"), "properties"), "name");
    if (!json_is_string(name))
        return -1; /* no crs member */
    const char *s = json_string_value(name);
    return strstr(s, "CRS84") || strstr(s, "4326") ? 1 : 0;
}

ag_status ag_footprints_read_buffer(const char *data, size_t len, const ag_footprints_options *opt,
                                    ag_footprints **out, ag_error *err)
{
    *out = NULL;
    json_error_t je;
    json_t *root = json_loadb(data, len, 0, &je);
    if (!root)
        return ag_error_set(err, AG_ERR_PARSE, je.line, "GeoJSON: %s (line %d, column %d)",
                            je.text, je.line, je.column);
    json_t *features = NULL, *single = NULL;
    const char *type = json_string_value(json_object_get(root, "type"));
    if (type && strcmp(type, "FeatureCollection") == 0) {
        features = json_object_get(root, "features");
        if (!json_is_array(features)) {
            json_decref(root);
            return ag_error_set(err, AG_ERR_PARSE, 0, "GeoJSON: \"features\" must be an array");
        }
    } else if (type && strcmp(type, "Feature") == 0) {
        single = json_array();
        json_array_append(single, root);
        features = single;
    } else {
        json_decref(root);
        return ag_error_set(err, AG_ERR_PARSE, 0,
                            "GeoJSON: expected a FeatureCollection or a Feature");
    }
    ag_footprints *f = calloc(1, sizeof *f);
    size_t nf = json_array_size(features);
    if (f)
        f->items = calloc(nf ? nf : 1, sizeof *f->items);
    ag_status st = AG_OK;
    if (!f || !f->items) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    const char *hp[] = {"height", "building:height", "measuredHeight", NULL};
    size_t fi;
    json_t *feat;
    json_array_foreach(features, fi, feat)
    {
        json_t *geom = json_object_get(feat, "geometry");
        const char *gt = json_string_value(json_object_get(geom, "type"));
        json_t *coords = json_object_get(geom, "coordinates");
        if (!gt || (strcmp(gt, "Polygon") != 0 && strcmp(gt, "MultiPolygon") != 0)) {
            skip(f, fi, "geometry is not a Polygon or MultiPolygon");
            continue;
        }
        ag_footprint *fp = &f->items[f->n];
        memset(fp, 0, sizeof *fp);
        json_t *props = json_object_get(feat, "properties");
        fp->id = id_text(json_object_get(feat, "id"));
        if (!fp->id)
            fp->id = id_text(json_object_get(props, "id"));
        if (!fp->id) {
            char buf[32];
            snprintf(buf, sizeof buf, "%zu", fi);
            fp->id = dupstr(buf);
        }
        if (opt && opt->height_property) {
            json_t *h = json_object_get(props, opt->height_property);
            if (json_is_number(h))
                fp->height = json_number_value(h);
        } else {
            for (int k = 0; hp[k]; k++) {
                json_t *h = json_object_get(props, hp[k]);
                if (json_is_number(h)) {
                    fp->height = json_number_value(h);
                    break;
                }
            }
        }
        if (!isfinite(fp->height) || fp->height < 0)
            fp->height = 0;
        if (strcmp(gt, "Polygon") == 0) {
            st = add_polygon(fp, coords, fi, err);
        } else if (!json_is_array(coords)) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)fi + 1,
                              "feature %zu: MultiPolygon coordinates must be an array", fi);
        } else {
            size_t pi;
            json_t *poly;
            json_array_foreach(coords, pi, poly)
            {
                st = add_polygon(fp, poly, fi, err);
                if (st != AG_OK)
                    break;
            }
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
        int c = crs_is_lonlat(root);
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
    if (single)
        json_decref(single);
    json_decref(root);
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

void ag_footprints_report_free(ag_footprints_report *r)
{
    if (!r)
        return;
    for (size_t i = 0; i < r->nfailed; i++)
        free(r->failed[i].id);
    for (size_t i = 0; i < r->nnot_watertight; i++)
        free(r->not_watertight[i].id);
    free(r->failed);
    free(r->not_watertight);
    memset(r, 0, sizeof *r);
}

static int add_issue(ag_footprint_issue **list, size_t *n, const char *id, const char *reason)
{
    ag_footprint_issue *nl = realloc(*list, (*n + 1) * sizeof *nl);
    if (!nl)
        return 0;
    *list = nl;
    nl[*n].id = dupstr(id);
    if (!nl[*n].id)
        return 0;
    snprintf(nl[*n].reason, sizeof nl[*n].reason, "%s", reason);
    (*n)++;
    return 1;
}

ag_status ag_footprints_extrude(const ag_footprints *f, const ag_style *style, ag_mesh *m,
                                ag_footprints_report *report, ag_error *err)
{
    memset(report, 0, sizeof *report);
    report->footprints = f->n;
    for (size_t i = 0; i < f->n; i++) {
        const ag_footprint *fp = &f->items[i];
        ag_error e = {0};
        ag_plan *plan = NULL;
        ag_status st = ag_style_apply(style, (const double *const *)fp->loops, fp->sizes,
                                      fp->nloops, fp->height, i, &plan, &e);
        size_t group = 0;
        if (st == AG_OK)
            st = ag_mesh_add_group(m, fp->id, &group);
        ag_extrude_result res;
        if (st == AG_OK)
            st = ag_extrude_plan(plan, m, (int32_t)group, &res, NULL, &e);
        ag_plan_free(plan);
        if (st == AG_ERR_NOMEM)
            return ag_error_set(err, st, 0, "out of memory");
        if (st != AG_OK) {
            if (!add_issue(&report->failed, &report->nfailed, fp->id,
                           e.text[0] ? e.text : ag_status_message(st)))
                return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            continue;
        }
        report->succeeded++;
        report->triangles += res.triangles;
        if (res.failing_faces) {
            char why[200];
            snprintf(why, sizeof why, "%zu face(s) fail; face %d: %s", res.failing_faces,
                     (int)res.problems[0].face, res.problems[0].reason);
            if (!add_issue(&report->not_watertight, &report->nnot_watertight, fp->id, why))
                return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
    }
    return AG_OK;
}
