/* /api/v1/models: list, upload (as an import job), read, rename, delete, geometry, op log. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/modelops.h"
#include "../app/views.h"
#include "../io/glb.h"
#include "../io/import.h"
#include "../io/meshblob.h"
#include "../store/models.h"
#include "../store/ops.h"
#include "routes.h"
#include "upload.h"

#define AG_PAGE_DEFAULT 50
#define AG_PAGE_MAX 200
#define AG_OPS_LIST_MAX 10000

static void version_etag(char *buf, size_t len, int64_t version)
{
    snprintf(buf, len, "\"%lld\"", (long long)version);
}

/* Parses a decimal query parameter within [lo, hi]; absent gives def. */
static ag_status query_int(ag_request *r, const char *name, long long lo, long long hi,
                           long long def, long long *out, ag_error *err)
{
    const char *v = ag_request_query(r, name);
    if (!v) {
        *out = def;
        return AG_OK;
    }
    char *end;
    long long n = strtoll(v, &end, 10);
    if (!*v || *end || n < lo || n > hi)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s must be a whole number from %lld to %lld",
                            name, lo, hi);
    *out = n;
    return AG_OK;
}

enum MHD_Result ag_api_models_list(ag_request *r)
{
    ag_error err;
    long long size;
    ag_status s = query_int(r, "page_size", 1, AG_PAGE_MAX, AG_PAGE_DEFAULT, &size, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* Page tokens are "m" + the last id seen: opaque to clients, cheap to check. */
    long long after = 0;
    const char *token = ag_request_query(r, "page_token");
    if (token) {
        char *end;
        after = token[0] == 'm' ? strtoll(token + 1, &end, 10) : -1;
        if (token[0] != 'm' || !token[1] || *end || after < 0)
            return ag_reply_problem(r, AG_ERR_INVALID,
                                    (ag_error_set(&err, AG_ERR_INVALID, 0,
                                                  "page_token is not one this server gave out"),
                                     &err));
    }
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_model_row *rows;
    size_t n;
    /* One extra row tells whether another page follows. */
    if ((s = ag_models_list(db, after, (size_t)size + 1, &rows, &n, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *items = json_array();
    size_t shown = n > (size_t)size ? (size_t)size : n;
    for (size_t i = 0; i < shown; i++) {
        json_t *m = ag_view_model(&rows[i]);
        ag_api_grammar_decorate_model(db, m, &rows[i]);
        json_array_append_new(items, m);
    }
    json_t *next = json_null();
    if (n > (size_t)size) {
        char buf[32];
        snprintf(buf, sizeof buf, "m%lld", (long long)rows[shown - 1].id);
        next = json_string(buf);
    }
    for (size_t i = 0; i < n; i++)
        ag_models_row_clear(&rows[i]);
    free(rows);
    return ag_reply_json(r, 200, json_pack("{s:o, s:o}", "items", items, "next_page_token", next),
                         NULL);
}

enum MHD_Result ag_api_models_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    char name[1024];
    ag_upload_name(r, "model", name, sizeof name);
    ag_status s = ag_models_check_name(name, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    const char *format = ag_request_query(r, "format");
    if (format && ag_format_from_name(format) == AG_FORMAT_UNKNOWN) {
        ag_error_set(&err, AG_ERR_UNSUPPORTED, 0, "unknown format \"%s\"; archgram reads obj, ply, stl, gltf, glb, "
                     "fbx and dae",
                     format);
        return ag_reply_problem(r, AG_ERR_UNSUPPORTED, &err);
    }
    const char *up = ag_request_query(r, "up");
    if (up && strcmp(up, "y") != 0 && strcmp(up, "z") != 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0, "up must be \"y\" or \"z\", not \"%s\"", up);
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    if (ag_upload_bytes(r->upload) == 0) {
        ag_error_set(&err, AG_ERR_INVALID, 0,
                     "the request has no file: send it as the body (or a multipart \"file\" part)");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    const char *filename = ag_upload_filename(r->upload);
    const char *path = ag_upload_take_path(r->upload);
    json_t *params = json_pack("{s:s, s:s, s:s?, s:s?, s:s?}", "upload", path, "name", name,
                               "format", format, "up", up, "filename", filename);
    return ag_reply_new_job(r, "import", params, path);
}

static enum MHD_Result reply_model(ag_request *r, ag_db *db, int64_t id, unsigned status)
{
    ag_error err;
    ag_model_row row;
    ag_status s = ag_models_get(db, id, &row, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, row.version);
    json_t *body = ag_view_model(&row);
    ag_api_grammar_decorate_model(db, body, &row);
    ag_models_row_clear(&row);
    return ag_reply_json(r, status, body, etag);
}

enum MHD_Result ag_api_model_get(ag_request *r)
{
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    return db ? reply_model(r, db, r->ids[0], 200) : rc;
}

/* If-Match as a version; "*" stands for the current one. */
static ag_status precondition(ag_request *r, ag_db *db, int64_t *version, ag_error *err)
{
    ag_status s = ag_request_if_match(r, version, err);
    if (s != AG_OK || *version != -1)
        return s;
    ag_model_row row;
    if ((s = ag_models_get(db, r->ids[0], &row, err)) != AG_OK)
        return s;
    *version = row.version;
    ag_models_row_clear(&row);
    return AG_OK;
}

/* What every change needs: a connection, the JSON body and the If-Match version. Returns 0
 * after answering the request itself when one is missing. */
static int change_request(ag_request *r, ag_db **db, json_t **body, int64_t *base,
                          enum MHD_Result *rc)
{
    ag_error err;
    *body = NULL;
    if (!(*db = ag_request_db(r, rc)))
        return 0;
    ag_status s = ag_request_json(r, body, &err);
    if (s == AG_OK && (s = precondition(r, *db, base, &err)) != AG_OK) {
        json_decref(*body);
        *body = NULL;
    }
    if (s != AG_OK) {
        *rc = ag_reply_problem(r, s, &err);
        return 0;
    }
    return 1;
}

enum MHD_Result ag_api_model_patch(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db;
    json_t *body;
    int64_t base;
    if (!change_request(r, &db, &body, &base, &rc))
        return rc;
    ag_status s;
    const char *key;
    json_t *value;
    json_object_foreach(body, key, value) {
        if (strcmp(key, "name") != 0) {
            json_decref(body);
            ag_error_set(&err, AG_ERR_INVALID, 0, "\"%s\" cannot be changed; only \"name\"", key);
            return ag_reply_problem(r, AG_ERR_INVALID, &err);
        }
    }
    const char *name = json_string_value(json_object_get(body, "name"));
    if (!name) {
        json_decref(body);
        ag_error_set(&err, AG_ERR_INVALID, 0, "the body needs a string \"name\"");
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    json_t *op = json_pack("{s:s, s:s}", "kind", "rename", "name", name);
    json_decref(body);
    char cid[64];
    ag_request_fresh_cid("rest", cid, sizeof cid);
    int64_t version;
    int dup;
    s = ag_modelops_apply(r->cfg->app, r->ids[0], base, ag_request_author(r), cid, op, 0, &version,
                          &dup, &err);
    json_decref(op);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return reply_model(r, db, r->ids[0], 200);
}

enum MHD_Result ag_api_model_delete(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    int64_t version;
    ag_status s = precondition(r, db, &version, &err);
    if (s == AG_OK)
        s = ag_modelops_delete(r->cfg->app, r->ids[0], version, &err);
    return s == AG_OK ? ag_reply_empty(r, 204, NULL) : ag_reply_problem(r, s, &err);
}

enum MHD_Result ag_api_model_mesh(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_model_row row;
    ag_status s = ag_models_get(db, r->ids[0], &row, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    int64_t blob_id = row.mesh_blob;
    ag_models_row_clear(&row);
    /* The geometry changes only with a new mesh blob, so its id is a strong validator. */
    char etag[48];
    snprintf(etag, sizeof etag, "\"mesh-%lld\"", (long long)blob_id);
    if (ag_request_none_match(r, etag))
        return ag_reply_empty(r, 304, etag);
    void *blob;
    size_t blob_len;
    if ((s = ag_blobs_get(db, blob_id, &blob, &blob_len, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    ag_mesh *mesh = NULL;
    s = ag_meshblob_decode(blob, blob_len, &mesh, &err);
    free(blob);
    if (s != AG_OK)
        return ag_reply_problem(r, AG_ERR_INTERNAL, &err);
    uint8_t *glb;
    size_t glb_len;
    s = ag_glb_write(mesh, &glb, &glb_len, &err);
    ag_mesh_free(mesh);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_bytes(r, 200, "model/gltf-binary", glb, glb_len, etag);
}

static void append_op(void *user, const ag_op_row *op)
{
    json_array_append_new(user, ag_view_op(op));
}

enum MHD_Result ag_api_model_ops_list(ag_request *r)
{
    ag_error err;
    long long since;
    ag_status s = query_int(r, "since", 0, (long long)1 << 62, 0, &since, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_model_row row;
    if ((s = ag_models_get(db, r->ids[0], &row, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, row.version);
    ag_models_row_clear(&row);
    json_t *items = json_array();
    if ((s = ag_ops_each_since(db, r->ids[0], since, AG_OPS_LIST_MAX, append_op, items, &err))) {
        json_decref(items);
        return ag_reply_problem(r, s, &err);
    }
    return ag_reply_json(r, 200, json_pack("{s:o}", "items", items), etag);
}

enum MHD_Result ag_api_model_ops_create(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db;
    json_t *body;
    int64_t base;
    if (!change_request(r, &db, &body, &base, &rc))
        return rc;
    ag_status s;
    char generated[64];
    const char *cid = json_string_value(json_object_get(body, "cid"));
    if (!cid) {
        ag_request_fresh_cid("rest", generated, sizeof generated);
        cid = generated;
    }
    int64_t version;
    int dup;
    s = ag_modelops_apply(r->cfg->app, r->ids[0], base, ag_request_author(r), cid,
                          json_object_get(body, "op"), 0, &version, &dup, &err);
    json_decref(body);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, version);
    return ag_reply_json(r, 200, json_pack("{s:I, s:b}", "version", (json_int_t)version,
                                           "duplicate", dup),
                         etag);
}
