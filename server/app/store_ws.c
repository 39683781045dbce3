#include "store_ws.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../io/edit_op_json.h"
#include "../io/meshblob.h"
#include "../io/meshjson.h"
#include "../store/extrusions.h"
#include "../store/grammars.h"
#include "../store/jobs.h"
#include "../store/members.h"
#include "../store/models.h"
#include "../store/states.h"
#include "extrusion.h"
#include "model_kept.h"
#include "model_tree.h"
#include "part_library.h"
#include "usecase_compose.h"
#include "usecase_extrude.h"

/* --- reading --------------------------------------------------------------------------- */

static ag_status input_mesh(ag_workspace *ws, ag_mesh **mesh, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    ag_model_row row;
    ag_status s = ag_models_get(w->o.env.db, w->o.model, &row, err);
    if (s != AG_OK)
        return s;
    int64_t version = row.version, blob_id = row.mesh_blob;
    ag_models_row_clear(&row);
    if (version != w->o.base)
        return ag_error_set(err, AG_ERR_STALE, (long)version,
                            "model %lld is at version %lld, not %lld", (long long)w->o.model,
                            (long long)version, (long long)w->o.base);
    void *blob;
    size_t len;
    if ((s = ag_blobs_get(w->o.env.db, blob_id, &blob, &len, err)) != AG_OK)
        return s;
    s = ag_meshblob_decode(blob, len, mesh, err);
    free(blob);
    return s;
}

/* The model a paste copies from, borrowed read-only: problems name the source_model field. */
static ag_status acquire_source(ag_store_ws *w, int64_t src, ag_error *err)
{
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_edit_session_acquire(w->o.env.sessions, w->o.env.db, src, &w->source, &e);
    if (s == AG_ERR_NOT_FOUND)
        return ag_error_set(err, s, 0, "source_model: there is no model %lld", (long long)src);
    if (s != AG_OK)
        return ag_error_set(err, s, e.element, "source_model: %s", e.text);
    return AG_OK;
}

static ag_status open_models(ag_workspace *ws, const ag_edit_op_origin *from, ag_edit_model **em,
                             const ag_edit_model **source, int64_t *source_version, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    if (from && from->dir)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "source_dir: a folder is for `archgram edit`; the service names the "
                            "model to paste from with source_model");
    /* another model as the source: both are borrowed, the lower model id first, so two pastes
     * between the same models in opposite directions cannot wait on each other */
    int64_t src = from && from->model != w->o.model ? from->model : 0;
    ag_status s = AG_OK;
    if (src && src < w->o.model && (s = acquire_source(w, src, err)) != AG_OK)
        return s;
    if ((s = ag_edit_session_acquire(w->o.env.sessions, w->o.env.db, w->o.model, &w->target,
                                     err)) != AG_OK)
        return s;
    if (src && src > w->o.model && (s = acquire_source(w, src, err)) != AG_OK)
        return s;
    if (w->target->version != w->o.base)
        return ag_error_set(err, AG_ERR_STALE, (long)w->target->version,
                            "model %lld is at version %lld, not %lld", (long long)w->o.model,
                            (long long)w->target->version, (long long)w->o.base);
    *em = w->target->em;
    if (w->source) {
        *source = w->source->em;
        *source_version = w->source->version;
    }
    return AG_OK;
}

static ag_status model_trace(ag_workspace *ws, const ag_trace **trace, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    if (!w->target)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no model is open to trace");
    return ag_edit_session_trace(w->target, trace, err);
}

/* --- writing --------------------------------------------------------------------------- */

/* A mesh as the store keeps it: the meshblob and the stats JSON (both malloc'd). */
static ag_status encode_mesh(const ag_mesh *mesh, uint8_t **blob, size_t *len, char **stats,
                             ag_error *err)
{
    *stats = NULL;
    ag_status s = ag_meshblob_encode(mesh, blob, len);
    if (s != AG_OK)
        return ag_error_set(err, s, 0, "cannot encode the mesh");
    json_t *summary = ag_meshjson_summary(mesh);
    *stats = summary ? json_dumps(summary, JSON_COMPACT) : NULL;
    json_decref(summary);
    if (*stats)
        return AG_OK;
    free(*blob);
    *blob = NULL;
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory summarising the mesh");
}

/* The grammar row of `version`, naming its mesh file. */
static ag_status put_grammar_row(ag_db *db, int64_t model, int64_t version, int64_t mesh_blob,
                                 const char *text, size_t text_len, const char *tree_json,
                                 const char *summary_json, ag_error *err)
{
    ag_grammar_new g = {.model = model,
                        .version = version,
                        .mesh_blob = mesh_blob,
                        .text = text,
                        .text_len = text_len,
                        .tree_json = tree_json,
                        .tree_numbering = AG_MODEL_TREE_NUMBERING,
                        .summary_json = summary_json};
    return ag_grammars_put(db, &g, err);
}

ag_status ag__store_ws_put_grammar(ag_db *db, int64_t model, int64_t version, const void *mesh,
                                   size_t mesh_len, const char *stats, const char *text,
                                   size_t text_len, const char *tree_json, const char *summary_json,
                                   ag_error *err)
{
    int64_t mesh_blob = 0;
    ag_status s = ag_models_set_mesh(db, model, mesh, mesh_len, stats, &mesh_blob, err);
    if (s != AG_OK)
        return s;
    return put_grammar_row(db, model, version, mesh_blob, text, text_len, tree_json,
                           summary_json, err);
}

/* A state's largest parts as the store keeps them, made outside the transaction where they
 * can be: the mesh encoded, and the stored tree text printed on a thread of its own meanwhile
 * (and while the mesh is written); the two need nothing of each other. */
typedef struct {
    const ag_edit_model *em;
    int bare; /* the tree stored bare: the kept member alone (app/model_kept.h) */
    char *tree;
    double tree_ms, mesh_ms; /* printing the tree, encoding the mesh */
    pthread_t printer;
    int threaded;
    uint8_t *blob;
    size_t blob_len;
    char *stats;
    ag_status mesh_status;
} encoded_state;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static void *print_tree(void *arg)
{
    encoded_state *e = arg;
    double t0 = now_ms();
    /* a reload gives this model back */
    e->tree = e->bare ? ag_model_kept_bare_text(e->em) : ag_model_kept_tree_text(e->em);
    e->tree_ms = now_ms() - t0;
    return NULL;
}

static void encode_state(const ag_model_state *st, int bare, encoded_state *e, ag_error *err)
{
    memset(e, 0, sizeof *e);
    e->em = st->em;
    e->bare = bare;
    e->threaded = pthread_create(&e->printer, NULL, print_tree, e) == 0;
    if (!e->threaded)
        print_tree(e);
    double t0 = now_ms();
    e->mesh_status = encode_mesh(st->em->proc->mesh, &e->blob, &e->blob_len, &e->stats, err);
    e->mesh_ms = now_ms() - t0;
}

/* The tree text, once printed. */
static char *encoded_tree(encoded_state *e)
{
    if (e->threaded) {
        pthread_join(e->printer, NULL);
        e->threaded = 0;
    }
    return e->tree;
}

static void encoded_clear(encoded_state *e)
{
    free(encoded_tree(e));
    free(e->stats);
    free(e->blob);
    memset(e, 0, sizeof *e);
}

static ag_status write_state(ag_db *db, int64_t model, int64_t version, const ag_model_state *st,
                             encoded_state *e, const char *summary_json, int keep, ag_error *err)
{
    int64_t mesh_blob = 0;
    ag_status s = e->mesh_status;
    if (s == AG_OK) /* the tree goes on printing meanwhile */
        s = ag_models_set_mesh(db, model, e->blob, e->blob_len, e->stats, &mesh_blob, err);
    char *tree = encoded_tree(e);
    if (s == AG_OK && !tree)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory describing the model");
    if (s == AG_OK)
        s = put_grammar_row(db, model, version, mesh_blob, st->text, st->text_len,
                            keep ? "" : tree, summary_json, err);
    if (s == AG_OK && keep)
        s = ag_states_keep_with_tree(db, model, version, tree, err);
    return s;
}

ag_status ag__store_ws_put_state(ag_db *db, int64_t model, int64_t version,
                                 const ag_model_state *st, const char *summary_json, int keep,
                                 ag_error *err)
{
    encoded_state e;
    encode_state(st, 0, &e, err);
    ag_status s = write_state(db, model, version, st, &e, summary_json, keep, err);
    encoded_clear(&e);
    return s;
}

ag_status ag__store_ws_begin(ag_store_ws *w, const char *doing, int by_client, ag_seq_txn *t,
                             int *duplicate, ag_error *err)
{
    int64_t seen = 0;
    *duplicate = 0;
    ag_status s = ag_sequencer_begin(w->o.env.seq, w->o.env.db, w->o.model, w->o.base,
                                     by_client ? w->o.author : NULL, by_client ? w->o.cid : NULL,
                                     t, by_client ? &seen : NULL, err);
    if (s == AG_ERR_STALE && w->o.job)
        ag_error_set(err, AG_ERR_STALE, err ? err->element : 0,
                     "model %lld changed while it was being %s (it is at version %ld, the job "
                     "started from %lld); nothing was stored",
                     (long long)w->o.model, doing, err ? err->element : 0, (long long)w->o.base);
    if (s != AG_OK)
        return s;
    if (seen) { /* the same op came in meanwhile: answered, not applied again */
        w->duplicate = *duplicate = 1;
        w->version = seen;
    } else {
        t->origin = w->o.origin;
    }
    return AG_OK;
}

ag_status ag__store_ws_commit(ag_store_ws *w, ag_seq_txn *t, ag_status s,
                              ag__store_ws_links links, const json_t *op, ag_error *err)
{
    if (s == AG_OK && w->o.job && ag_jobctx_cancelled(w->o.job))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK && w->o.job_id) {
        char result[400];
        long long m = (long long)w->o.model;
        int n = snprintf(result, sizeof result,
                         "{\"model\":%lld,\"version\":%lld,\"href\":\"/api/v1/models/%lld\"", m,
                         (long long)t->version, m);
        if (links == AG__STORE_WS_LINKS_GRAMMAR)
            snprintf(result + n, sizeof result - (size_t)n,
                     ",\"tree\":\"/api/v1/models/%lld/tree\",\"grammar\":\"/api/v1/models/%lld/"
                     "grammar\"}",
                     m, m);
        else
            snprintf(result + n, sizeof result - (size_t)n,
                     ",\"points\":\"/api/v1/models/%lld/points.glb\"}", m);
        s = ag_jobs_finish(t->db, w->o.job_id, "succeeded", result, NULL, w->o.model, err);
    }
    int64_t v = t->version;
    if (s == AG_OK)
        s = ag_sequencer_commit(t, w->o.author, w->o.cid, op, err);
    else
        ag_sequencer_abort(t);
    if (s == AG_OK)
        w->version = v;
    return s;
}

void ag__store_ws_keep_model(ag_edit_sessions *reg, int64_t model, int64_t version,
                             ag_model_state *st)
{
    ag_edit_state *kept = NULL;
    if (!reg || ag_edit_session_hold(reg, model, &kept, NULL) != AG_OK)
        return;
    ag_edit_session_replace(kept, version, st->em);
    st->em = NULL;
    ag_edit_session_release(reg, kept);
}

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

/* The summary GET …/tree serves for a proceduralized model. */
static char *proc_summary(const ag_proc_outcome *o, const ag_model_state *st)
{
    const ag_proceduralize_result *r = o->proc;
    const ag_labels *L = r->labels;
    const ag_mesh *in = o->input;
    json_t *j = json_object();
    json_object_set_new(j, "source", json_string("proceduralize"));
    json_object_set_new(j, "input",
                        json_pack("{s:I, s:I, s:I, s:I, s:I, s:b}", "triangles",
                                  (json_int_t)in->ntris, "vertices", (json_int_t)in->nverts,
                                  "components", (json_int_t)r->mesh->ncomponents, "groups",
                                  (json_int_t)in->ngroups, "groups_split",
                                  (json_int_t)r->segment.groups_split, "planar_fallback",
                                  r->segment.planar_fallback));
    json_t *labels = json_array();
    for (size_t l = 0; l < L->nlabels; l++) {
        uint32_t ex = L->exemplar[l];
        double size[3];
        for (int a = 0; a < 3; a++)
            size[a] = L->box[ex].max[a] - L->box[ex].min[a];
        char name[32];
        snprintf(name, sizeof name, "L%zu", l + 1);
        json_array_append_new(labels, json_pack("{s:s, s:I, s:I, s:o}", "label", name, "count",
                                                (json_int_t)L->count[l], "triangles",
                                                (json_int_t)L->ntris[ex], "size", vec3(size)));
    }
    json_object_set_new(j, "labels", labels);
    ag_splittree_stats ts = ag_splittree_stats_of(r->tree);
    json_object_set_new(j, "tree",
                        json_pack("{s:I, s:I, s:I, s:I}", "nodes", (json_int_t)ts.nodes,
                                  "visible", (json_int_t)ts.visible, "invisible",
                                  (json_int_t)ts.invisible, "depth", (json_int_t)ts.depth));
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    json_object_set_new(j, "terminals", json_integer((json_int_t)r->grammar->nterminals));
    json_t *patterns = json_array();
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        int32_t ri = r->info.rule_of_class && pt->rule >= 0 ? r->info.rule_of_class[pt->rule] : -1;
        json_array_append_new(
            patterns,
            json_pack("{s:o, s:[I,I,I], s:o, s:I}", "rule",
                      ri >= 0 ? json_string(r->grammar->rules[ri].name) : json_null(), "counts",
                      (json_int_t)pt->counts[0], (json_int_t)pt->counts[1],
                      (json_int_t)pt->counts[2], "step", vec3(pt->step), "instances",
                      (json_int_t)pt->counts[0] * pt->counts[1] * pt->counts[2]));
    }
    json_object_set_new(j, "patterns", patterns);
    json_object_set_new(j, "grammar_bytes", json_integer((json_int_t)st->text_len));
    json_object_set_new(j, "terminal_bytes", json_integer((json_int_t)st->terms.bytes));
    json_object_set_new(j, "fidelity",
                        json_pack("{s:f, s:f, s:I}", "max_error", o->fidelity.max_error,
                                  "relative", o->fidelity.relative, "unmatched",
                                  (json_int_t)o->fidelity.unmatched));
    double total = 0;
    json_t *sec = json_object();
    for (int s = 0; s < AG_STAGE_COUNT; s++) {
        json_object_set_new(sec, ag_proceduralize_stage_name((ag_stage)s), json_real(o->seconds[s]));
        total += o->seconds[s];
    }
    json_object_set_new(sec, "total", json_real(total));
    json_object_set_new(j, "seconds", sec);
    char *text = json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    json_decref(j);
    return text;
}

static ag_status save_proc(ag_store_ws *w, ag_model_state *st, const ag_proc_outcome *o,
                           ag_error *err)
{
    char *summary = proc_summary(o, st);
    json_t *op = json_pack("{s:s, s:I, s:I, s:I}", "kind", "proceduralize", "rules",
                           (json_int_t)o->proc->grammar->nrules, "terminals",
                           (json_int_t)o->proc->grammar->nterminals, "patterns",
                           (json_int_t)o->proc->tree->npatterns);
    ag_status s = summary && op ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_seq_txn t;
    int dup = 0;
    if (s == AG_OK)
        s = ag__store_ws_begin(w, "proceduralized", 0, &t, &dup, err);
    if (s != AG_OK) {
        free(summary);
        json_decref(op);
        return s;
    }
    /* kept as a state at once, as an edit keeps its own: the first edit would otherwise copy
     * this version's rows (the served tree of a large model is megabytes) inside its commit */
    s = ag__store_ws_put_state(t.db, w->o.model, t.version, st, summary, 1, err);
    if (s == AG_OK)
        s = ag_grammars_clear_terminals(t.db, w->o.model, err);
    for (size_t i = 0; s == AG_OK && i < st->terms.n; i++)
        s = ag_grammars_put_terminal(t.db, w->o.model, st->terms.path[i], st->terms.obj[i],
                                     st->terms.len[i], err);
    s = ag__store_ws_commit(w, &t, s, AG__STORE_WS_LINKS_GRAMMAR, op, err);
    if (s == AG_OK)
        ag__store_ws_keep_model(w->o.env.sessions, w->o.model, w->version, st);
    free(summary);
    json_decref(op);
    return s;
}

/* Commits a structural change of the model (an edit, a composition): the state before and
 * after are kept for undo, st is stored with the version the op raises, body is logged. */
static char *change_summary(const char *source, const char *kind, const ag_model_state *st);

static ag_status commit_change(ag_store_ws *w, ag_model_state *st, json_t *body,
                               const char *source, const char *kind, ag_error *err)
{
    /* encoded before the sequencer's lock is taken: it serializes every model's changes;
     * meanwhile the grammar's read-back check may still be running (ag_model_state_start);
     * the tree is stored bare, served from the edit model kept for the next edit when asked */
    encoded_state e;
    encode_state(st, 1, &e, err);
    ag_status s = e.mesh_status;
    if (s == AG_OK)
        s = ag_model_state_checked(st, err);
    char *summary = s == AG_OK ? change_summary(source, kind, st) : NULL;
    if (s == AG_OK && !summary)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s != AG_OK) {
        encoded_clear(&e);
        return s;
    }
    ag_seq_txn t;
    int dup = 0;
    double t_begin = now_ms();
    s = ag__store_ws_begin(w, "edited", 1, &t, &dup, err);
    if (s != AG_OK || dup) {
        encoded_clear(&e);
        free(summary);
        return s;
    }
    double t_locked = now_ms();
    s = ag_states_keep(t.db, w->o.model, t.version - 1, err);
    if (s == AG_OK)
        s = write_state(t.db, w->o.model, t.version, st, &e, summary, 1, err);
    double t_tree = e.tree_ms, t_mesh = e.mesh_ms;
    encoded_clear(&e);
    free(summary);
    for (size_t i = 0; s == AG_OK && i < st->terms.n; i++)
        s = ag_grammars_put_terminal(t.db, w->o.model, st->terms.path[i], st->terms.obj[i],
                                     st->terms.len[i], err);
    /* the commit's stages up to here, for the op log (bench/parts reads them) */
    json_t *report = json_object_get(body, "report");
    if (s == AG_OK && json_is_object(report))
        json_object_set_new(report, "commit",
                            json_pack("{s:f, s:f, s:f, s:f}", "tree_ms", t_tree, "mesh_ms",
                                      t_mesh, "lock_ms", t_locked - t_begin, "writes_ms",
                                      now_ms() - t_locked));
    int64_t v = t.version;
    if (s == AG_OK)
        s = ag_sequencer_commit(&t, w->o.author, w->o.cid, body, err);
    else
        ag_sequencer_abort(&t);
    if (s == AG_OK) {
        w->version = v;
        /* the next edit starts from this one's model */
        ag_edit_session_replace(w->target, v, st->em);
        st->em = NULL;
    }
    return s;
}

/* The summary GET …/tree serves for an edited or composed model. */
static char *change_summary(const char *source, const char *kind, const ag_model_state *st)
{
    const ag_grammar *g = st->em->proc->grammar;
    json_t *sj = json_pack("{s:s, s:s, s:I, s:I, s:I, s:I, s:I}", "source", source, "op", kind,
                           "rules", (json_int_t)g->nrules, "terminals", (json_int_t)g->nterminals,
                           "grammar_bytes", (json_int_t)st->text_len, "triangles",
                           (json_int_t)st->derived->ntris, "components",
                           (json_int_t)st->derived->ncomponents);
    char *summary = sj ? json_dumps(sj, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(sj);
    return summary;
}

static ag_status save_edit(ag_store_ws *w, ag_model_state *st, const ag_edit_outcome *o,
                           ag_error *err)
{
    json_t *report = ag_edit_op_json_report(&o->report);
    json_t *body = json_deep_copy(w->o.op);
    if (report)
        json_object_set_new(report, "edit_ms", json_real(o->edit_ms));
    if (report && o->source_version) /* the version of the source model whose nodes were copied */
        json_object_set_new(report, "source_version", json_integer((json_int_t)o->source_version));
    ag_status s = AG_OK;
    if (!report || !body) {
        json_decref(report);
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    } else if (json_object_set_new(body, "report", report) != 0) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (s == AG_OK)
        s = commit_change(w, st, body, "edit",
                          json_string_value(json_object_get(w->o.op, "kind")), err);
    json_decref(body);
    return s;
}

/* The new state's stages, for the op log (bench/parts reads them): the grammar's terminals,
 * text and read-back, the edit model made, and inside it the graft's stages. */
static json_t *state_stages(const ag_model_state *st, const ag_graft_report *g)
{
    const ag_model_state_times *t = &st->times;
    return json_pack("{s:f, s:f, s:f, s:f, s:{s:f, s:f, s:f, s:f, s:f, s:f, s:f}}",
                     "terminals_ms", t->terminals_ms, "text_ms", t->text_ms, "read_back_ms",
                     t->read_back_ms, "model_ms", t->model_ms, "graft", "components_ms",
                     g->components_ms, "removal_ms", g->removal_ms, "pair_ms", g->pair_ms,
                     "classify_ms", g->classify_ms, "insert_ms", g->insert_ms, "input_ms",
                     g->input_ms, "rebuild_ms", g->rebuild_ms);
}

static ag_status save_composed(ag_workspace *ws, ag_model_state *st, const ag_compose_outcome *o,
                               ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    /* logged: the op as sent, with the part version it used and the composition's report */
    json_t *report = ag_usecase_compose_report_json(o);
    json_t *body = json_deep_copy(w->o.op);
    ag_status s = AG_OK;
    if (report) {
        json_object_set_new(report, "compose_ms", json_real(o->compose_ms));
        json_object_set_new(report, "state_ms", json_real(o->state_ms));
        json_object_set_new(report, "state_stages", state_stages(st, &o->graft));
    }
    if (!report || !body || !w->target ||
        json_object_set_new(body, "version", json_integer((json_int_t)o->part->version)) ||
        json_object_set(body, "report", report))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK)
        s = commit_change(w, st, body, "compose", "compose", err);
    json_decref(report);
    json_decref(body);
    ag_model_state_clear(st);
    return s;
}

static ag_status open_part(ag_workspace *ws, const ag_part_ref *ref, const ag_part **part,
                           ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    if (!w->part) {
        if (ref->id < 1)
            return ag_error_set(err, AG_ERR_INVALID, 0, "part: the id of a part of the library");
        ag_status s = ag_part_library_load(w->o.env.db, ref->id, ref->version, &w->part, err);
        if (s != AG_OK)
            return s;
    }
    *part = w->part;
    return AG_OK;
}

static ag_status save_part(ag_workspace *ws, ag_part *part, const ag_part_outcome *o,
                           ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    (void)o;
    ag_model_row row;
    ag_status s = ag_models_get(w->o.env.db, w->o.model, &row, err);
    if (s == AG_OK) {
        ag_part_library_source from = {.model = w->o.model,
                                       .name = row.name,
                                       .version = w->target ? w->target->version : w->o.base};
        s = ag_part_library_save(w->o.env.db, part, &from, w->o.part_update, w->o.part_base,
                                 &w->part_id, &w->part_version, err);
        ag_models_row_clear(&row);
    }
    ag_part_free(part);
    return s;
}

static ag_status save(ag_workspace *ws, ag_model_state *st, const ag_proc_outcome *proc,
                      const ag_edit_outcome *edit, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    /* an edit's read-back check is waited for in its commit, after the model is encoded */
    ag_status s = proc ? ag_model_state_checked(st, err) : AG_OK;
    if (s == AG_OK)
        s = proc                  ? save_proc(w, st, proc, err)
            : edit && w->target ? save_edit(w, st, edit, err)
                                : ag_error_set(err, AG_ERR_INTERNAL, 0, "nothing to save");
    ag_model_state_clear(st);
    return s;
}

/* A new model row; up (may be NULL) is how its file's up axis was decided. */
static ag_status insert_model(ag_db *db, const char *name, const ag_mesh *mesh,
                              const void *source, size_t source_len, const char *source_format,
                              const ag_up_decision *up, int64_t *model, ag_error *err)
{
    uint8_t *blob = NULL;
    size_t blob_len = 0;
    char *stats = NULL, *up_json = NULL;
    ag_status s = encode_mesh(mesh, &blob, &blob_len, &stats, err);
    if (s != AG_OK)
        return s;
    if (up) {
        json_t *j = ag_import_up_json(up);
        up_json = j ? json_dumps(j, JSON_COMPACT | JSON_REAL_PRECISION(6)) : NULL;
        json_decref(j);
        if (!up_json) {
            free(stats);
            free(blob);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory describing the up axis");
        }
    }
    ag_model_new m = {
        .name = name,
        .stats_json = stats,
        .up_json = up_json,
        .source = source,
        .source_len = source_len,
        .source_format = source_format,
        .source_media_type = "application/octet-stream",
        .mesh = blob,
        .mesh_len = blob_len,
    };
    s = ag_models_insert(db, &m, model, err);
    free(stats);
    free(up_json);
    free(blob);
    return s;
}

ag_status ag_store_ws_insert_model(ag_db *db, const char *name, const ag_mesh *mesh,
                                   const void *source, size_t source_len,
                                   const char *source_format, int64_t *model, ag_error *err)
{
    return insert_model(db, name, mesh, source, source_len, source_format, NULL, model, err);
}

static ag_status add_model(ag_workspace *ws, const char *name, const ag_mesh *mesh,
                           const void *source, size_t source_len, const char *source_format,
                           const ag_up_decision *up, int64_t *model, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    ag_db *db = w->o.env.db;
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    s = insert_model(db, name, mesh, source, source_len, source_format, up, model, err);
    if (s == AG_OK && w->o.job_id)
        s = ag_members_own_from_job(db, *model, w->o.job_id, err);
    if (s == AG_OK && w->o.job && ag_jobctx_cancelled(w->o.job))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK && w->o.job_id) {
        char result[128];
        snprintf(result, sizeof result, "{\"model\":%lld,\"href\":\"/api/v1/models/%lld\"}",
                 (long long)*model, (long long)*model);
        s = ag_jobs_finish(db, w->o.job_id, "succeeded", result, NULL, *model, err);
    }
    return s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
}

static ag_status add_extrusion(ag_workspace *ws, const char *name, const ag_extrusion_batch *b,
                               const ag_mesh *mesh, const char *source, size_t source_len,
                               const json_t *report, int64_t *model_out, ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    ag_db *db = w->o.env.db;
    uint8_t *blob = NULL;
    size_t blob_len = 0;
    char *stats = ag_extrusion_stats(mesh), *meta = json_dumps(b->meta, JSON_COMPACT);
    ag_status s = stats && meta ? ag_meshblob_encode(mesh, &blob, &blob_len) : AG_ERR_NOMEM;
    if (s != AG_OK) {
        free(stats);
        free(meta);
        return ag_error_set(err, s, 0, "cannot encode the mesh");
    }
    if ((s = ag_db_begin(db, err)) != AG_OK)
        goto out;
    int geo = strcmp(b->format, "geojson") == 0;
    ag_model_new m = {
        .name = name,
        .kind = "extrusion",
        .stats_json = stats,
        .source = source,
        .source_len = source_len,
        .source_format = b->format,
        .source_media_type = geo ? "application/geo+json" : "application/json",
        .mesh = blob,
        .mesh_len = blob_len,
    };
    int64_t model = 0;
    s = ag_models_insert(db, &m, &model, err);
    *model_out = model;
    if (s == AG_OK && w->o.job_id)
        s = ag_members_own_from_job(db, model, w->o.job_id, err);
    if (s == AG_OK)
        s = ag_extrusions_put(db, model, strcmp(b->format, "plan") != 0, meta, err);
    for (size_t i = 0; s == AG_OK && i < b->n; i++) {
        const ag_extrude_building *it = &b->items[i];
        ag_extrusion_building row = {.model = model,
                                     .building = (int64_t)i,
                                     .footprint = it->id,
                                     .plan_json = it->plan_json ? it->plan_json : "null",
                                     .mesh = it->built.blob,
                                     .mesh_len = it->built.blob_len,
                                     .triangles = (int64_t)it->built.triangles,
                                     .reason = it->built.reason[0] ? (char *)it->built.reason
                                                                   : NULL,
                                     .fallback = ag_extrusion_built_fallback(&it->built),
                                     .moved = it->built.moved};
        snprintf(row.status, sizeof row.status, "%s", it->built.status);
        s = ag_extrusions_put_building(db, &row, err);
    }
    if (s == AG_OK && w->o.job && ag_jobctx_cancelled(w->o.job))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    char *result = NULL;
    if (s == AG_OK && w->o.job_id) {
        char href[64];
        snprintf(href, sizeof href, "/api/v1/models/%lld", (long long)model);
        json_t *r = json_pack("{s:I, s:s, s:O}", "model", (json_int_t)model, "href", href,
                              "report", (json_t *)report);
        result = r ? json_dumps(r, JSON_COMPACT) : NULL;
        json_decref(r);
        s = result ? ag_jobs_finish(db, w->o.job_id, "succeeded", result, NULL, model, err)
                   : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    free(result);
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
out:
    free(blob);
    free(stats);
    free(meta);
    return s;
}


static int cancelled(ag_workspace *ws)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    return w->o.job ? ag_jobctx_cancelled(w->o.job) : 0;
}

static void progress(ag_workspace *ws, double fraction, const char *stage)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    if (w->o.job)
        ag_jobctx_progress(w->o.job, fraction, stage);
}

static const ag_workspace_ops store_ops = {
    .add_model = add_model,
    .add_extrusion = add_extrusion,
    .input_mesh = input_mesh,
    .open_models = open_models,
    .save = save,
    .open_part = open_part,
    .save_part = save_part,
    .save_composed = save_composed,
    .model_trace = model_trace,
    .add_cloud = ag__store_ws_add_cloud,
    .input_cloud = ag__store_ws_input_cloud,
    .save_segmentation = ag__store_ws_save_segmentation,
    .open_point_models = ag__store_ws_open_point_models,
    .save_points = ag__store_ws_save_points,
    .cancelled = cancelled,
    .progress = progress,
    .state_flags = 0, /* the mesh is kept: a reload gives the saved model itself */
};

void ag_store_ws_init(ag_store_ws *w, const ag_store_ws_options *o)
{
    memset(w, 0, sizeof *w);
    w->ws.ops = &store_ops;
    w->o = *o;
}

void ag_store_ws_init_op(ag_store_ws *w, const ag_store_env *env, const ag_op_request *rq)
{
    ag_store_ws_init(w, &(ag_store_ws_options){.env = *env,
                                               .model = rq->model,
                                               .base = rq->base,
                                               .author = rq->author,
                                               .cid = rq->cid,
                                               .origin = rq->origin,
                                               .op = rq->op});
}

void ag_store_ws_init_job(ag_store_ws *w, const ag_store_env *env, ag_jobctx *ctx, int64_t job,
                          int64_t model, int64_t base, const char *author)
{
    char cid[sizeof w->job_cid];
    snprintf(cid, sizeof cid, "job-%lld", (long long)job);
    ag_store_ws_init(w, &(ag_store_ws_options){.env = *env,
                                               .model = model,
                                               .base = base,
                                               .author = author,
                                               .job = ctx,
                                               .job_id = job});
    memcpy(w->job_cid, cid, sizeof cid);
    w->o.cid = w->job_cid;
}

void ag_store_ws_end(ag_store_ws *w, ag_status outcome)
{
    if (w->target && outcome != AG_OK && outcome != AG_ERR_STALE && outcome != AG_ERR_INVALID &&
        outcome != AG_ERR_NOT_FOUND && outcome != AG_ERR_CONFLICT && outcome != AG_ERR_PARSE &&
        outcome != AG_ERR_NOT_PROCEDURALIZED && outcome != AG_ERR_TOO_LARGE &&
        outcome != AG_ERR_EMPTY && outcome != AG_ERR_RESULT_TOO_LARGE &&
        outcome != AG_ERR_DEADLINE && outcome != AG_ERR_CANCELLED)
        ag_edit_session_reset(w->target); /* an unexpected failure: load afresh next time */
    ag_edit_session_release(w->o.env.sessions, w->source);
    ag_edit_session_release(w->o.env.sessions, w->target);
    w->source = w->target = NULL;
    ag_part_free(w->part);
    w->part = NULL;
    ag_pointmodel_free(w->points);
    ag_pointmodel_free(w->points_source);
    w->points = w->points_source = NULL;
}
