#include "app_parts.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/parts/select.h"
#include "../store/parts.h"
#include "compose_ops.h"
#include "edit_session.h"
#include "part_library.h"
#include "part_media.h"
#include "store_env.h"
#include "store_ws.h"
#include "usecase_save_part.h"

/* --- views -------------------------------------------------------------------------------- */

static json_t *tags_json(const ag_part_row *row)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < row->ntags; i++)
        json_array_append_new(a, json_string(row->tags[i]));
    return a;
}

static json_t *part_view(const ag_part_row *row)
{
    char href[64], thumb[128], mesh[96], bundle[96];
    long long id = (long long)row->id, v = (long long)row->version;
    snprintf(href, sizeof href, "/api/v1/parts/%lld", id);
    snprintf(thumb, sizeof thumb, "/api/v1/parts/%lld/thumbnail.png?version=%lld", id, v);
    snprintf(mesh, sizeof mesh, "/api/v1/parts/%lld/mesh.glb?version=%lld", id, v);
    snprintf(bundle, sizeof bundle, "/api/v1/parts/%lld/bundle", id);
    return json_pack("{s:I,s:s,s:s,s:o,s:I,s:s,s:s,s:s,s:s,s:s,s:s}", "id", (json_int_t)row->id,
                     "name", row->name, "description", row->description, "tags", tags_json(row),
                     "version", (json_int_t)row->version, "created_at", row->created_at,
                     "updated_at", row->updated_at, "href", href, "thumbnail", thumb, "mesh", mesh,
                     "bundle", bundle);
}

static json_t *version_view(const ag_part_version_row *v)
{
    json_t *stats = json_loads(v->stats_json ? v->stats_json : "{}", 0, NULL);
    json_t *source = v->source_name || v->source_model
                         ? json_pack("{s:o,s:o,s:I,s:I}", "model",
                                     v->source_model ? json_integer(v->source_model) : json_null(),
                                     "name", v->source_name ? json_string(v->source_name)
                                                            : json_null(),
                                     "version", (json_int_t)v->source_version, "node",
                                     (json_int_t)v->source_node)
                         : json_null();
    char thumb[128], mesh[96], bundle[112];
    long long id = (long long)v->part, ver = (long long)v->version;
    snprintf(thumb, sizeof thumb, "/api/v1/parts/%lld/thumbnail.png?version=%lld", id, ver);
    snprintf(mesh, sizeof mesh, "/api/v1/parts/%lld/mesh.glb?version=%lld", id, ver);
    snprintf(bundle, sizeof bundle, "/api/v1/parts/%lld/bundle?version=%lld", id, ver);
    return json_pack("{s:I,s:s,s:o,s:o,s:s,s:s,s:s}", "version", (json_int_t)v->version,
                     "created_at", v->created_at, "source", source ? source : json_null(),
                     "stats", stats ? stats : json_object(), "thumbnail", thumb, "mesh", mesh,
                     "bundle", bundle);
}

static ag_status full_view(ag_db *db, int64_t id, json_t **view, int64_t *version, ag_error *err)
{
    *view = NULL;
    ag_part_row row;
    ag_status s = ag_parts_get(db, id, &row, err);
    if (s != AG_OK)
        return s;
    ag_part_version_row *vs = NULL;
    size_t nv = 0;
    json_t *v = part_view(&row);
    json_t *list = json_array();
    if ((s = ag_parts_versions(db, id, &vs, &nv, err)) == AG_OK)
        for (size_t i = 0; i < nv; i++) {
            json_array_append_new(list, version_view(&vs[i]));
            ag_parts_version_row_clear(&vs[i]);
        }
    free(vs);
    if (s == AG_OK && (!v || !list || json_object_set(v, "versions", list)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    json_decref(list);
    if (version)
        *version = row.version;
    ag_parts_row_clear(&row);
    if (s != AG_OK) {
        json_decref(v);
        return s;
    }
    *view = v;
    return AG_OK;
}

/* --- saving ------------------------------------------------------------------------------- */

ag_status ag_app_parts_save(ag_app *app, const ag_app_part_save *rq, json_t **view,
                            int64_t *id, int64_t *version, ag_error *err)
{
    *view = NULL;
    *id = *version = 0;
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    if (s != AG_OK)
        return s;
    /* a new version keeps what it does not name */
    ag_part_row old = {0};
    if (rq->update && (s = ag_parts_get(env.db, rq->update, &old, err)) != AG_OK)
        return s;
    ag_part_meta meta = {.name = rq->name ? rq->name : old.name,
                         .description = rq->description ? rq->description : old.description,
                         .tags = rq->tags ? rq->tags : (const char *const *)old.tags,
                         .ntags = rq->tags ? rq->ntags : old.ntags};
    if (meta.description && !meta.description[0])
        meta.description = NULL;
    if (!meta.name)
        s = ag_error_set(err, AG_ERR_INVALID, 0, "name: a part needs a name");
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env,
                                                .model = rq->model,
                                                .base = rq->version,
                                                .part_update = rq->update,
                                                .part_base = rq->base});
    ag_usecase_save_part_result r;
    if (s == AG_OK)
        s = ag_usecase_save_part_run(
            &w.ws,
            &(ag_usecase_save_part_params){.nodes = rq->nodes, .nnodes = rq->nnodes,
                                           .meta = &meta},
            &r, err);
    ag_store_ws_end(&w, s);
    ag_parts_row_clear(&old);
    if (s != AG_OK)
        return s;
    *id = w.part_id;
    *version = w.part_version;
    return full_view(env.db, w.part_id, view, NULL, err);
}

/* --- reading ------------------------------------------------------------------------------ */

#define DB_OR_RETURN(db, app, err)                                                              \
    ag_db *db = ag_app_db(app, err);                                                           \
    if (!db)                                                                                   \
        return err ? err->code : AG_ERR_DB

ag_status ag_app_parts_search(ag_app *app, const char *q, const char *tag, size_t offset,
                              size_t limit, json_t **items, int *more, ag_error *err)
{
    *items = NULL;
    *more = 0;
    DB_OR_RETURN(db, app, err);
    if (limit < 1 || limit > AG_APP_PARTS_PAGE_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "page_size: 1 to %d", AG_APP_PARTS_PAGE_MAX);
    ag_part_row *rows;
    size_t n;
    ag_parts_query pq = {q, tag, offset, limit};
    ag_status s = ag_parts_search(db, &pq, &rows, &n, more, err);
    if (s != AG_OK)
        return s;
    json_t *list = json_array();
    for (size_t i = 0; i < n; i++) {
        if (list)
            json_array_append_new(list, part_view(&rows[i]));
        ag_parts_row_clear(&rows[i]);
    }
    free(rows);
    if (!list)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    *items = list;
    return AG_OK;
}

ag_status ag_app_parts_get(ag_app *app, int64_t id, json_t **view, int64_t *version,
                           ag_error *err)
{
    DB_OR_RETURN(db, app, err);
    return full_view(db, id, view, version, err);
}

ag_status ag_app_parts_version(ag_app *app, int64_t id, int64_t *version, ag_error *err)
{
    DB_OR_RETURN(db, app, err);
    ag_part_row row;
    ag_status s = ag_parts_get(db, id, &row, err);
    if (s == AG_OK)
        *version = row.version;
    ag_parts_row_clear(&row);
    return s;
}

/* The version a request names (0: the newest) and its strong validator. */
static ag_status version_etag(ag_db *db, int64_t id, int64_t *version, const char *what,
                              char *etag, size_t cap, ag_error *err)
{
    ag_part_version_row row;
    ag_status s = ag_parts_get_version(db, id, *version, 0, &row, err);
    if (s != AG_OK)
        return s;
    *version = row.version;
    snprintf(etag, cap, "\"part-%lld-%lld-%s\"", (long long)id, (long long)row.version, what);
    ag_parts_version_row_clear(&row);
    return AG_OK;
}

ag_status ag_app_parts_thumbnail(ag_app *app, int64_t id, int64_t version,
                                 int (*fresh)(void *user, const char *etag), void *user,
                                 ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    DB_OR_RETURN(db, app, err);
    ag_status s = version_etag(db, id, &version, "png", out->etag, sizeof out->etag, err);
    if (s != AG_OK || (fresh && fresh(user, out->etag)))
        return s;
    void *png = NULL;
    s = ag_parts_thumbnail(db, id, version, &png, &out->len, err);
    out->data = png;
    return s;
}

ag_status ag_app_parts_glb(ag_app *app, int64_t id, int64_t version,
                           int (*fresh)(void *user, const char *etag), void *user,
                           ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    DB_OR_RETURN(db, app, err);
    ag_status s = version_etag(db, id, &version, "glb", out->etag, sizeof out->etag, err);
    if (s != AG_OK || (fresh && fresh(user, out->etag)))
        return s;
    ag_part *p = NULL;
    if ((s = ag_part_library_load(db, id, version, &p, err)) == AG_OK)
        s = ag_part_media_glb(p, &out->data, &out->len, err);
    ag_part_free(p);
    return s;
}

ag_status ag_app_parts_bundle(ag_app *app, const int64_t *ids, size_t n, int64_t version,
                              ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    DB_OR_RETURN(db, app, err);
    char *text = NULL;
    ag_status s = ag_part_library_export(db, ids, n, version, &text, &out->len, err);
    out->data = (uint8_t *)text;
    return s;
}

ag_status ag_app_parts_import(ag_app *app, const char *data, size_t len, json_t **items,
                              ag_error *err)
{
    *items = NULL;
    DB_OR_RETURN(db, app, err);
    int64_t *ids = NULL;
    size_t n = 0;
    ag_status s = ag_part_library_import(db, data, len, &ids, &n, err);
    if (s != AG_OK) {
        /* every problem of the bundle is the bundle's: unprocessable, element named */
        if (s != AG_ERR_NOMEM && s != AG_ERR_DB && s != AG_ERR_BUSY && s != AG_ERR_INTERNAL) {
            s = AG_ERR_PARSE;
            if (err)
                err->code = s;
        }
        return s;
    }
    json_t *list = json_array();
    for (size_t i = 0; s == AG_OK && i < n; i++) {
        json_t *v = NULL;
        if ((s = full_view(db, ids[i], &v, NULL, err)) == AG_OK)
            json_array_append_new(list, v);
    }
    free(ids);
    if (s != AG_OK) {
        json_decref(list);
        return s;
    }
    *items = list;
    return AG_OK;
}

ag_status ag_app_parts_delete(ag_app *app, int64_t id, int64_t version, ag_error *err)
{
    DB_OR_RETURN(db, app, err);
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    s = ag_parts_delete(db, id, version, err);
    return s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
}

/* --- selecting and composing ---------------------------------------------------------------- */

static json_t *ids_json(const int32_t *ids, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        json_array_append_new(a, json_integer(ids[i]));
    return a;
}

ag_status ag_app_parts_selection(ag_app *app, int64_t model, int64_t base, const int32_t *nodes,
                                 size_t n, json_t **out, ag_error *err)
{
    *out = NULL;
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    ag_edit_state *st = NULL;
    if (s == AG_OK)
        s = ag_edit_session_acquire(env.sessions, env.db, model, &st, err);
    if (s != AG_OK)
        return s;
    int32_t tree = -1, *rule = NULL;
    size_t nrule = 0;
    if (base && base != st->version)
        s = ag_error_set(err, AG_ERR_STALE, (long)st->version,
                         "model %lld is at version %lld, not %lld", (long long)model,
                         (long long)st->version, (long long)base);
    const ag_splittree *t = st->em->proc->tree;
    if (s == AG_OK)
        s = ag_select_common_tree(t, nodes, n, &tree, err);
    if (s == AG_OK)
        s = ag_select_common_rule(t, nodes, n, &rule, &nrule, err);
    if (s == AG_OK &&
        !(*out = json_pack("{s:I,s:I,s:o,s:I,s:o}", "model", (json_int_t)model, "version",
                           (json_int_t)st->version, "nodes", ids_json(nodes, n), "tree",
                           (json_int_t)tree, "rule", ids_json(rule, nrule))))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    free(rule);
    ag_edit_session_release(env.sessions, st);
    return s;
}

ag_status ag_app_parts_compose_preview(ag_app *app, int64_t model, int64_t base,
                                       const json_t *op, ag_app_bytes *glb, json_t **report,
                                       ag_error *err)
{
    memset(glb, 0, sizeof *glb);
    *report = NULL;
    ag_store_env env;
    ag_status s = ag__app_env(app, &env, err);
    ag_mesh *m = NULL;
    if (s == AG_OK)
        s = ag_compose_ops_preview(&env, model, base, op, &m, report, err);
    if (s != AG_OK)
        return s;
    s = ag_part_media_mesh_glb(m, &glb->data, &glb->len, err);
    ag_mesh_free(m);
    if (s != AG_OK) {
        json_decref(*report);
        *report = NULL;
    }
    return s;
}
