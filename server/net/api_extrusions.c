/* Extrusions over REST: POST /api/v1/extrusions (an upload becomes an extrude job) and
 * GET /api/v1/models/{id}/plan (the stored building descriptions). Plan and profile edits
 * are ops (POST …/ops, websocket), see app/plan_edit.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../core/extrude/style.h"
#include "../store/extrusions.h"
#include "../store/models.h"
#include "routes.h"
#include "upload.h"

/* The query parameters as job params (without the upload), or a problem. */
static ag_status job_params(ag_request *r, json_t **out, ag_error *err)
{
    *out = NULL;
    char name[1024];
    ag_upload_name(r, "extrusion", name, sizeof name);
    ag_status s = ag_models_check_name(name, err);
    if (s != AG_OK)
        return s;
    const char *format = ag_request_query(r, "format");
    const char *ctype = ag_request_header(r, MHD_HTTP_HEADER_CONTENT_TYPE);
    if (!format && ctype && strncasecmp(ctype, "application/geo+json", 20) == 0)
        format = "geojson";
    if (format && strcmp(format, "plan") != 0 && strcmp(format, "buildings") != 0 &&
        strcmp(format, "geojson") != 0)
        return ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                            "unknown format \"%s\"; extrusions read plan, buildings and geojson",
                            format);
    const char *style = ag_request_query(r, "style");
    ag_style probe;
    if (style && ag_style_builtin(style, &probe, NULL) != AG_OK)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "unknown style \"%s\"; the styles are flat, hip, gable, mansard and "
                            "overhang", style);
    json_t *seed = json_null();
    const char *sv = ag_request_query(r, "seed");
    if (sv) {
        char *end;
        long long n = strtoll(sv, &end, 10);
        if (!*sv || *end || n < 0)
            return ag_error_set(err, AG_ERR_INVALID, 0, "seed must be a whole number >= 0");
        seed = json_integer(n);
    }
    json_t *lonlat = json_null();
    const char *lv = ag_request_query(r, "lonlat");
    if (lv) {
        if (strcmp(lv, "true") == 0 || strcmp(lv, "1") == 0)
            lonlat = json_true();
        else if (strcmp(lv, "false") == 0 || strcmp(lv, "0") == 0)
            lonlat = json_false();
        else {
            json_decref(seed);
            return ag_error_set(err, AG_ERR_INVALID, 0, "lonlat must be true or false");
        }
    }
    *out = json_pack("{s:s, s:s?, s:s, s:s?, s:o, s:o}", "name", name, "format", format,
                     "style", style ? style : "hip", "height_property",
                     ag_request_query(r, "height_property"), "seed", seed, "lonlat", lonlat);
    return *out ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

enum MHD_Result ag_api_extrusions_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    json_t *params;
    ag_status s = job_params(r, &params, &err);
    if (s == AG_OK && ag_upload_bytes(r->upload) == 0) {
        json_decref(params);
        s = ag_error_set(&err, AG_ERR_INVALID, 0,
                         "the request has no body: send a building description or GeoJSON "
                         "footprints (or a multipart \"file\" part)");
    }
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    const char *path = ag_upload_take_path(r->upload);
    json_object_set_new(params, "upload", json_string(path));
    return ag_reply_new_job(r, "extrude", params, path);
}

typedef struct {
    json_t *list;
    int64_t component; /* the next building with geometry gets this component */
    ag_error *err;
} plan_view;

static ag_status add_view(void *user, ag_extrusion_building *b)
{
    plan_view *v = user;
    json_t *plan = json_loads(b->plan_json, JSON_DECODE_ANY, NULL);
    int has_mesh = strcmp(b->status, "failed") != 0;
    json_t *o = json_pack("{s:s, s:o, s:s, s:I, s:o}", "id", b->footprint, "plan",
                          plan ? plan : json_null(), "status", b->status, "triangles",
                          (json_int_t)b->triangles, "component",
                          has_mesh ? json_integer(v->component) : json_null());
    if (!o)
        return ag_error_set(v->err, AG_ERR_NOMEM, 0, "out of memory");
    if (b->reason)
        json_object_set_new(o, "reason", json_string(b->reason));
    v->component += has_mesh;
    json_array_append_new(v->list, o);
    return AG_OK;
}

/* The descriptions as stored: one plan as it is, a batch as {"buildings": [...]} with the
 * batch's metadata (format, style, origin, lonlat). */
static ag_status plan_json(ag_db *db, int64_t model, json_t **out, ag_error *err)
{
    *out = NULL;
    ag_extrusion_row row;
    ag_status s = ag_extrusions_get(db, model, &row, err);
    if (s != AG_OK)
        return s;
    int batch = row.batch;
    json_t *doc = json_loads(row.meta_json, 0, NULL);
    ag_extrusions_row_clear(&row);
    if (!json_is_object(doc)) {
        json_decref(doc);
        doc = json_object();
    }
    if (!batch) {
        json_decref(doc);
        ag_extrusion_building b;
        if ((s = ag_extrusions_get_building(db, model, 0, AG_EXTRUSIONS_PLAN, &b, err)) != AG_OK)
            return s;
        doc = json_loads(b.plan_json, 0, NULL);
        ag_extrusions_building_clear(&b);
        if (!doc)
            return ag_error_set(err, AG_ERR_INTERNAL, 0, "the stored plan is not JSON");
        *out = doc;
        return AG_OK;
    }
    plan_view v = {json_array(), 0, err};
    s = ag_extrusions_each_building(db, model, AG_EXTRUSIONS_PLAN, add_view, &v, err);
    if (s != AG_OK) {
        json_decref(v.list);
        json_decref(doc);
        return s;
    }
    json_object_set_new(doc, "buildings", v.list);
    *out = doc;
    return AG_OK;
}

enum MHD_Result ag_api_model_plan(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    /* The version and the plans are read apart: read again if an edit came in between. */
    for (int attempt = 0; attempt < 5; attempt++) {
        ag_model_row m;
        ag_status s = ag_models_get(db, r->ids[0], &m, &err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &err);
        int64_t version = m.version;
        ag_models_row_clear(&m);
        json_t *doc;
        if ((s = plan_json(db, r->ids[0], &doc, &err)) != AG_OK)
            return ag_reply_problem(r, s, &err);
        if ((s = ag_models_get(db, r->ids[0], &m, &err)) != AG_OK) {
            json_decref(doc);
            return ag_reply_problem(r, s, &err);
        }
        int same = m.version == version;
        ag_models_row_clear(&m);
        if (!same) {
            json_decref(doc);
            continue;
        }
        char etag[32];
        snprintf(etag, sizeof etag, "\"%lld\"", (long long)version);
        return ag_reply_json(r, 200, doc, etag);
    }
    ag_error_set(&err, AG_ERR_BUSY, 0, "the model kept changing while its plan was read");
    return ag_reply_problem(r, AG_ERR_BUSY, &err);
}
