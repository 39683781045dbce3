/* /api/v1/parts: the parts library (save from a model, search, read, thumbnail, mesh, bundle,
 * import, export, new versions, delete), and what the client needs to select and compose in a
 * model: GET …/selection and POST …/compose-preview. Composing is an op (api_models.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/app_parts.h"
#include "../app/problem.h"
#include "defer.h"
#include "routes.h"
#include "upload.h"

#define AG_PARTS_PAGE_DEFAULT 50
#define AG_PARTS_MAX_SELECTION 100000
#define AG_PARTS_MAX_BUNDLE ((size_t)256 << 20)
#define AG_PARTS_MAX_TAGS 64

static void version_etag(char *buf, size_t len, int64_t version)
{
    snprintf(buf, len, "\"%lld\"", (long long)version);
}

static enum MHD_Result invalid(ag_request *r, const char *msg)
{
    ag_error err;
    ag_error_set(&err, AG_ERR_INVALID, 0, "%s", msg);
    return ag_reply_problem(r, AG_ERR_INVALID, &err);
}

/* The ?version= of a part's file: 0 (the newest) when absent. */
static ag_status query_version(ag_request *r, int64_t *version, ag_error *err)
{
    long long v;
    ag_status s = ag_request_query_int(r, "version", 1, (long long)1 << 40, 0, &v, err);
    *version = v;
    return s;
}

static int client_has(void *user, const char *etag)
{
    return ag_request_none_match(user, etag);
}

/* --- saving ------------------------------------------------------------------------------- */

/* A node: an index or "root". */
static int node_of(json_t *v, int32_t *out)
{
    if (json_is_string(v) && strcmp(json_string_value(v), "root") == 0) {
        *out = 0;
        return 1;
    }
    if (!json_is_integer(v) || json_integer_value(v) < 0 || json_integer_value(v) > INT32_MAX)
        return 0;
    *out = (int32_t)json_integer_value(v);
    return 1;
}

typedef struct {
    ag_app_part_save rq;
    int32_t one, *nodes;
    const char *tags[AG_PARTS_MAX_TAGS];
} save_body;

/* POST /api/v1/parts and …/versions bodies: {"model","version","node"|"nodes","name",
 * "description","tags"}; a new version may leave out name and tags (kept). */
static ag_status read_save_body(json_t *b, int update, save_body *out, ag_error *err)
{
    static const char *const allowed[] = {"model", "version", "node", "nodes", "name",
                                          "description", "tags", NULL};
    memset(out, 0, sizeof *out);
    const char *key;
    json_t *v;
    json_object_foreach(b, key, v) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++)
            ok |= strcmp(key, *a) == 0;
        if (!ok)
            return ag_error_set(err, AG_ERR_INVALID, 0, "\"%s\" is not a member of a part save",
                                key);
    }
    json_t *jm = json_object_get(b, "model"), *jv = json_object_get(b, "version");
    if (!json_is_integer(jm) || json_integer_value(jm) < 1)
        return ag_error_set(err, AG_ERR_INVALID, 0, "model: the id of the model to save from");
    if (!json_is_integer(jv) || json_integer_value(jv) < 1)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "version: the model version whose tree the nodes are of");
    out->rq.model = json_integer_value(jm);
    out->rq.version = json_integer_value(jv);
    json_t *jn = json_object_get(b, "node"), *jl = json_object_get(b, "nodes");
    if (!!jn == !!jl)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a part is saved from a \"node\" or a selection of \"nodes\"");
    if (jn) {
        if (!node_of(jn, &out->one))
            return ag_error_set(err, AG_ERR_INVALID, 0, "node: an index or \"root\"");
        out->rq.nodes = &out->one;
        out->rq.nnodes = 1;
    } else {
        size_t n = json_array_size(jl);
        if (!json_is_array(jl) || n < 1 || n > AG_PARTS_MAX_SELECTION)
            return ag_error_set(err, AG_ERR_INVALID, 0, "nodes: an array of 1 to %d nodes",
                                AG_PARTS_MAX_SELECTION);
        if (!(out->nodes = malloc(n * sizeof *out->nodes)))
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        for (size_t i = 0; i < n; i++)
            if (!node_of(json_array_get(jl, i), &out->nodes[i]))
                return ag_error_set(err, AG_ERR_INVALID, 0, "nodes[%zu]: an index or \"root\"",
                                    i);
        out->rq.nodes = out->nodes;
        out->rq.nnodes = n;
    }
    json_t *jname = json_object_get(b, "name"), *jd = json_object_get(b, "description");
    json_t *jt = json_object_get(b, "tags");
    if ((jname && !json_is_string(jname)) || (!jname && !update))
        return ag_error_set(err, AG_ERR_INVALID, 0, "name: a part needs a name (a string)");
    if (jd && !json_is_string(jd))
        return ag_error_set(err, AG_ERR_INVALID, 0, "description: a string");
    out->rq.name = jname ? json_string_value(jname) : NULL;
    out->rq.description = jd ? json_string_value(jd) : NULL;
    if (jt) {
        size_t n = json_array_size(jt);
        if (!json_is_array(jt) || n > AG_PARTS_MAX_TAGS)
            return ag_error_set(err, AG_ERR_INVALID, 0, "tags: an array of at most %d strings",
                                AG_PARTS_MAX_TAGS);
        for (size_t i = 0; i < n; i++) {
            if (!(out->tags[i] = json_string_value(json_array_get(jt, i))))
                return ag_error_set(err, AG_ERR_INVALID, 0, "tags[%zu]: a string", i);
        }
        out->rq.tags = out->tags;
        out->rq.ntags = n;
    } else if (!update) {
        out->rq.tags = out->tags; /* none */
    }
    return AG_OK;
}

static enum MHD_Result reply_saved(ag_request *r, ag_status s, json_t *view, int64_t id,
                                   int64_t version, const ag_error *err)
{
    if (s != AG_OK)
        return ag_reply_problem(r, s, err);
    char loc[64], etag[32];
    snprintf(loc, sizeof loc, "/api/v1/parts/%lld", (long long)id);
    ag_reply_header(r, "Location", loc);
    version_etag(etag, sizeof etag, version);
    return ag_reply_json(r, 201, view, etag);
}

enum MHD_Result ag_api_parts_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    json_t *b;
    ag_status s = ag_request_json(r, &b, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    save_body sb;
    json_t *view = NULL;
    int64_t id = 0, version = 0;
    if ((s = read_save_body(b, 0, &sb, &err)) == AG_OK)
        s = ag_app_parts_save(r->cfg->app, &sb.rq, &view, &id, &version, &err);
    free(sb.nodes);
    json_decref(b);
    return reply_saved(r, s, view, id, version, &err);
}

/* The If-Match version of a change to a part; "*" is its newest. */
static ag_status part_precondition(ag_request *r, int64_t *version, ag_error *err)
{
    ag_if_match m;
    ag_status s = ag_request_if_match(r, &m, err);
    if (s == AG_ERR_PRECONDITION_REQUIRED)
        return ag_error_set(err, s, 0, "send If-Match with the part's ETag (its version)");
    if (s != AG_OK)
        return s;
    /* one version named: the save checks it, atomically */
    if (!m.any && m.n == 1 && m.tags == 1) {
        *version = m.versions[0];
        return AG_OK;
    }
    int64_t current;
    if ((s = ag_app_parts_version(r->cfg->app, r->ids[0], &current, err)) != AG_OK)
        return s;
    return ag_request_if_match_check(&m, "part", r->ids[0], current, version, err);
}

enum MHD_Result ag_api_part_versions_create(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    int64_t base = 0;
    json_t *b = NULL;
    ag_status s = ag_request_json(r, &b, &err);
    if (s == AG_OK)
        s = part_precondition(r, &base, &err);
    save_body sb = {0};
    json_t *view = NULL;
    int64_t id = 0, version = 0;
    if (s == AG_OK && (s = read_save_body(b, 1, &sb, &err)) == AG_OK) {
        sb.rq.update = r->ids[0];
        sb.rq.base = base;
        s = ag_app_parts_save(r->cfg->app, &sb.rq, &view, &id, &version, &err);
    }
    free(sb.nodes);
    json_decref(b);
    return reply_saved(r, s, view, id, version, &err);
}

/* --- reading ------------------------------------------------------------------------------ */

enum MHD_Result ag_api_parts_list(ag_request *r)
{
    ag_error err;
    long long size;
    ag_status s = ag_request_query_int(r, "page_size", 1, AG_APP_PARTS_PAGE_MAX,
                                       AG_PARTS_PAGE_DEFAULT, &size, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    /* Page tokens are "p" + the offset of the page: opaque to clients, cheap to check. */
    long long offset = 0;
    const char *token = ag_request_query(r, "page_token");
    if (token) {
        char *end;
        offset = token[0] == 'p' ? strtoll(token + 1, &end, 10) : -1;
        if (token[0] != 'p' || !token[1] || *end || offset < 0 || offset > 100000000)
            return invalid(r, "page_token is not one this server gave out");
    }
    const char *q = ag_request_query(r, "q"), *tag = ag_request_query(r, "tag");
    if (tag && !*tag)
        tag = NULL;
    json_t *items;
    int more;
    if ((s = ag_app_parts_search(r->cfg->app, q, tag, (size_t)offset, (size_t)size, &items,
                                 &more, &err)) != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *next = json_null();
    if (more) {
        char buf[32];
        snprintf(buf, sizeof buf, "p%lld", offset + (long long)json_array_size(items));
        next = json_string(buf);
    }
    return ag_reply_json(r, 200, json_pack("{s:o, s:o}", "items", items, "next_page_token", next),
                         NULL);
}

enum MHD_Result ag_api_part_get(ag_request *r)
{
    ag_error err;
    json_t *view;
    int64_t version;
    ag_status s = ag_app_parts_get(r->cfg->app, r->ids[0], &view, &version, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, version);
    return ag_reply_json(r, 200, view, etag);
}

enum MHD_Result ag_api_part_delete(ag_request *r)
{
    ag_error err;
    int64_t version;
    ag_status s = part_precondition(r, &version, &err);
    if (s == AG_OK)
        s = ag_app_parts_delete(r->cfg->app, r->ids[0], version, &err);
    return s == AG_OK ? ag_reply_empty(r, 204, NULL) : ag_reply_problem(r, s, &err);
}

static enum MHD_Result reply_file(ag_request *r, ag_status s, ag_app_bytes *b, const char *type,
                                  const ag_error *err)
{
    if (s != AG_OK)
        return ag_reply_problem(r, s, err);
    if (!b->data)
        return ag_reply_empty(r, 304, b->etag);
    return ag_reply_bytes(r, 200, type, b->data, b->len, b->etag);
}

typedef ag_status (*part_file)(ag_app *app, int64_t id, int64_t version,
                               int (*fresh)(void *user, const char *etag), void *user,
                               ag_app_bytes *out, ag_error *err);

/* A file of one part version (?version=, else the newest), 304 when the client has it. */
static enum MHD_Result reply_part_file(ag_request *r, part_file read, const char *type)
{
    ag_error err;
    int64_t version;
    ag_app_bytes b = {0};
    ag_status s = query_version(r, &version, &err);
    if (s == AG_OK)
        s = read(r->cfg->app, r->ids[0], version, client_has, r, &b, &err);
    return reply_file(r, s, &b, type, &err);
}

enum MHD_Result ag_api_part_thumbnail(ag_request *r)
{
    return reply_part_file(r, ag_app_parts_thumbnail, "image/png");
}

enum MHD_Result ag_api_part_mesh_glb(ag_request *r)
{
    return reply_part_file(r, ag_app_parts_glb, "model/gltf-binary");
}

static enum MHD_Result reply_bundle(ag_request *r, ag_status s, ag_app_bytes *b,
                                    const char *filename, const ag_error *err)
{
    if (s != AG_OK)
        return ag_reply_problem(r, s, err);
    char disp[128];
    snprintf(disp, sizeof disp, "attachment; filename=\"%s\"", filename);
    ag_reply_header(r, "Content-Disposition", disp);
    return ag_reply_bytes(r, 200, "application/json", b->data, b->len, NULL);
}

enum MHD_Result ag_api_part_bundle(ag_request *r)
{
    ag_error err;
    int64_t version;
    ag_app_bytes b = {0};
    ag_status s = query_version(r, &version, &err);
    if (s == AG_OK)
        s = ag_app_parts_bundle(r->cfg->app, &r->ids[0], 1, version, &b, &err);
    char name[48];
    snprintf(name, sizeof name, "part-%lld.agpart", (long long)r->ids[0]);
    return reply_bundle(r, s, &b, name, &err);
}

/* "1,2,3" into ids (at most cap); -1 for anything else. */
static long parse_ids(const char *s, int64_t *ids, size_t cap, long long hi)
{
    size_t n = 0;
    while (*s) {
        char *end;
        long long v = strtoll(s, &end, 10);
        if (end == s || *s == '-' || *s == '+' || v < 0 || v > hi || n == cap ||
            (*end && *end != ','))
            return -1;
        ids[n++] = v;
        s = *end ? end + 1 : end;
        if (*end && !*s)
            return -1; /* a trailing comma */
    }
    return (long)n;
}

#define AG_PARTS_EXPORT_IDS 1000

enum MHD_Result ag_api_parts_export(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    const char *list = ag_request_query(r, "ids");
    int64_t *ids = NULL;
    long n = 0;
    if (list) {
        if (!(ids = malloc(AG_PARTS_EXPORT_IDS * sizeof *ids)))
            return ag_reply_problem(r, AG_ERR_NOMEM,
                                    (ag_error_set(&err, AG_ERR_NOMEM, 0, "out of memory"), &err));
        n = parse_ids(list, ids, AG_PARTS_EXPORT_IDS, (long long)1 << 62);
        if (n < 1) {
            free(ids);
            return invalid(r, "ids: a comma-separated list of 1 to 1000 part ids");
        }
    }
    ag_app_bytes b = {0};
    ag_status s = ag_app_parts_bundle(r->cfg->app, ids, (size_t)n, 0, &b, &err);
    free(ids);
    return reply_bundle(r, s, &b, "library.agpart", &err);
}

/* The element a bundle problem names: its text up to the first ": " (a position such as
 * ":12:3" left out). */
static void problem_element(const char *text, char *out, size_t cap)
{
    const char *e = strstr(text, ": ");
    size_t n = e ? (size_t)(e - text) : 0;
    while (n > 0 && ((text[n - 1] >= '0' && text[n - 1] <= '9') || text[n - 1] == ':')) {
        size_t k = n;
        while (k > 0 && text[k - 1] >= '0' && text[k - 1] <= '9')
            k--;
        if (k == 0 || text[k - 1] != ':' || k == n)
            break;
        n = k - 1;
    }
    snprintf(out, cap, "%.*s", (int)n, text);
}

enum MHD_Result ag_api_parts_import(ag_request *r)
{
    ag_error err;
    ag_error_clear(&err);
    char *text = NULL;
    size_t len = 0;
    ag_status s = ag_upload_read_all(r, AG_PARTS_MAX_BUNDLE, "part bundle", &text, &len, &err);
    json_t *items = NULL;
    if (s == AG_OK)
        s = ag_app_parts_import(r->cfg->app, text, len, &items, &err);
    free(text);
    if (s == AG_ERR_PARSE) {
        json_t *p = ag_problem_json(s, &err);
        char element[160];
        problem_element(err.text, element, sizeof element);
        if (p && element[0])
            json_object_set_new(p, "element", json_string(element));
        char *body = p ? json_dumps(p, JSON_COMPACT) : NULL;
        json_decref(p);
        if (!body)
            return ag_reply_problem(r, s, &err);
        return ag_reply_bytes(r, 422, "application/problem+json", body, strlen(body), NULL);
    }
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_json(r, 201, json_pack("{s:o}", "items", items), NULL);
}

/* --- selecting and composing in a model --------------------------------------------------- */

enum MHD_Result ag_api_model_selection(ag_request *r)
{
    ag_error err;
    long long base;
    ag_status s = ag_request_query_int(r, "version", 1, (long long)1 << 62, 0, &base, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    const char *list = ag_request_query(r, "nodes");
    int64_t *ids = malloc(AG_PARTS_MAX_SELECTION * sizeof *ids);
    int32_t *nodes = malloc(AG_PARTS_MAX_SELECTION * sizeof *nodes);
    long n = list && ids && nodes ? parse_ids(list, ids, AG_PARTS_MAX_SELECTION, INT32_MAX) : -1;
    for (long i = 0; i < n; i++)
        nodes[i] = (int32_t)ids[i];
    free(ids);
    if (n < 1) {
        free(nodes);
        return invalid(r, "nodes: a comma-separated list of node ids of the model's tree");
    }
    json_t *out;
    s = ag_app_parts_selection(r->cfg->app, r->ids[0], base, nodes, (size_t)n, &out, &err);
    free(nodes);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    char etag[32];
    version_etag(etag, sizeof etag, json_integer_value(json_object_get(out, "version")));
    return ag_reply_json(r, 200, out, etag);
}

/* The composition is derived and encoded: on the model's task lane, off the HTTP threads. */
static void compose_preview(ag_request *r, ag_task_budget *budget)
{
    (void)budget;
    ag_error err;
    ag_error_clear(&err);
    json_t *b = NULL;
    int64_t base = 0;
    ag_status s = ag_request_json(r, &b, &err);
    if (s == AG_OK)
        s = ag_api_precondition(r, 1, &base, &err);
    json_t *report = NULL;
    ag_app_bytes glb = {0};
    if (s == AG_OK)
        s = ag_app_parts_compose_preview(r->cfg->app, r->ids[0], base, json_object_get(b, "op"),
                                         &glb, &report, &err);
    json_decref(b);
    if (s != AG_OK)
        return ag_defer_answer_problem(r, s, &err);
    char n[32];
    snprintf(n, sizeof n, "%lld",
             (long long)json_integer_value(json_object_get(report, "instances")));
    ag_reply_header(r, "X-Archgram-Instances", n);
    json_decref(report);
    ag_defer_answer_bytes(r, 200, "model/gltf-binary", glb.data, glb.len, NULL);
}

enum MHD_Result ag_api_model_compose_preview(ag_request *r)
{
    return ag_defer_run(r, AG_TASK_OP, r->ids[0], compose_preview);
}
