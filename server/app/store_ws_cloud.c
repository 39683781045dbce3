/* The store workspace's point cloud operations (app/store_ws.h): a new cloud model, the
 * cloud and segmentation a use case works on, and a segmentation saved as a sequenced op
 * with the states undo goes back to. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/meshblob.h"
#include "../store/jobs.h"
#include "../store/members.h"
#include "../store/models.h"
#include "../store/pointclouds.h"
#include "../store/states.h"
#include "store_ws.h"

#define SOURCE_MAX ((size_t)256 << 20) /* an uploaded file larger than this is not kept */

static int is_cloud(const ag_model_row *row)
{
    return strcmp(row->kind, "pointcloud") == 0;
}

ag_status ag__store_ws_add_cloud(ag_workspace *ws, const char *name, const ag_cloud_new *c,
                                 int64_t *model_out, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    ag_db *db = w->o.env.db;
    /* models keep a mesh: a cloud's is empty until a surface is made of it */
    ag_mesh *empty = ag_mesh_create();
    uint8_t *mesh = NULL;
    size_t mesh_len = 0;
    json_t *stats = ag_cloud_state_stats(
        c->cloud, ag_cloudblob_positions_name(ag_cloudblob_positions_choose(c->cloud)));
    char *stats_text = stats ? json_dumps(stats, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(stats);
    ag_status s = empty && stats_text ? ag_meshblob_encode(empty, &mesh, &mesh_len) : AG_ERR_NOMEM;
    ag_mesh_free(empty);
    if (s != AG_OK) {
        free(stats_text);
        return ag_error_set(err, s, 0, "out of memory describing the point cloud");
    }
    int keep_source = c->source && c->source_len <= SOURCE_MAX;
    ag_model_new m = {.name = name,
                      .kind = "pointcloud",
                      .stats_json = stats_text,
                      .source = keep_source ? c->source : NULL,
                      .source_len = keep_source ? c->source_len : 0,
                      .source_format = c->source_format,
                      .source_media_type = "application/octet-stream",
                      .mesh = mesh,
                      .mesh_len = mesh_len};
    int64_t model = 0;
    if ((s = ag_db_begin(db, err)) == AG_OK) {
        s = ag_models_insert(db, &m, &model, err);
        if (s == AG_OK && w->o.job_id)
            s = ag_members_own_from_job(db, model, w->o.job_id, err);
        if (s == AG_OK)
            s = ag_pointclouds_put(db, model, c->cloud, c->lod, 0, err);
        if (s == AG_OK && w->o.job && ag_jobctx_cancelled(w->o.job))
            s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        if (s == AG_OK && w->o.job_id) {
            char result[256];
            snprintf(result, sizeof result,
                     "{\"model\":%lld,\"href\":\"/api/v1/models/%lld\",\"points\":"
                     "\"/api/v1/models/%lld/points.glb\"}",
                     (long long)model, (long long)model, (long long)model);
            s = ag_jobs_finish(db, w->o.job_id, "succeeded", result, NULL, model, err);
        }
        s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    }
    if (s == AG_OK)
        *model_out = model;
    free(mesh);
    free(stats_text);
    return s;
}

static ag_status read_cloud(ag_store_ws *w, int with_properties, int need_segmentation,
                            ag_cloud_state *st, ag_error *err)
{
    ag_db *db = w->o.env.db;
    ag_model_row row;
    ag_status s = ag_models_get(db, w->o.model, &row, err);
    if (s != AG_OK)
        return s;
    int64_t version = row.version;
    int cloud = is_cloud(&row);
    char kind[sizeof row.kind];
    memcpy(kind, row.kind, sizeof kind);
    ag_models_row_clear(&row);
    if (!cloud)
        return ag_error_set(err, AG_ERR_CONFLICT, 0,
                            "model %lld is a %s, not a point cloud: segmentation works on "
                            "point clouds",
                            (long long)w->o.model, kind);
    if (version != w->o.base)
        return ag_error_set(err, AG_ERR_STALE, (long)version,
                            "model %lld is at version %lld, not %lld", (long long)w->o.model,
                            (long long)version, (long long)w->o.base);
    ag_pointcloud_info info;
    if ((s = ag_pointclouds_info(db, w->o.model, &info, err)) != AG_OK)
        return s;
    if (need_segmentation && !info.segmentation)
        return ag_error_set(err, AG_ERR_CONFLICT, 0,
                            "model %lld is not segmented: segment it first (POST "
                            "/api/v1/models/%lld/segment)",
                            (long long)w->o.model, (long long)w->o.model);
    unsigned what = AG_POINTCLOUDS_POSITIONS | AG_POINTCLOUDS_NORMALS |
                    (with_properties ? AG_POINTCLOUDS_PROPERTIES : 0);
    if ((s = ag_pointclouds_load(db, &info, what, NULL, &st->cloud, err)) != AG_OK)
        return s;
    st->had_normals = info.normals;
    if (!info.segmentation)
        return AG_OK;
    ag_pointcloud_segmentation seg;
    if ((s = ag_pointclouds_get_segmentation(db, &info, 1, &seg, err)) != AG_OK)
        return s;
    ag_segment_cloud_ids ids = {.segment = seg.segment,
                                .label = seg.label,
                                .piece = seg.piece,
                                .nsegments = seg.nsegments,
                                .nplanes = seg.nplanes,
                                .kind = seg.kind,
                                .nlabels = seg.nlabels,
                                .npieces = seg.npieces,
                                .spacing = seg.spacing};
    s = ag_segment_cloud_restore(st->cloud, &ids, &st->seg, err);
    if (s == AG_ERR_INVALID) /* the store's own data does not fit: not the caller's fault */
        s = ag_error_set(err, AG_ERR_INTERNAL, err ? err->element : 0,
                         "the stored segmentation of model %lld is not readable: %s",
                         (long long)w->o.model, err ? err->text : "");
    ag_pointcloud_segmentation_clear(&seg);
    return s;
}

ag_status ag__store_ws_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                   ag_cloud_state *st, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    /* the version, the points and the segmentation of one snapshot */
    ag_status s = ag_pointclouds_read_begin(w->o.env.db, err);
    if (s != AG_OK)
        return s;
    s = read_cloud(w, with_properties, need_segmentation, st, err);
    ag_pointclouds_read_end(w->o.env.db);
    if (s != AG_OK)
        ag_cloud_state_clear(st);
    return s;
}

/* The model's stats with the segmentation's figures. */
static ag_status update_stats(ag_db *db, int64_t model, const json_t *figures, int normals,
                              ag_error *err)
{
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s != AG_OK)
        return s;
    json_t *stats = json_loads(row.stats_json ? row.stats_json : "{}", 0, NULL);
    ag_models_row_clear(&row);
    if (!json_is_object(stats)) {
        json_decref(stats);
        stats = json_object();
    }
    ag_cloud_state_stats_segmented(stats, figures);
    if (normals)
        json_object_set_new(stats, "normals", json_true());
    char *text = stats ? json_dumps(stats, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(stats);
    s = text ? ag_models_set_stats(db, model, text, err)
             : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    free(text);
    return s;
}

/* The op logged: a client's op as sent with the report, or the job's "segment" op. */
static json_t *logged_op(const ag_store_ws *w, const ag_segment_outcome *o)
{
    json_t *body = w->o.op ? json_deep_copy(w->o.op) : json_pack("{s:s}", "kind", o->kind);
    if (body && o->report)
        json_object_set(body, "report", (json_t *)o->report);
    return body;
}

ag_status ag__store_ws_save_segmentation(ag_workspace *ws, const ag_cloud_state *st,
                                         const ag_segment_outcome *o, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    if (!st->seg)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no segmentation to save");
    json_t *figures = ag_cloud_state_segmentation(st->seg, strcmp(o->kind, "segment") == 0);
    json_t *body = logged_op(w, o);
    char *summary = figures ? json_dumps(figures, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    ag_status s = figures && body && summary ? AG_OK
                                             : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_seq_txn t;
    int dup = 0;
    if (s == AG_OK)
        s = ag__store_ws_begin(w, "segmented", 1, &t, &dup, err);
    if (s == AG_OK && !dup) {
        int add_normals = !st->had_normals && st->cloud->normals;
        s = ag_states_keep(t.db, w->o.model, t.version - 1, err);
        if (s == AG_OK && add_normals)
            s = ag_pointclouds_put_normals(t.db, w->o.model, st->cloud, err);
        if (s == AG_OK)
            s = ag_pointclouds_put_segmentation(t.db, w->o.model, t.version, st->seg, summary,
                                                NULL, err);
        if (s == AG_OK)
            s = update_stats(t.db, w->o.model, figures, add_normals, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, w->o.model, t.version, err);
        s = ag__store_ws_commit(w, &t, s, AG__STORE_WS_LINKS_POINTS, body, err);
    }
    json_decref(figures);
    json_decref(body);
    free(summary);
    return s;
}
