#include "app_points.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/ply.h"
#include "../io/points_glb.h"
#include "../store/grammars.h"
#include "../store/pointclouds.h"
#include "store_ws.h"

/* Adds (or replaces) an int32 property with the given values. */
static ag_status set_ids(ag_cloud *c, const char *name, const int32_t *values, ag_error *err)
{
    ag_cloud_remove_property(c, name);
    size_t i;
    ag_status s = ag_cloud_add_property(c, name, AG_SCALAR_INT32, &i, err);
    if (s == AG_OK)
        memcpy(c->props[i].values, values, c->n * sizeof *values);
    return s;
}

/* The model's points and (want_ids) segmentation, read in one snapshot. */
static ag_status read_points(ag_db *db, int64_t id, unsigned what, const char *const *only,
                             int want_ids, ag_pointcloud_info *info, ag_cloud **cloud,
                             ag_pointcloud_segmentation *seg, ag_error *err)
{
    *cloud = NULL;
    memset(seg, 0, sizeof *seg);
    ag_status s = ag_pointclouds_read_begin(db, err);
    if (s != AG_OK)
        return s;
    s = ag_pointclouds_info(db, id, info, err);
    if (s == AG_OK && what)
        s = ag_pointclouds_load(db, info, what, only, cloud, err);
    if (s == AG_OK && info->segmentation)
        s = ag_pointclouds_get_segmentation(db, info, want_ids, seg, err);
    ag_pointclouds_read_end(db);
    if (s != AG_OK) {
        ag_cloud_free(*cloud);
        *cloud = NULL;
        ag_pointcloud_segmentation_clear(seg);
    }
    return s;
}

/* Segments with points (ids below seg->nsegments may be unused: segment_cloud.h). */
static size_t segments_in_use(const ag_pointcloud_segmentation *seg)
{
    uint8_t *seen = calloc(seg->nsegments + 1, 1);
    if (!seen || !seg->segment) {
        free(seen);
        return seg->nsegments; /* out of memory: the ids, an upper bound */
    }
    size_t used = 0;
    for (size_t i = 0; i < seg->n; i++) {
        int32_t sg = seg->segment[i];
        if (sg >= 0 && (size_t)sg < seg->nsegments && !seen[sg]) {
            seen[sg] = 1;
            used++;
        }
    }
    free(seen);
    return used;
}

/* The ETag of what a read shows: the points never change, the segmentation has its id, the
 * normals come once. */
static void etag_of(char *buf, size_t len, const char *what, const ag_pointcloud_info *info,
                    size_t shown)
{
    snprintf(buf, len, "\"%s-%lld-%lld-%d-%zu\"", what, (long long)info->model,
             (long long)info->segmentation, info->normals, shown);
}

/* c as binary little-endian PLY in out. */
static ag_status ply_bytes(const ag_cloud *c, ag_app_bytes *out, ag_error *err)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing PLY");
    ag_ply_write_options po = {.encoding = AG_PLY_BINARY_LE};
    ag_status s = ag_ply_write(c, &po, f, err);
    if (fclose(f) != 0 && s == AG_OK)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing PLY");
    if (s == AG_OK) {
        out->data = (uint8_t *)buf;
        out->len = len;
    } else {
        free(buf);
    }
    return s;
}

ag_status ag_app_points_ply(ag_app *app, int64_t id, int (*fresh)(void *user, const char *etag),
                            void *user, ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_pointcloud_info info;
    ag_cloud *c = NULL;
    ag_pointcloud_segmentation seg;
    ag_status s = read_points(db, id, 0, NULL, 0, &info, &c, &seg, err);
    if (s != AG_OK)
        return s;
    ag_pointcloud_segmentation_clear(&seg);
    etag_of(out->etag, sizeof out->etag, "ply", &info, info.points);
    if (fresh && fresh(user, out->etag))
        return AG_OK;
    s = read_points(db, id,
                    AG_POINTCLOUDS_POSITIONS | AG_POINTCLOUDS_NORMALS | AG_POINTCLOUDS_PROPERTIES,
                    NULL, 1, &info, &c, &seg, err);
    if (s != AG_OK)
        return s;
    /* the tag of what was read (a change may have come in between) */
    etag_of(out->etag, sizeof out->etag, "ply", &info, info.points);
    if (seg.segment) {
        s = set_ids(c, "segment", seg.segment, err);
        if (s == AG_OK)
            s = set_ids(c, "label", seg.label, err);
        if (s == AG_OK)
            s = set_ids(c, "piece", seg.piece, err);
    }
    if (s == AG_OK)
        s = ply_bytes(c, out, err);
    ag_cloud_free(c);
    ag_pointcloud_segmentation_clear(&seg);
    return s;
}

/* RGBA of the shown points from red, green and blue (16-bit colour, as LAS has, when any
 * value passes 255); NULL when the cloud has no colour. */
static uint8_t *colours(const ag_cloud *c, const uint32_t *order, size_t k)
{
    const ag_cloud_property *ch[3] = {ag_cloud_find(c, "red"), ag_cloud_find(c, "green"),
                                      ag_cloud_find(c, "blue")};
    if (!ch[0] || !ch[1] || !ch[2])
        return NULL;
    double most = 0;
    for (int a = 0; a < 3; a++)
        for (size_t i = 0; i < c->n; i++) {
            double v = ag_cloud_get(ch[a], i);
            if (v > most)
                most = v;
        }
    int floats = ag_scalar_is_float(ch[0]->type) && most <= 1.0;
    double scale = floats ? 255.0 : most > 255 ? 1.0 / 257.0 : 1.0;
    uint8_t *rgba = malloc(4 * (k ? k : 1));
    for (size_t i = 0; rgba && i < k; i++) {
        for (int a = 0; a < 3; a++) {
            double v = ag_cloud_get(ch[a], order[i]) * scale + 0.5;
            rgba[4 * i + a] = v <= 0 ? 0 : v >= 255 ? 255 : (uint8_t)v;
        }
        rgba[4 * i + 3] = 255;
    }
    return rgba;
}

ag_status ag_app_points_glb(ag_app *app, int64_t id, size_t budget,
                            int (*fresh)(void *user, const char *etag), void *user,
                            ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    if (!budget)
        budget = AG_POINTS_GLB_DEFAULT_BUDGET;
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_pointcloud_info info;
    ag_cloud *c = NULL;
    ag_pointcloud_segmentation seg;
    ag_status s = read_points(db, id, 0, NULL, 0, &info, &c, &seg, err);
    if (s != AG_OK)
        return s;
    ag_pointcloud_segmentation_clear(&seg);
    size_t k = budget < info.points ? budget : info.points;
    etag_of(out->etag, sizeof out->etag, "glb", &info, k);
    if (fresh && fresh(user, out->etag))
        return AG_OK;
    static const char *const wanted[] = {"red", "green", "blue", "classification", NULL};
    s = read_points(db, id, AG_POINTCLOUDS_POSITIONS | AG_POINTCLOUDS_PROPERTIES, wanted, 1,
                    &info, &c, &seg, err);
    if (s != AG_OK)
        return s;
    k = budget < info.points ? budget : info.points;
    etag_of(out->etag, sizeof out->etag, "glb", &info, k);
    uint32_t *order = malloc((k ? k : 1) * sizeof *order);
    double *xyz = malloc((k ? k : 1) * 3 * sizeof *xyz);
    float *attr = malloc((k ? k : 1) * 3 * sizeof *attr);
    uint8_t *rgba = NULL;
    json_t *extras = NULL;
    if (!order || !xyz || !attr)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for %zu points", k);
    if (s == AG_OK)
        s = ag_pointclouds_load_order(db, &info, k, order, err);
    ag_points_glb_attribute attrs[3];
    size_t nattrs = 0;
    if (s == AG_OK) {
        for (size_t i = 0; i < k; i++)
            memcpy(xyz + 3 * i, c->xyz + 3 * (size_t)order[i], 3 * sizeof *xyz);
        rgba = colours(c, order, k);
        if (seg.segment) {
            float *sa = attr, *la = attr + k;
            for (size_t i = 0; i < k; i++) {
                sa[i] = (float)seg.segment[order[i]];
                la[i] = (float)seg.label[order[i]];
            }
            attrs[nattrs++] = (ag_points_glb_attribute){"_SEGMENT", sa};
            attrs[nattrs++] = (ag_points_glb_attribute){"_LABEL", la};
        }
        const ag_cloud_property *cls = ag_cloud_find(c, "classification");
        if (cls) {
            float *ca = attr + 2 * k;
            for (size_t i = 0; i < k; i++)
                ca[i] = (float)ag_cloud_get(cls, order[i]);
            attrs[nattrs++] = (ag_points_glb_attribute){"_CLASSIFICATION", ca};
        }
        extras = json_pack("{s:I, s:I, s:I, s:I, s:[f,f,f], s:b, s:I, s:I, s:I}", "model",
                           (json_int_t)id, "points", (json_int_t)info.points, "shown",
                           (json_int_t)k, "budget", (json_int_t)budget, "offset",
                           info.offset[0], info.offset[1], info.offset[2], "segmented",
                           seg.segment != NULL, "segments", (json_int_t)segments_in_use(&seg),
                           "segment_ids", (json_int_t)seg.nsegments, "labels",
                           (json_int_t)seg.nlabels);
        if (!extras)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (s == AG_OK) {
        ag_points_glb in = {.n = k,
                            .xyz = xyz,
                            .rgba = rgba,
                            .attributes = attrs,
                            .nattributes = nattrs,
                            .extras = extras};
        s = ag_points_glb_write(&in, &out->data, &out->len, err);
    }
    json_decref(extras);
    free(order);
    free(xyz);
    free(attr);
    free(rgba);
    ag_cloud_free(c);
    ag_pointcloud_segmentation_clear(&seg);
    return s;
}

/* Every k-th point of *c, k the least that keeps at most budget (0: all), in place. */
static ag_status thin_to_budget(ag_cloud **c, size_t budget, ag_error *err)
{
    size_t n = (*c)->n;
    if (!budget || n <= budget)
        return AG_OK;
    size_t k = (n + budget - 1) / budget, m = (n + k - 1) / k;
    uint32_t *idx = malloc(m * sizeof *idx);
    if (!idx)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory for %zu points", m);
    for (size_t i = 0; i < m; i++)
        idx[i] = (uint32_t)(i * k);
    ag_cloud *kept = NULL;
    ag_status s = ag_cloud_subset(*c, idx, m, &kept, err);
    free(idx);
    if (s == AG_OK) {
        ag_cloud_free(*c);
        *c = kept;
    }
    return s;
}

ag_status ag_app_points_derived_ply(ag_app *app, int64_t id, size_t budget,
                                    int (*fresh)(void *user, const char *etag), void *user,
                                    ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    /* the grammar row names the state: each saved point model state has its own mesh file */
    ag_grammar_row g;
    ag_status s = ag_grammars_current(db, id, 0, &g, err);
    if (s == AG_OK) {
        snprintf(out->etag, sizeof out->etag, "\"derived-%lld-%lld-%zu\"", (long long)id,
                 (long long)g.mesh_blob, budget);
        ag_grammars_row_clear(&g);
        if (fresh && fresh(user, out->etag))
            return AG_OK;
    }
    ag_pointmodel *pm = NULL;
    ag_cloud *c = NULL;
    int64_t version = 0, blob = 0;
    if ((s = ag_pointclouds_read_begin(db, err)) != AG_OK)
        return s;
    s = ag_store_ws_read_point_model(db, id, "", &pm, &version, err);
    /* the tag of what was read (a change may have come in between) */
    if (s == AG_OK && (s = ag_grammars_current(db, id, 0, &g, err)) == AG_OK) {
        blob = g.mesh_blob;
        ag_grammars_row_clear(&g);
    }
    ag_pointclouds_read_end(db);
    if (s == AG_OK) {
        snprintf(out->etag, sizeof out->etag, "\"derived-%lld-%lld-%zu\"", (long long)id,
                 (long long)blob, budget);
        s = ag_pointmodel_derive(pm, AG_CLOUD_MAX_POINTS, &c, NULL, err);
    }
    if (s == AG_OK)
        s = thin_to_budget(&c, budget, err);
    if (s == AG_OK)
        s = ply_bytes(c, out, err);
    ag_cloud_free(c);
    ag_pointmodel_free(pm);
    return s;
}
