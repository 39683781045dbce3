/* Proceduralization over REST: POST …/proceduralize (a job), GET …/tree, GET and PUT
 * …/grammar, and mesh.glb with each component's label and split-tree node. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../app/grammar_edit.h"
#include "../app/views.h"
#include "../io/glb.h"
#include "../io/meshblob.h"
#include "../io/splittree_json.h"
#include "../store/grammars.h"
#include "../store/models.h"
#include "routes.h"
#include "upload.h"

/* If-Match as a version ("*" = the current one); AG_OK with *version = 0 when absent and
 * not required. */
static ag_status if_match(ag_request *r, int required, int64_t current, int64_t *version,
                          ag_error *err)
{
    *version = 0;
    if (!required && !ag_request_header(r, MHD_HTTP_HEADER_IF_MATCH))
        return AG_OK;
    ag_status s = ag_request_if_match(r, version, err);
    if (s != AG_OK)
        return s;
    if (*version == -1)
        *version = current;
    if (*version != current)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "model %lld is at version %lld, not %lld", (long long)r->ids[0],
                            (long long)current, (long long)*version);
    return AG_OK;
}

void ag_api_grammar_decorate_model(ag_db *db, json_t *model, const ag_model_row *row)
{
    int yes = 0;
    if (model && ag_grammars_is_current(db, row->id, row->mesh_blob, &yes, NULL) == AG_OK)
        json_object_set_new(model, "proceduralized", json_boolean(yes));
}

enum MHD_Result ag_api_model_proceduralize(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    /* an empty body or {} */
    if (r->body_len) {
        json_t *body;
        ag_status s = ag_request_json(r, &body, &err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &err);
        const char *key = NULL;
        json_t *v;
        json_object_foreach(body, key, v) break;
        if (key)
            ag_error_set(&err, AG_ERR_INVALID, 0, "\"%s\" is not an option of proceduralize",
                         key);
        json_decref(body);
        if (key)
            return ag_reply_problem(r, AG_ERR_INVALID, &err);
    }
    ag_model_row row;
    ag_status s = ag_models_get(db, r->ids[0], &row, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    int64_t current = row.version, base;
    ag_models_row_clear(&row);
    if ((s = if_match(r, 0, current, &base, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *params = json_pack("{s:I, s:I, s:s}", "model", (json_int_t)r->ids[0], "base",
                               (json_int_t)current, "author", ag_request_author(r));
    return ag_reply_new_job(r, "proceduralize", params, NULL);
}

enum MHD_Result ag_api_model_tree(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_grammar_row g;
    ag_status s = ag_grammars_current(db, r->ids[0], 1, &g, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* The stored tree is an object; the model, its version and the summary go in front. */
    const char *tree = g.tree_json;
    while (*tree == ' ')
        tree++;
    char *out = NULL;
    int n = -1;
    if (*tree == '{')
        n = asprintf(&out, "{\"model\":%lld,\"version\":%lld,\"summary\":%s%s%s",
                     (long long)r->ids[0], (long long)g.model_version, g.summary_json,
                     tree[1] == '}' ? "" : ",", tree + 1);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)g.model_version);
    ag_grammars_row_clear(&g);
    if (n < 0) {
        ag_error_set(&err, *tree == '{' ? AG_ERR_NOMEM : AG_ERR_INTERNAL, 0,
                     "the stored split tree cannot be served");
        return ag_reply_problem(r, err.code, &err);
    }
    return ag_reply_bytes(r, 200, "application/json", out, (size_t)n, etag);
}

enum MHD_Result ag_api_model_grammar_get(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_grammar_row g;
    ag_status s = ag_grammars_current(db, r->ids[0], 0, &g, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)g.model_version);
    char *text = g.text;
    size_t len = g.text_len;
    g.text = NULL;
    ag_grammars_row_clear(&g);
    return ag_reply_bytes(r, 200, "text/plain; charset=utf-8", text, len, etag);
}

/* The spooled body, whole, as NUL-terminated text (the file is removed). */
static ag_status read_body(ag_request *r, char **text, size_t *len, ag_error *err)
{
    *text = NULL;
    *len = 0;
    size_t n = r->upload ? ag_upload_bytes(r->upload) : 0;
    if (n > AG_GRAMMAR_TEXT_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "the grammar has %zu bytes; at most %zu are accepted", n,
                            AG_GRAMMAR_TEXT_MAX);
    if (n == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the body must hold the grammar text");
    const char *path = ag_upload_take_path(r->upload);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    char *buf = malloc(n + 1);
    size_t got = 0;
    while (fd >= 0 && buf && got < n) {
        ssize_t k = read(fd, buf + got, n - got);
        if (k <= 0)
            break;
        got += (size_t)k;
    }
    int e = errno;
    if (fd >= 0)
        close(fd);
    unlink(path);
    if (!buf)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the body");
    if (got != n) {
        free(buf);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot read the body back: %s", strerror(e));
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return AG_OK;
}

enum MHD_Result ag_api_model_grammar_put(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_model_row row;
    ag_status s = ag_models_get(db, r->ids[0], &row, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    int64_t current = row.version, base;
    ag_models_row_clear(&row);
    if ((s = if_match(r, 1, current, &base, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    char *text;
    size_t len;
    if ((s = read_body(r, &text, &len, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    char cid[64];
    ag_request_fresh_cid("grammar", cid, sizeof cid);
    int64_t version;
    long col = 0;
    s = ag_grammar_edit_apply(r->cfg->app, r->ids[0], base, ag_request_author(r), cid, text, len,
                              &version, &err, &col);
    free(text);
    if (s == AG_ERR_PARSE) {
        /* line and column as members, and in the detail */
        long line = err.element > 0 ? err.element : 1;
        if (col < 1)
            col = 1;
        char msg[AG_ERROR_TEXT];
        snprintf(msg, sizeof msg, "%s", err.text);
        ag_error_set(&err, AG_ERR_PARSE, line, "line %ld, column %ld: %s", line, col, msg);
        json_t *p = ag_view_problem(AG_ERR_PARSE, &err);
        if (p) {
            json_object_set_new(p, "line", json_integer(line));
            json_object_set_new(p, "column", json_integer(col));
        }
        char *body = p ? json_dumps(p, JSON_COMPACT) : NULL;
        json_decref(p);
        if (!body)
            return ag_reply_problem(r, AG_ERR_PARSE, &err);
        return ag_reply_bytes(r, 422, "application/problem+json", body, strlen(body), NULL);
    }
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    if ((s = ag_models_get(db, r->ids[0], &row, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    snprintf(etag, sizeof etag, "\"%lld\"", (long long)row.version);
    json_t *body = ag_view_model(&row);
    ag_api_grammar_decorate_model(db, body, &row);
    ag_models_row_clear(&row);
    return ag_reply_json(r, 200, body, etag);
}

/* mesh.glb: a proceduralized model's components also carry their label and tree node; any
 * other model is served as before. */
enum MHD_Result ag_api_model_mesh_glb(ag_request *r)
{
    ag_error err;
    enum MHD_Result rc;
    ag_db *db = ag_request_db(r, &rc);
    if (!db)
        return rc;
    ag_grammar_row g;
    ag_status s = ag_grammars_current(db, r->ids[0], 1, &g, &err);
    if (s == AG_ERR_NOT_FOUND)
        return ag_api_model_mesh(r);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[48];
    snprintf(etag, sizeof etag, "\"mesh-%lld\"", (long long)g.mesh_blob);
    if (ag_request_none_match(r, etag)) {
        ag_grammars_row_clear(&g);
        return ag_reply_empty(r, 304, etag);
    }
    void *blob;
    size_t blob_len;
    ag_mesh *mesh = NULL;
    ag_glb_component_meta *meta = NULL;
    char *labels = NULL;
    uint8_t *glb = NULL;
    size_t glb_len = 0;
    if ((s = ag_blobs_get(db, g.mesh_blob, &blob, &blob_len, &err)) == AG_OK) {
        s = ag_meshblob_decode(blob, blob_len, &mesh, &err);
        free(blob);
        if (s != AG_OK)
            s = AG_ERR_INTERNAL;
    }
    if (s == AG_OK)
        s = ag_splittree_json_component_meta(g.tree_json, mesh->ncomponents, &meta, &labels,
                                             &err);
    if (s == AG_OK)
        s = ag_glb_write_meta(mesh, meta, mesh->ncomponents, &glb, &glb_len, &err);
    ag_grammars_row_clear(&g);
    ag_mesh_free(mesh);
    free(meta);
    free(labels);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_bytes(r, 200, "model/gltf-binary", glb, glb_len, etag);
}
