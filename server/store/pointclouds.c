#include "pointclouds.h"

#include <jansson.h>
#include <stdlib.h>
#include <string.h>

static size_t chunks_of(size_t n, size_t chunk)
{
    return n ? (n - 1) / chunk + 1 : 0;
}

static size_t chunk_len(size_t n, size_t chunk, size_t k)
{
    size_t start = k * chunk;
    return n - start < chunk ? n - start : chunk;
}

static ag_status put_column(ag_db *db, int64_t model, int col, size_t chunk, const uint8_t *data,
                            size_t len, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "INSERT OR REPLACE INTO pointcloud_columns (model_id, col, chunk, data) VALUES (?, ?, ?, ?)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int(st, 2, col);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)chunk);
    sqlite3_bind_blob64(st, 4, len ? (const void *)data : "", len, SQLITE_STATIC);
    return ag_db_step_done(db, st, "storing points", err);
}

/* Encodes and stores one column of c in chunks. */
typedef ag_status (*encode_fn)(const ag_cloud *c, size_t which, size_t start, size_t count,
                               uint8_t **out, size_t *len, ag_error *err);

static ag_status enc_positions(const ag_cloud *c, size_t which, size_t start, size_t count,
                               uint8_t **out, size_t *len, ag_error *err)
{
    return ag_cloudblob_encode_positions(c, (ag_cloudblob_positions)which, start, count, out,
                                         len, err);
}

static ag_status enc_normals(const ag_cloud *c, size_t which, size_t start, size_t count,
                             uint8_t **out, size_t *len, ag_error *err)
{
    (void)which;
    return ag_cloudblob_encode_normals(c, start, count, out, len, err);
}

static ag_status enc_property(const ag_cloud *c, size_t which, size_t start, size_t count,
                              uint8_t **out, size_t *len, ag_error *err)
{
    return ag_cloudblob_encode_property(c, which, start, count, out, len, err);
}

static ag_status put_chunks(ag_db *db, int64_t model, int col, const ag_cloud *c, size_t chunk,
                            encode_fn fn, size_t which, ag_error *err)
{
    ag_status s = AG_OK;
    for (size_t k = 0; s == AG_OK && k < chunks_of(c->n, chunk); k++) {
        uint8_t *data = NULL;
        size_t len = 0;
        s = fn(c, which, k * chunk, chunk_len(c->n, chunk, k), &data, &len, err);
        if (s == AG_OK)
            s = put_column(db, model, col, k, data, len, err);
        free(data);
    }
    return s;
}

static char *properties_json(const ag_cloud *c)
{
    json_t *list = json_array();
    for (size_t p = 0; list && p < c->nprops; p++)
        json_array_append_new(list, json_pack("{s:s, s:s}", "name", c->props[p].name, "type",
                                              ag_scalar_name(c->props[p].type)));
    char *text = list ? json_dumps(list, JSON_COMPACT) : NULL;
    json_decref(list);
    return text;
}

ag_status ag_pointclouds_put(ag_db *db, int64_t model, const ag_cloud *c, const uint32_t *lod,
                             size_t chunk_points, ag_error *err)
{
    size_t chunk = chunk_points ? chunk_points : AG_POINTCLOUDS_CHUNK;
    ag_cloudblob_positions enc = ag_cloudblob_positions_choose(c);
    char *props = properties_json(c);
    if (!props)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "INSERT INTO pointclouds (model_id, points, chunk_points, offset_x, offset_y, offset_z, "
        "scale_x, scale_y, scale_z, positions, normals, properties) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
        err);
    if (s == AG_OK) {
        sqlite3_bind_int64(st, 1, model);
        sqlite3_bind_int64(st, 2, (sqlite3_int64)c->n);
        sqlite3_bind_int64(st, 3, (sqlite3_int64)chunk);
        for (int k = 0; k < 3; k++) {
            sqlite3_bind_double(st, 4 + k, c->offset[k]);
            sqlite3_bind_double(st, 7 + k, c->scale[k] > 0 ? c->scale[k] : 0);
        }
        sqlite3_bind_text(st, 10, ag_cloudblob_positions_name(enc), -1, SQLITE_STATIC);
        sqlite3_bind_int(st, 11, c->normals != NULL);
        sqlite3_bind_text(st, 12, props, -1, SQLITE_STATIC);
        s = ag_db_step_done(db, st, "storing a point cloud", err);
    }
    free(props);
    if (s == AG_OK)
        s = put_chunks(db, model, AG_POINTCLOUDS_COL_POSITIONS, c, chunk, enc_positions, enc, err);
    if (s == AG_OK && c->normals)
        s = put_chunks(db, model, AG_POINTCLOUDS_COL_NORMALS, c, chunk, enc_normals, 0, err);
    for (size_t k = 0; s == AG_OK && k < chunks_of(c->n, chunk); k++) {
        uint8_t *data = NULL;
        size_t len = 0;
        s = ag_cloudblob_encode_indices(lod + k * chunk, chunk_len(c->n, chunk, k), &data, &len,
                                        err);
        if (s == AG_OK)
            s = put_column(db, model, AG_POINTCLOUDS_COL_ORDER, k, data, len, err);
        free(data);
    }
    for (size_t p = 0; s == AG_OK && p < c->nprops; p++)
        s = put_chunks(db, model, AG_POINTCLOUDS_COL_PROPERTY + (int)p, c, chunk, enc_property, p,
                       err);
    return s;
}

static ag_status parse_properties(const char *text, ag_pointcloud_info *info, ag_error *err)
{
    json_t *list = json_loads(text ? text : "[]", 0, NULL);
    ag_status s = json_is_array(list) && json_array_size(list) <= AG_CLOUD_MAX_PROPERTIES
                      ? AG_OK
                      : ag_error_set(err, AG_ERR_INTERNAL, 0, "a stored property list is not one");
    size_t i;
    json_t *v;
    json_array_foreach(list, i, v) {
        if (s != AG_OK)
            break;
        const char *name = json_string_value(json_object_get(v, "name"));
        const char *type = json_string_value(json_object_get(v, "type"));
        int t = -1;
        for (int k = 0; type && k < AG_SCALAR_COUNT; k++)
            if (strcmp(type, ag_scalar_name((ag_scalar_type)k)) == 0)
                t = k;
        if (!name || strlen(name) >= AG_CLOUD_NAME_MAX || t < 0) {
            s = ag_error_set(err, AG_ERR_INTERNAL, 0, "stored property %zu is not one", i);
            break;
        }
        strcpy(info->props[i].name, name);
        info->props[i].type = (ag_scalar_type)t;
        info->nprops = i + 1;
    }
    json_decref(list);
    return s;
}

ag_status ag_pointclouds_info(ag_db *db, int64_t model, ag_pointcloud_info *info,
                              ag_error *err)
{
    memset(info, 0, sizeof *info);
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "SELECT points, chunk_points, offset_x, offset_y, offset_z, scale_x, scale_y, scale_z, "
        "positions, normals, properties, coalesce(segmentation, 0) FROM pointclouds "
        "WHERE model_id = ?",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        info->model = model;
        info->points = (size_t)sqlite3_column_int64(st, 0);
        info->chunk_points = (size_t)sqlite3_column_int64(st, 1);
        for (int k = 0; k < 3; k++) {
            info->offset[k] = sqlite3_column_double(st, 2 + k);
            info->scale[k] = sqlite3_column_double(st, 5 + k);
        }
        info->positions =
            ag_cloudblob_positions_from_name((const char *)sqlite3_column_text(st, 8));
        info->normals = sqlite3_column_int(st, 9);
        s = parse_properties((const char *)sqlite3_column_text(st, 10), info, err);
        info->segmentation = sqlite3_column_int64(st, 11);
        if (s == AG_OK && (!info->positions || !info->chunk_points))
            s = ag_error_set(err, AG_ERR_INTERNAL, 0, "the stored points of model %lld are "
                             "not readable", (long long)model);
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld is not a point cloud",
                         (long long)model);
    } else {
        s = ag_db_fail(db, err, "reading a point cloud");
    }
    sqlite3_reset(st);
    return s;
}

/* Calls fn(user, chunk, data, len) for each stored chunk of a column, in order; every chunk
 * the point count needs must be there. */
typedef ag_status (*chunk_fn)(void *user, size_t chunk, const uint8_t *data, size_t len,
                              ag_error *err);

static ag_status each_chunk(ag_db *db, const ag_pointcloud_info *info, int col, size_t upto,
                            chunk_fn fn, void *user, ag_error *err)
{
    size_t want = chunks_of(upto, info->chunk_points);
    if (!want)
        return AG_OK;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT chunk, data FROM pointcloud_columns WHERE model_id = ? "
                                 "AND col = ? AND chunk < ? ORDER BY chunk",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, info->model);
    sqlite3_bind_int(st, 2, col);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)want);
    size_t next = 0;
    int rc;
    while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        size_t k = (size_t)sqlite3_column_int64(st, 0);
        const uint8_t *data = sqlite3_column_blob(st, 1);
        size_t len = (size_t)sqlite3_column_bytes(st, 1);
        if (k != next)
            s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                             "chunk %zu of column %d of model %lld is missing", next, col,
                             (long long)info->model);
        else
            s = fn(user, k, data, len, err);
        next++;
    }
    if (s == AG_OK && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading points");
    if (s == AG_OK && next != want)
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "chunk %zu of column %d of model %lld is missing",
                         next, col, (long long)info->model);
    sqlite3_reset(st);
    return s;
}

typedef struct {
    const ag_pointcloud_info *info;
    ag_cloud *c;
    size_t prop; /* the cloud's property being filled */
    uint32_t *order;
    size_t count;
} load_ctx;

static ag_status got_positions(void *user, size_t k, const uint8_t *data, size_t len,
                               ag_error *err)
{
    load_ctx *x = user;
    size_t chunk = x->info->chunk_points;
    return ag_cloudblob_decode_positions(data, len, x->info->positions, x->c, k * chunk,
                                         chunk_len(x->c->n, chunk, k), err);
}

static ag_status got_normals(void *user, size_t k, const uint8_t *data, size_t len,
                             ag_error *err)
{
    load_ctx *x = user;
    size_t chunk = x->info->chunk_points;
    return ag_cloudblob_decode_normals(data, len, x->c, k * chunk, chunk_len(x->c->n, chunk, k),
                                       err);
}

static ag_status got_property(void *user, size_t k, const uint8_t *data, size_t len,
                              ag_error *err)
{
    load_ctx *x = user;
    size_t chunk = x->info->chunk_points;
    return ag_cloudblob_decode_property(data, len, x->c, x->prop, k * chunk,
                                        chunk_len(x->c->n, chunk, k), err);
}

static int wanted(const char *name, const char *const *only)
{
    if (!only)
        return 1;
    for (; *only; only++)
        if (strcmp(*only, name) == 0)
            return 1;
    return 0;
}

ag_status ag_pointclouds_load(ag_db *db, const ag_pointcloud_info *info, unsigned what,
                              const char *const *only, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_cloud *c = ag_cloud_create();
    if (!c)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    memcpy(c->offset, info->offset, sizeof c->offset);
    memcpy(c->scale, info->scale, sizeof c->scale);
    ag_status s = AG_OK;
    if ((what & AG_POINTCLOUDS_NORMALS) && info->normals)
        s = ag_cloud_add_normals(c, err);
    size_t col_of[AG_CLOUD_MAX_PROPERTIES];
    size_t nprops = 0;
    for (size_t p = 0; s == AG_OK && (what & AG_POINTCLOUDS_PROPERTIES) && p < info->nprops; p++) {
        if (!wanted(info->props[p].name, only))
            continue;
        s = ag_cloud_add_property(c, info->props[p].name, info->props[p].type, NULL, err);
        col_of[nprops++] = p;
    }
    if (s == AG_OK)
        s = ag_cloud_resize(c, info->points, err);
    load_ctx x = {.info = info, .c = c};
    if (s == AG_OK && (what & AG_POINTCLOUDS_POSITIONS))
        s = each_chunk(db, info, AG_POINTCLOUDS_COL_POSITIONS, info->points, got_positions, &x,
                       err);
    if (s == AG_OK && c->normals)
        s = each_chunk(db, info, AG_POINTCLOUDS_COL_NORMALS, info->points, got_normals, &x, err);
    for (size_t p = 0; s == AG_OK && p < nprops; p++) {
        x.prop = p;
        s = each_chunk(db, info, AG_POINTCLOUDS_COL_PROPERTY + (int)col_of[p], info->points,
                       got_property, &x, err);
    }
    if (s != AG_OK) {
        ag_cloud_free(c);
        return s;
    }
    *out = c;
    return AG_OK;
}

static ag_status got_order(void *user, size_t k, const uint8_t *data, size_t len, ag_error *err)
{
    load_ctx *x = user;
    size_t chunk = x->info->chunk_points, start = k * chunk;
    size_t stored = chunk_len(x->info->points, chunk, k);
    size_t take = x->count - start < stored ? x->count - start : stored;
    if (len != 4 * stored)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "a stored chunk of the order has %zu bytes",
                            len);
    /* only the entries asked for: decode the prefix of the chunk */
    return ag_cloudblob_decode_indices(data, 4 * take, x->order + start, take, err);
}

ag_status ag_pointclouds_load_order(ag_db *db, const ag_pointcloud_info *info, size_t count,
                                    uint32_t *order, ag_error *err)
{
    if (count > info->points)
        count = info->points;
    load_ctx x = {.info = info, .order = order, .count = count};
    ag_status s = each_chunk(db, info, AG_POINTCLOUDS_COL_ORDER, count, got_order, &x, err);
    for (size_t i = 0; s == AG_OK && i < count; i++)
        if (order[i] >= info->points)
            s = ag_error_set(err, AG_ERR_INTERNAL, 0, "the stored order names point %u of %zu",
                             order[i], info->points);
    return s;
}

ag_status ag_pointclouds_put_normals(ag_db *db, int64_t model, const ag_cloud *c,
                                     ag_error *err)
{
    ag_pointcloud_info info;
    ag_status s = ag_pointclouds_info(db, model, &info, err);
    if (s == AG_OK && (info.points != c->n || !c->normals))
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "normals of another cloud");
    if (s == AG_OK)
        s = put_chunks(db, model, AG_POINTCLOUDS_COL_NORMALS, c, info.chunk_points, enc_normals, 0,
                       err);
    sqlite3_stmt *st;
    if (s == AG_OK &&
        (s = ag_db_prepared(db, &st, "UPDATE pointclouds SET normals = 1 WHERE model_id = ?",
                            err)) == AG_OK) {
        sqlite3_bind_int64(st, 1, model);
        s = ag_db_step_done(db, st, "storing normals", err);
    }
    return s;
}

/* --- segmentations ------------------------------------------------------------------------ */

void ag_pointcloud_segmentation_clear(ag_pointcloud_segmentation *s)
{
    if (!s)
        return;
    free(s->segment);
    free(s->label);
    free(s->piece);
    free(s->kind);
    free(s->summary_json);
    memset(s, 0, sizeof *s);
}

static ag_status set_current(ag_db *db, int64_t model, int64_t segmentation, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "UPDATE pointclouds SET segmentation = nullif(?, 0) "
                                 "WHERE model_id = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, segmentation);
    sqlite3_bind_int64(st, 2, model);
    if ((s = ag_db_step_done(db, st, "choosing a segmentation", err)) == AG_OK &&
        sqlite3_changes(ag_db_handle(db)) == 0)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld is not a point cloud",
                         (long long)model);
    return s;
}

ag_status ag_pointclouds_put_segmentation(ag_db *db, int64_t model, int64_t version,
                                          const ag_segment_cloud_result *r,
                                          const char *summary_json, int64_t *id_out,
                                          ag_error *err)
{
    ag_pointcloud_info info;
    ag_status s = ag_pointclouds_info(db, model, &info, err);
    if (s == AG_OK && info.points != r->n)
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "a segmentation of %zu points for a cloud of %zu",
                         r->n, info.points);
    if (s != AG_OK)
        return s;
    size_t most = r->nsegments;
    if (r->nlabels > most)
        most = r->nlabels;
    if (r->npieces > most)
        most = r->npieces;
    unsigned width = ag_cloudblob_id_width((int64_t)most);
    uint8_t *kinds = malloc(r->nsegments + 1); /* each id's kind (migration 0012) */
    if (!kinds)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory storing a segmentation");
    for (size_t k = 0; k < r->nsegments; k++)
        kinds[k] = (uint8_t)r->segments[k].kind;
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st,
                            "INSERT INTO pointcloud_segmentations (model_id, version, segments, "
                            "planes, pieces, labels, spacing, id_width, summary, kinds) "
                            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                            err)) != AG_OK) {
        free(kinds);
        return s;
    }
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, version);
    sqlite3_bind_int64(st, 3, (sqlite3_int64)r->nsegments);
    sqlite3_bind_int64(st, 4, (sqlite3_int64)r->nplanes);
    sqlite3_bind_int64(st, 5, (sqlite3_int64)r->npieces);
    sqlite3_bind_int64(st, 6, (sqlite3_int64)r->nlabels);
    sqlite3_bind_double(st, 7, r->spacing);
    sqlite3_bind_int(st, 8, (int)width);
    sqlite3_bind_text(st, 9, summary_json ? summary_json : "{}", -1, SQLITE_STATIC);
    sqlite3_bind_blob64(st, 10, kinds, r->nsegments, SQLITE_STATIC);
    s = ag_db_step_done(db, st, "storing a segmentation", err);
    free(kinds);
    if (s != AG_OK)
        return s;
    int64_t id = sqlite3_last_insert_rowid(ag_db_handle(db));
    size_t chunk = info.chunk_points;
    for (size_t k = 0; s == AG_OK && k < chunks_of(r->n, chunk); k++) {
        size_t start = k * chunk, m = chunk_len(r->n, chunk, k);
        const int32_t *cols[3] = {r->segment + start, r->label + start, r->piece + start};
        uint8_t *data = malloc(3 * m * width + 1);
        if (!data)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory storing a segmentation");
        for (int j = 0; s == AG_OK && j < 3; j++) {
            uint8_t *part = NULL;
            size_t len = 0;
            s = ag_cloudblob_encode_ids(cols[j], m, width, &part, &len, err);
            if (s == AG_OK)
                memcpy(data + (size_t)j * m * width, part, len);
            free(part);
        }
        if (s == AG_OK && (s = ag_db_prepared(db, &st,
                                              "INSERT INTO pointcloud_segmentation_chunks "
                                              "(segmentation_id, chunk, data) VALUES (?, ?, ?)",
                                              err)) == AG_OK) {
            sqlite3_bind_int64(st, 1, id);
            sqlite3_bind_int64(st, 2, (sqlite3_int64)k);
            sqlite3_bind_blob64(st, 3, data, 3 * m * width, SQLITE_STATIC);
            s = ag_db_step_done(db, st, "storing a segmentation", err);
        }
        free(data);
    }
    if (s == AG_OK)
        s = set_current(db, model, id, err);
    if (s == AG_OK && id_out)
        *id_out = id;
    return s;
}

typedef struct {
    ag_pointcloud_segmentation *seg;
    size_t chunk;
    unsigned width;
} seg_ctx;

static ag_status got_ids(void *user, size_t k, const uint8_t *data, size_t len, ag_error *err)
{
    seg_ctx *x = user;
    size_t start = k * x->chunk, m = chunk_len(x->seg->n, x->chunk, k);
    size_t part = m * x->width;
    if (len != 3 * part)
        return ag_error_set(err, AG_ERR_INTERNAL, 0,
                            "a stored chunk of a segmentation has %zu bytes, not %zu", len,
                            3 * part);
    int32_t *cols[3] = {x->seg->segment + start, x->seg->label + start, x->seg->piece + start};
    ag_status s = AG_OK;
    for (int j = 0; s == AG_OK && j < 3; j++)
        s = ag_cloudblob_decode_ids(data + (size_t)j * part, part, x->width, cols[j], m, err);
    return s;
}

ag_status ag_pointclouds_get_segmentation(ag_db *db, const ag_pointcloud_info *info, int ids,
                                          ag_pointcloud_segmentation *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    if (!info->segmentation)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld is not segmented",
                            (long long)info->model);
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT version, segments, planes, pieces, labels, spacing, "
                                 "id_width, summary, kinds FROM pointcloud_segmentations "
                                 "WHERE id = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, info->segmentation);
    int rc = sqlite3_step(st);
    unsigned width = 0;
    if (rc == SQLITE_ROW) {
        int nomem = 0;
        out->id = info->segmentation;
        out->version = sqlite3_column_int64(st, 0);
        out->n = info->points;
        out->nsegments = (size_t)sqlite3_column_int64(st, 1);
        out->nplanes = (size_t)sqlite3_column_int64(st, 2);
        out->npieces = (size_t)sqlite3_column_int64(st, 3);
        out->nlabels = (size_t)sqlite3_column_int64(st, 4);
        out->spacing = sqlite3_column_double(st, 5);
        width = (unsigned)sqlite3_column_int(st, 6);
        out->summary_json = ag_db_column_dup(st, 7, NULL, &nomem);
        if (sqlite3_column_type(st, 8) != SQLITE_NULL) { /* NULL: stored before 0012 */
            const void *k = sqlite3_column_blob(st, 8);
            size_t len = (size_t)sqlite3_column_bytes(st, 8);
            if (len != out->nsegments)
                s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                                 "segmentation %lld has %zu kinds for %zu segments",
                                 (long long)info->segmentation, len, out->nsegments);
            else if (!(out->kind = malloc(len + 1)))
                nomem = 1;
            else if (len)
                memcpy(out->kind, k, len);
        }
        if (nomem)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");

    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld is not segmented",
                         (long long)info->model);
    } else {
        s = ag_db_fail(db, err, "reading a segmentation");
    }
    sqlite3_reset(st);
    if (s == AG_OK && ids) {
        size_t n = info->points ? info->points : 1;
        out->segment = malloc(n * sizeof *out->segment);
        out->label = malloc(n * sizeof *out->label);
        out->piece = malloc(n * sizeof *out->piece);
        if (!out->segment || !out->label || !out->piece)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a segmentation");
    }
    if (s == AG_OK && ids && info->points) {
        seg_ctx x = {out, info->chunk_points, width};
        size_t want = chunks_of(info->points, info->chunk_points), next = 0;
        if ((s = ag_db_prepared(db, &st,
                                "SELECT chunk, data FROM pointcloud_segmentation_chunks "
                                "WHERE segmentation_id = ? ORDER BY chunk",
                                err)) == AG_OK) {
            sqlite3_bind_int64(st, 1, info->segmentation);
            while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
                size_t k = (size_t)sqlite3_column_int64(st, 0);
                const uint8_t *data = sqlite3_column_blob(st, 1);
                size_t len = (size_t)sqlite3_column_bytes(st, 1);
                s = k == next && k < want
                        ? got_ids(&x, k, data, len, err)
                        : ag_error_set(err, AG_ERR_INTERNAL, 0,
                                       "chunk %zu of segmentation %lld is missing", next,
                                       (long long)info->segmentation);
                next++;
            }
            if (s == AG_OK && rc != SQLITE_DONE)
                s = ag_db_fail(db, err, "reading a segmentation");
            if (s == AG_OK && next != want)
                s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                                 "chunk %zu of segmentation %lld is missing", next,
                                 (long long)info->segmentation);
            sqlite3_reset(st);
        }
    }
    if (s != AG_OK)
        ag_pointcloud_segmentation_clear(out);
    return s;
}

ag_status ag_pointclouds_clear_segmentation(ag_db *db, int64_t model, ag_error *err)
{
    return set_current(db, model, 0, err);
}

ag_status ag_pointclouds_states_keep(ag_db *db, int64_t model, int64_t version, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "INSERT OR IGNORE INTO pointcloud_states (model_id, version, "
                                 "segmentation) SELECT model_id, ?, segmentation FROM pointclouds "
                                 "WHERE model_id = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, version);
    sqlite3_bind_int64(st, 2, model);
    return ag_db_step_done(db, st, "keeping a segmentation", err);
}

ag_status ag_pointclouds_states_restore(ag_db *db, int64_t model, int64_t kept_version,
                                        ag_error *err)
{
    /* a state kept before point clouds had states (none are) or of a mesh: nothing to do */
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "UPDATE pointclouds SET segmentation = (SELECT segmentation "
                                 "FROM pointcloud_states WHERE model_id = ?1 AND version = ?2) "
                                 "WHERE model_id = ?1 AND EXISTS (SELECT 1 FROM pointcloud_states "
                                 "WHERE model_id = ?1 AND version = ?2)",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, kept_version);
    return ag_db_step_done(db, st, "restoring a segmentation", err);
}

ag_status ag_pointclouds_read_begin(ag_db *db, ag_error *err)
{
    char *msg = NULL;
    if (sqlite3_exec(ag_db_handle(db), "BEGIN", NULL, NULL, &msg) != SQLITE_OK) {
        ag_error_set(err, AG_ERR_DB, 0, "cannot begin a read: %s", msg ? msg : "?");
        sqlite3_free(msg);
        return AG_ERR_DB;
    }
    return AG_OK;
}

void ag_pointclouds_read_end(ag_db *db)
{
    sqlite3_exec(ag_db_handle(db), "COMMIT", NULL, NULL, NULL);
}

ag_status ag_pointclouds_release_terminals(ag_db *db, int64_t model, size_t *released,
                                           ag_error *err)
{
    if (released)
        *released = 0;
    sqlite3_stmt *st;
    /* a path is named as a quoted string ("terminals/<hex>.ply") in a grammar text */
    ag_status s = ag_db_prepared(
        db, &st,
        "DELETE FROM terminals WHERE model_id = ?1"
        " AND NOT EXISTS (SELECT 1 FROM grammars g WHERE g.model_id = ?1"
        "                 AND instr(g.text, '\"' || terminals.path || '\"') > 0)"
        " AND NOT EXISTS (SELECT 1 FROM model_states k WHERE k.model_id = ?1"
        "                 AND k.grammar IS NOT NULL"
        "                 AND instr(k.grammar, '\"' || terminals.path || '\"') > 0)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    s = ag_db_step_done(db, st, "releasing terminals no version names", err);
    if (s == AG_OK && released)
        *released = (size_t)sqlite3_changes(ag_db_handle(db));
    return s;
}
