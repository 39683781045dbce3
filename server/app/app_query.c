#include "app_query.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/extrude/extrude.h"
#include "../io/glb.h"
#include "../io/meshblob.h"
#include "../io/plan_json.h"
#include "../store/extrusions.h"
#include "../store/grammars.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "../store/ops.h"
#include "app_points.h"
#include "edit_session.h"
#include "jobqueue.h"
#include "model_kept.h"
#include "model_tree.h"
#include "store_env.h"
#include "views.h"

static ag_db *db_of(ag_app *app, ag_error *err)
{
    return ag_app_db(app, err);
}

#define DB_OR_RETURN(db, app, err)                                                              \
    ag_db *db = db_of(app, err);                                                               \
    if (!db)                                                                                   \
        return err ? err->code : AG_ERR_DB

/* Adds "proceduralized" (a grammar describes the model's current mesh). */
static void decorate(ag_db *db, json_t *model, const ag_model_row *row)
{
    int yes = 0;
    if (model && ag_grammars_is_current(db, row->id, row->mesh_blob, &yes, NULL) == AG_OK)
        json_object_set_new(model, "proceduralized", json_boolean(yes));
}

ag_status ag_app_query_models(ag_app *app, const ag_identity *who, int64_t after, size_t limit,
                              json_t **items, int *more, ag_error *err)
{
    *items = NULL;
    *more = 0;
    DB_OR_RETURN(db, app, err);
    ag_model_row *rows;
    size_t n;
    /* One extra row tells whether another page follows; admins see every model. */
    int64_t visible_to = who->role == AG_ACCOUNT_ADMIN ? 0 : who->user;
    ag_status s = ag_models_list(db, visible_to, after, limit + 1, &rows, &n, err);
    if (s != AG_OK)
        return s;
    json_t *list = json_array();
    size_t shown = n > limit ? limit : n;
    for (size_t i = 0; i < shown; i++) {
        json_t *m = ag_view_model(&rows[i]);
        decorate(db, m, &rows[i]);
        ag_model_role member = AG_ROLE_NONE;
        if (rows[i].member_role[0] &&
            ag_members_role_parse(rows[i].member_role, &member, NULL) != AG_OK)
            member = AG_ROLE_NONE;
        json_object_set_new(
            m, "role", json_string(ag_members_role_name(ag_auth_role(who, member,
                                                                     rows[i].public_read))));
        json_array_append_new(list, m);
    }
    *more = n > limit;
    for (size_t i = 0; i < n; i++)
        ag_models_row_clear(&rows[i]);
    free(rows);
    if (!list)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    *items = list;
    return AG_OK;
}

ag_status ag_app_query_model(ag_app *app, int64_t id, json_t **view, int64_t *version,
                             ag_error *err)
{
    *view = NULL;
    DB_OR_RETURN(db, app, err);
    ag_model_row row;
    ag_status s = ag_models_get(db, id, &row, err);
    if (s != AG_OK)
        return s;
    *version = row.version;
    *view = ag_view_model(&row);
    decorate(db, *view, &row);
    ag_models_row_clear(&row);
    return *view ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

ag_status ag_app_query_version(ag_app *app, int64_t id, int64_t *version, ag_error *err)
{
    DB_OR_RETURN(db, app, err);
    ag_model_row row;
    ag_status s = ag_models_get(db, id, &row, err);
    if (s == AG_OK) {
        *version = row.version;
        ag_models_row_clear(&row);
    }
    return s;
}

static void append_op(void *user, const ag_op_row *op)
{
    json_array_append_new(user, ag_view_op(op));
}

ag_status ag_app_query_ops(ag_app *app, int64_t id, int64_t since, int64_t limit,
                           json_t **items, int64_t *version, ag_error *err)
{
    *items = NULL;
    DB_OR_RETURN(db, app, err);
    ag_status s = ag_app_query_version(app, id, version, err);
    if (s != AG_OK)
        return s;
    json_t *list = json_array();
    if ((s = ag_ops_each_since(db, id, since, limit, append_op, list, err)) != AG_OK) {
        json_decref(list);
        return s;
    }
    *items = list;
    return AG_OK;
}

ag_status ag_app_query_job(ag_app *app, int64_t job, json_t **view, int *finished,
                           ag_error *err)
{
    *view = NULL;
    DB_OR_RETURN(db, app, err);
    ag_job_row row;
    ag_status s = ag_jobs_get(db, job, &row, err);
    if (s != AG_OK)
        return s;
    if (finished)
        *finished = strcmp(row.status, "succeeded") == 0 || strcmp(row.status, "failed") == 0 ||
                    strcmp(row.status, "cancelled") == 0;
    *view = ag_view_job(&row);
    ag_jobs_row_clear(&row);
    return *view ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

/* What a reader makes of the served tree text: called while the text is valid, with the
 * grammar row it belongs to (the text is not kept). */
typedef ag_status (*served_reader)(void *user, const ag_grammar_row *g, const char *tree,
                                   ag_error *err);

/* The served tree of the model's current grammar g, handed to `read`, in the numbering ops
 * name: a tree stored in an older one is rebuilt (loading the model's edit model) before it is
 * served, and a bare one (an edit's, app/model_kept.h) is printed from the model's edit model,
 * once per version (ag_edit_session_served), and read in place there. On success g holds the
 * row the tree was read from (the caller clears it). */
static ag_status current_tree(ag_app *app, ag_db *db, int64_t id, ag_grammar_row *g,
                              served_reader read, void *user, ag_error *err)
{
    /* a version that comes while the edit model is loaded is read again: at most a few */
    for (int tries = 0; tries < 4; tries++) {
        ag_status s = ag_grammars_current(db, id, 1, g, err);
        if (s != AG_OK)
            return s;
        int renumber = g->tree_numbering != AG_MODEL_TREE_NUMBERING;
        if (!renumber && ag_model_kept_serves(g->tree_json)) {
            char *text = ag_model_kept_served_text(g->tree_json);
            s = text ? read(user, g, text, err)
                     : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            free(text);
            if (s != AG_OK)
                ag_grammars_row_clear(g);
            return s;
        }
        ag_store_env env;
        ag_edit_state *st = NULL;
        if ((s = ag__app_env(app, &env, err)) != AG_OK ||
            (s = ag_edit_session_acquire(env.sessions, db, id, &st, err)) != AG_OK) {
            ag_grammars_row_clear(g);
            return s;
        }
        const char *text = NULL;
        int current = !renumber && st->version == g->model_version;
        if (current && (s = ag_edit_session_served(st, &text, err)) == AG_OK)
            s = read(user, g, text, err);
        ag_edit_session_release(env.sessions, st);
        if (s == AG_OK && current)
            return AG_OK;
        ag_grammars_row_clear(g); /* renumbered, or changed meanwhile: read again */
        if (s != AG_OK)
            return s;
    }
    return ag_error_set(err, AG_ERR_BUSY, 0,
                        "model %lld kept changing while its tree was read; ask again",
                        (long long)id);
}

/* GET …/tree: the served tree, an object, with the model, its version and the summary in
 * front of its members. */
typedef struct {
    int64_t id;
    char *json;
    size_t len;
} tree_document;

static ag_status tree_document_of(void *user, const ag_grammar_row *g, const char *tree,
                                  ag_error *err)
{
    tree_document *d = user;
    while (*tree == ' ')
        tree++;
    if (*tree != '{')
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "the stored split tree cannot be served");
    int n = asprintf(&d->json, "{\"model\":%lld,\"version\":%lld,\"summary\":%s%s%s",
                     (long long)d->id, (long long)g->model_version, g->summary_json,
                     tree[1] == '}' ? "" : ",", tree + 1);
    if (n < 0) {
        d->json = NULL;
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    d->len = (size_t)n;
    return AG_OK;
}

ag_status ag_app_query_tree(ag_app *app, int64_t id, char **json, size_t *len,
                            int64_t *version, ag_error *err)
{
    *json = NULL;
    DB_OR_RETURN(db, app, err);
    ag_grammar_row g;
    tree_document d = {.id = id};
    ag_status s = current_tree(app, db, id, &g, tree_document_of, &d, err);
    if (s != AG_OK)
        return s;
    *version = g.model_version;
    ag_grammars_row_clear(&g);
    *json = d.json;
    *len = d.len;
    return AG_OK;
}

ag_status ag_app_query_grammar(ag_app *app, int64_t id, char **text, size_t *len,
                               int64_t *version, ag_error *err)
{
    *text = NULL;
    DB_OR_RETURN(db, app, err);
    ag_grammar_row g;
    ag_status s = ag_grammars_current(db, id, 0, &g, err);
    if (s != AG_OK)
        return s;
    *version = g.model_version;
    *text = g.text;
    *len = g.text_len;
    g.text = NULL;
    ag_grammars_row_clear(&g);
    return AG_OK;
}

/* --- plans of extrusion models ----------------------------------------------------------- */

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
    if (b->fallback) {
        json_object_set_new(o, "fallback", json_string(b->fallback));
        if (strcmp(b->fallback, "simplified") == 0)
            json_object_set_new(o, "moved", json_real(b->moved));
    }
    v->component += has_mesh;
    json_array_append_new(v->list, o);
    return AG_OK;
}

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

ag_status ag_app_query_plan(ag_app *app, int64_t id, json_t **doc, int64_t *version,
                            ag_error *err)
{
    *doc = NULL;
    DB_OR_RETURN(db, app, err);
    /* The version and the plans are read apart: read again if an edit came in between. */
    for (int attempt = 0; attempt < 5; attempt++) {
        int64_t before, after;
        ag_status s = ag_app_query_version(app, id, &before, err);
        json_t *d = NULL;
        if (s == AG_OK)
            s = plan_json(db, id, &d, err);
        if (s == AG_OK)
            s = ag_app_query_version(app, id, &after, err);
        if (s != AG_OK) {
            json_decref(d);
            return s;
        }
        if (before == after) {
            *doc = d;
            *version = before;
            return AG_OK;
        }
        json_decref(d);
    }
    return ag_error_set(err, AG_ERR_BUSY, 0, "the model kept changing while its plan was read");
}

/* mesh.glb: the served tree copied, read after the mesh is loaded. */
static ag_status copy_served(void *user, const ag_grammar_row *g, const char *tree,
                             ag_error *err)
{
    (void)g;
    char **out = user;
    free(*out); /* a version that came meanwhile: its tree replaces this one */
    if (!(*out = strdup(tree)))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return AG_OK;
}

/* --- geometry ---------------------------------------------------------------------------- */

static ag_status load_mesh(ag_db *db, int64_t blob_id, ag_mesh **mesh, ag_error *err)
{
    void *blob;
    size_t len;
    ag_status s = ag_blobs_get(db, blob_id, &blob, &len, err);
    if (s != AG_OK)
        return s;
    s = ag_meshblob_decode(blob, len, mesh, err);
    free(blob);
    return s == AG_OK ? AG_OK : AG_ERR_INTERNAL;
}

ag_status ag_app_query_glb(ag_app *app, int64_t id, int (*fresh)(void *user, const char *etag),
                           void *user, ag_app_bytes *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    DB_OR_RETURN(db, app, err);
    {
        /* a point cloud's mesh is empty until a surface is made of it: its points instead */
        ag_model_row row;
        ag_status ks = ag_models_get(db, id, &row, err);
        if (ks != AG_OK)
            return ks;
        int cloud = strcmp(row.kind, "pointcloud") == 0;
        ag_models_row_clear(&row);
        if (cloud)
            return ag_app_points_glb(app, id, 0, fresh, user, out, err);
    }
    ag_grammar_row g;
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_grammars_current(db, id, 0, &g, &e);
    int proceduralized = s == AG_OK;
    int64_t blob_id = 0;
    if (proceduralized) {
        blob_id = g.mesh_blob;
        ag_grammars_row_clear(&g);
    } else if (s == AG_ERR_NOT_FOUND) {
        ag_model_row row;
        if ((s = ag_models_get(db, id, &row, err)) != AG_OK)
            return s;
        blob_id = row.mesh_blob;
        ag_models_row_clear(&row);
    } else {
        if (err)
            *err = e;
        return s;
    }
    /* The geometry changes only with a new mesh file, so its id is a strong validator. */
    snprintf(out->etag, sizeof out->etag, "\"mesh-%lld\"", (long long)blob_id);
    if (fresh && fresh(user, out->etag))
        return AG_OK;
    /* the components' nodes and labels from the served tree (a version may have come since:
     * the mesh is then that version's) */
    char *served = NULL;
    if (proceduralized) {
        if ((s = current_tree(app, db, id, &g, copy_served, &served, err)) != AG_OK)
            return s;
        blob_id = g.mesh_blob;
        ag_grammars_row_clear(&g);
        snprintf(out->etag, sizeof out->etag, "\"mesh-%lld\"", (long long)blob_id);
    }
    ag_mesh *mesh = NULL;
    ag_glb_component_meta *meta = NULL;
    char *labels = NULL;
    s = load_mesh(db, blob_id, &mesh, err);
    if (s == AG_OK && proceduralized)
        s = ag_model_tree_component_meta(served, mesh->ncomponents, &meta, &labels, err);
    if (s == AG_OK)
        s = meta ? ag_glb_write_meta(mesh, meta, mesh->ncomponents, &out->data, &out->len, err)
                 : ag_glb_write(mesh, &out->data, &out->len, err);
    free(served);
    ag_mesh_free(mesh);
    free(meta);
    free(labels);
    return s;
}

/* Everything but out-of-memory is the plan's fault: report it as unprocessable input. */
static ag_status as_plan_problem(ag_status s, ag_error *err)
{
    if (s == AG_ERR_NOMEM || s == AG_OK)
        return s;
    if (err)
        err->code = AG_ERR_PARSE;
    return AG_ERR_PARSE;
}

/* One building extruded under opt (NULL: the defaults), as GLB. */
static ag_status preview(const char *plan_json, size_t len, const ag_extrude_options *opt,
                         ag_app_bytes *out, size_t *failing_faces, ag_error *err)
{
    memset(out, 0, sizeof *out);
    *failing_faces = 0;
    ag_plan *plan = NULL;
    ag_status s = ag_plan_json_read_buffer(plan_json, len, &plan, err);
    if (s != AG_OK)
        return as_plan_problem(s, err);
    ag_mesh *m = ag_mesh_create();
    if (!m) {
        ag_plan_free(plan);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_extrude_result res;
    s = ag_extrude_plan_with(plan, opt, m, -1, &res, NULL, err);
    ag_plan_free(plan);
    if (s != AG_OK) {
        ag_mesh_free(m);
        return s == AG_ERR_CANCELLED ? s : as_plan_problem(s, err);
    }
    s = ag_glb_write(m, &out->data, &out->len, err);
    ag_mesh_free(m);
    /* A shell that is not watertight is still shown; the caller tells the editor so. */
    *failing_faces = res.failing_faces;
    return s;
}

ag_status ag_app_query_extrusion_preview(const char *plan_json, size_t len, ag_app_bytes *out,
                                         size_t *failing_faces, ag_error *err)
{
    return preview(plan_json, len, NULL, out, failing_faces, err);
}

ag_status ag_app_query_extrusion_preview_budgeted(const char *plan_json, size_t len,
                                                  ag_task_budget *budget, ag_app_bytes *out,
                                                  size_t *failing_faces, ag_error *err)
{
    memset(out, 0, sizeof *out);
    *failing_faces = 0;
    if (ag_task_budget_exhausted(budget))
        return ag_task_budget_explain(budget, AG_ERR_CANCELLED, "the extrusion preview", err);
    /* the sweep polls the task's budget (its deadline, the asker still there, the service
     * still running) and stops within milliseconds of any; the events and memory it may
     * spend stay the extrusion's own defaults */
    ag_extrude_options o = {.budget = {.cancelled = ag_task_budget_exhausted, .user = budget}};
    ag_status s = preview(plan_json, len, &o, out, failing_faces, err);
    return ag_task_budget_explain(budget, s, "the extrusion preview", err);
}

json_t *ag_app_query_health(ag_app *app, int ws_port, ag_error *err)
{
    ag_db *db = db_of(app, err);
    if (!db)
        return NULL;
    const ag_work_limits *l = ag_app_limits(app);
    ag_jobqueue_stats q = ag_jobqueue_stats_now(ag__app_jobqueue(app));
    return json_pack("{s:s, s:s, s:{s:s, s:i}, s:i, s:i, s:{s:I, s:I, s:f, s:f, s:f}, "
                     "s:{s:I, s:I, s:I, s:I}}",
                     "status", "ok", "version", AG_VERSION, "db", "path", ag_db_path(db),
                     "schema_version", ag_db_schema_version(db), "ws_port", ws_port, "workers",
                     ag_app_workers(app), "limits", "max_triangles",
                     (json_int_t)l->max_triangles, "max_nodes", (json_int_t)l->max_nodes,
                     "op_seconds", l->op_seconds, "job_seconds", l->job_seconds,
                     "preview_seconds", l->preview_seconds, "work", "jobs_waiting",
                     (json_int_t)q.jobs_waiting, "jobs_running", (json_int_t)q.jobs_running,
                     "tasks_waiting", (json_int_t)q.tasks_waiting, "tasks_running",
                     (json_int_t)q.tasks_running);
}
