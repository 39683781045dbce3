/* The store workspace's point model operations (app/store_ws.h): the point model of a
 * proceduralized cloud read from its stored grammar and PLY terminals, and a proceduralized
 * or edited point model saved as a sequenced op.
 *
 * A point model is kept in the tables meshes use: its grammar text, served tree (boxes in the
 * input's coordinates, numbering AG_MODEL_TREE_NUMBERING) and summary in grammars, its PLY
 * terminals in terminals (paths name their content, so a run or edit that makes the same
 * point set stores it once; the terminals of every kept state stay readable, and those no kept
 * version names are released with each save), and a new empty mesh file per saved state, so that the grammar describes the
 * model exactly while that state is current (store/grammars.h) and undo, redo and restore
 * bring a version's grammar back with its states (store/states.h). Nothing is cached: a model
 * is read back from its text each time, numbered by the tree stored with the text: an edit
 * keeps the ids of the nodes it left alone (issue 14 §4), and its tree is stored with what
 * rebuilds that numbering (app/model_kept.h), so a reload, undo, redo and restore give it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/points/pointedit.h"
#include "../io/edit_op_json.h"
#include "../io/meshblob.h"
#include "../store/grammars.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "../store/pointclouds.h"
#include "../store/states.h"
#include "edit_ops.h"
#include "model_kept.h"
#include "model_tree.h"
#include "points_state.h"
#include "points_summary.h"
#include "store_ws.h"
#include "usecase_points.h"

/* ---- reading ------------------------------------------------------------------------------ */

ag_status ag__store_ws_terminal_lookup(void *user, const char *path, char **data, size_t *len,
                                       ag_error *err)
{
    const ag__store_ws_terminals *t = user;
    return ag_grammars_get_terminal(t->db, t->model, path, data, len, err);
}

ag_status ag_store_ws_read_point_model(ag_db *db, int64_t model, const char *field,
                                       ag_pointmodel **pm, int64_t *version, ag_error *err)
{
    *pm = NULL;
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s == AG_ERR_NOT_FOUND && field[0])
        return ag_error_set(err, s, 0, "%s: there is no model %lld", field, (long long)model);
    if (s != AG_OK)
        return s;
    int cloud = strcmp(row.kind, "pointcloud") == 0;
    *version = row.version;
    ag_models_row_clear(&row);
    if (!cloud)
        return ag_error_set(err, AG_ERR_CONFLICT, 0,
                            "%s%smodel %lld is not a point cloud: a point model is edited with "
                            "point models",
                            field, field[0] ? ": " : "", (long long)model);
    ag_grammar_row g;
    ag_error e;
    ag_error_clear(&e);
    if ((s = ag_grammars_current(db, model, 1, &g, &e)) == AG_ERR_NOT_FOUND)
        return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                            "%s%smodel %lld is not proceduralized: structural edits need a "
                            "grammar (POST /api/v1/models/%lld/proceduralize)",
                            field, field[0] ? ": " : "", (long long)model, (long long)model);
    if (s != AG_OK) {
        if (err)
            *err = e;
        return s;
    }
    ag__store_ws_terminals ts = {db, model};
    long col = 0;
    s = ag_points_state_read(g.text, g.text_len, ag__store_ws_terminal_lookup, &ts, pm, &e, &col);
    /* numbered as the state was saved: the ids an edit kept, not those the text gives */
    if (s == AG_OK)
        s = ag_points_state_reload_kept(*pm, g.tree_json, &e);
    if (s != AG_OK) {
        ag_pointmodel_free(*pm);
        *pm = NULL;
    }
    ag_grammars_row_clear(&g);
    if (s != AG_OK) /* what the store saved does not read back: not the caller's fault */
        s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                         "the stored point grammar of model %lld does not read: %s",
                         (long long)model, e.text);
    return s;
}

ag_status ag__store_ws_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                         ag_pointmodel **pm, const ag_pointmodel **source,
                                         ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    *pm = NULL;
    *source = NULL;
    if (from && from->dir)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "source_dir: a folder is for `archgram edit`; the service names the "
                            "model to paste from with source_model");
    /* held, so edits of one model wait for each other as mesh edits do */
    ag_status s = AG_OK;
    if (!w->target &&
        (s = ag_edit_session_hold(w->o.env.sessions, w->o.model, &w->target, err)) != AG_OK)
        return s;
    ag_db *db = w->o.env.db;
    /* the version, the grammar and its terminals of one snapshot */
    if ((s = ag_pointclouds_read_begin(db, err)) != AG_OK)
        return s;
    int64_t version = 0, source_version = 0;
    s = ag_store_ws_read_point_model(db, w->o.model, "", &w->points, &version, err);
    if (s == AG_OK && version != w->o.base)
        s = ag_error_set(err, AG_ERR_STALE, (long)version,
                         "model %lld is at version %lld, not %lld", (long long)w->o.model,
                         (long long)version, (long long)w->o.base);
    int64_t src = from && from->model != w->o.model ? from->model : 0;
    if (s == AG_OK && src)
        s = ag_store_ws_read_point_model(db, src, "source_model", &w->points_source,
                                         &source_version, err);
    ag_pointclouds_read_end(db);
    if (s != AG_OK)
        return s;
    w->source_version = source_version;
    *pm = w->points;
    *source = w->points_source;
    return AG_OK;
}

/* ---- writing ------------------------------------------------------------------------------ */

/* The model's stats as they are (a point model's state keeps the cloud's figures). */
static ag_status current_stats(ag_db *db, int64_t model, char **stats, ag_error *err)
{
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s != AG_OK)
        return s;
    *stats = strdup(row.stats_json ? row.stats_json : "{}");
    ag_models_row_clear(&row);
    return *stats ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

/* The state st as the model's at version (inside the caller's transaction): a new empty mesh
 * file, the grammar with its tree and summary, the terminals. */
static ag_status put_points_state(ag_db *db, int64_t model, int64_t version,
                                  const ag_points_state *st, const char *summary, ag_error *err)
{
    ag_mesh *empty = ag_mesh_create();
    uint8_t *mesh = NULL;
    size_t mesh_len = 0;
    char *stats = NULL, *tree_text = NULL;
    json_t *tree = ag_model_tree_served(st->pm->em);
    if (tree)
        ag_points_summary_shift_tree(tree, st->pm->offset);
    char *served = tree ? json_dumps(tree, JSON_COMPACT | JSON_REAL_PRECISION(12)) : NULL;
    json_decref(tree);
    /* with what gives a reload this numbering (app/model_kept.h) */
    tree_text = served ? ag_model_kept_join(served, st->pm->em) : NULL;
    free(served);
    ag_status s = empty && tree_text ? ag_meshblob_encode(empty, &mesh, &mesh_len) : AG_ERR_NOMEM;
    ag_mesh_free(empty);
    if (s != AG_OK)
        s = ag_error_set(err, s, 0, "out of memory describing the point model");
    if (s == AG_OK)
        s = current_stats(db, model, &stats, err);
    if (s == AG_OK)
        s = ag__store_ws_put_grammar(db, model, version, mesh, mesh_len, stats, st->text,
                                     st->text_len, tree_text, summary, err);
    for (size_t i = 0; s == AG_OK && i < st->terms.n; i++)
        s = ag_grammars_put_terminal(db, model, st->terms.path[i], st->terms.obj[i],
                                     st->terms.len[i], err);
    free(mesh);
    free(stats);
    free(tree_text);
    return s;
}

/* The op logged: the proceduralization's figures, or the client's op with the edit's report. */
static json_t *logged_op(const ag_store_ws *w, const ag_points_state *st,
                         const ag_points_outcome *proc, const ag_edit_outcome *edit)
{
    if (proc)
        return json_pack("{s:s, s:s, s:I, s:I, s:I, s:I}", "kind", "proceduralize", "input",
                         "pointcloud", "rules", (json_int_t)st->pm->em->proc->grammar->nrules,
                         "terminals", (json_int_t)st->pm->nterminals, "placements",
                         (json_int_t)st->pm->nplacements, "patterns",
                         (json_int_t)st->pm->em->proc->tree->npatterns);
    json_t *body = json_deep_copy(w->o.op);
    if (!edit->op) /* a grammar text edit: logged as it came */
        return body;
    json_t *report = ag_edit_op_json_report(&edit->report);
    if (!body || !report) {
        json_decref(body);
        json_decref(report);
        return NULL;
    }
    json_object_set_new(report, "edit_ms", json_real(edit->edit_ms));
    json_object_set_new(report, "placements", json_integer((json_int_t)st->pm->nplacements));
    if (w->source_version) /* the version of the source model whose nodes were copied */
        json_object_set_new(report, "source_version", json_integer((json_int_t)w->source_version));
    json_object_set_new(body, "report", report);
    return body;
}

ag_status ag__store_ws_save_points(ag_workspace *ws, ag_points_state *st,
                                   const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                   ag_error *err)
{
    ag_store_ws *w = (ag_store_ws *)ws;
    /* an edit's state numbered as the model it edited: the nodes it left alone keep their ids
     * (issue 14 §4), and the tree kept with the state gives them back on a reload */
    ag_status s = AG_OK;
    if (edit && edit->op && w->points) {
        ag_edit_op local = ag_usecase_points_local_op(w->points, edit->op);
        s = ag_pointedit_keep_ids(st->pm, w->points, &local, w->points_source, err);
    }
    if (s != AG_OK) {
        ag_points_state_clear(st);
        return s;
    }
    json_t *summary_json = proc ? ag_points_summary_proc(st, proc, NULL)
                                : edit ? ag_points_summary_edit(st, edit) : NULL;
    char *summary = summary_json ? json_dumps(summary_json, JSON_COMPACT | JSON_PRESERVE_ORDER |
                                                                JSON_REAL_PRECISION(10))
                                 : NULL;
    json_decref(summary_json);
    json_t *body = logged_op(w, st, proc, edit);
    s = summary && body ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_seq_txn t;
    int dup = 0;
    /* a proceduralization is the job's (no client id); an edit is the client's op */
    if (s == AG_OK)
        s = ag__store_ws_begin(w, proc ? "proceduralized" : "edited", !proc, &t, &dup, err);
    if (s == AG_OK && !dup) {
        /* the states around the change, so undo and restore come back to either side */
        s = ag_states_keep(t.db, w->o.model, t.version - 1, err);
        if (s == AG_OK)
            s = put_points_state(t.db, w->o.model, t.version, st, summary, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, w->o.model, t.version, err);
        /* what the earlier runs and edits stored and no version names any more goes */
        if (s == AG_OK)
            s = ag_pointclouds_release_terminals(t.db, w->o.model, NULL, err);
        s = ag__store_ws_commit(w, &t, s, AG__STORE_WS_LINKS_GRAMMAR, body, err);
    }
    json_decref(body);
    free(summary);
    ag_points_state_clear(st);
    return s;
}

/* ---- live drag ------------------------------------------------------------------------------ */

/* The point model a model's edit session keeps for drags, with the grammar text and stored
 * tree it was read from: a text names its terminals by their content, so the same text is the
 * same model, and the same tree numbers it the same. */
typedef struct {
    char *text, *tree;
    size_t len;
    ag_pointmodel *pm;
} kept_points;

static void kept_points_free(void *p)
{
    kept_points *k = p;
    if (!k)
        return;
    free(k->text);
    free(k->tree);
    ag_pointmodel_free(k->pm);
    free(k);
}

/* The model's point model at its current grammar (from the held state when it is that one),
 * and its version. */
static ag_status drag_model(const ag_store_env *env, int64_t model, ag_edit_state *held,
                            kept_points **out, int64_t *version, ag_error *err)
{
    ag_grammar_row g;
    ag_status s = ag_grammars_current(env->db, model, 1, &g, err);
    if (s == AG_ERR_NOT_FOUND) /* not proceduralized, or no such model: the reader says which */
        return ag_store_ws_read_point_model(env->db, model, "", &(ag_pointmodel *){NULL}, version,
                                            err);
    if (s != AG_OK)
        return s;
    *version = g.model_version;
    kept_points *k = held->points;
    if (k && k->len == g.text_len && !memcmp(k->text, g.text, g.text_len) &&
        !strcmp(k->tree ? k->tree : "", g.tree_json ? g.tree_json : "")) {
        ag_grammars_row_clear(&g);
        *out = k;
        return AG_OK;
    }
    if (!(k = calloc(1, sizeof *k))) {
        ag_grammars_row_clear(&g);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    k->text = g.text;
    k->len = g.text_len;
    k->tree = g.tree_json;
    g.text = NULL;
    g.tree_json = NULL;
    ag_grammars_row_clear(&g);
    int64_t v = 0;
    if ((s = ag_store_ws_read_point_model(env->db, model, "", &k->pm, &v, err)) != AG_OK) {
        kept_points_free(k);
        return s;
    }
    /* the held state keeps it for the next drag (freed with the state) */
    if (held->points_free)
        held->points_free(held->points);
    held->points = k;
    held->points_free = kept_points_free;
    *out = k;
    return AG_OK;
}

ag_status ag_store_ws_points_preview(const ag_store_env *env, int64_t model, int64_t base,
                                     const ag_edit_op *op, json_t **boxes, double *solve_ms,
                                     ag_error *err)
{
    *boxes = NULL;
    *solve_ms = 0;
    /* held, so a preview waits for an edit of the model being committed, and the model kept
     * is used by one drag at a time */
    ag_edit_state *held = NULL;
    ag_status s = ag_edit_session_hold(env->sessions, model, &held, err);
    if (s != AG_OK)
        return s;
    int64_t version = 0;
    kept_points *k = NULL;
    if ((s = ag_pointclouds_read_begin(env->db, err)) == AG_OK) {
        s = drag_model(env, model, held, &k, &version, err);
        ag_pointclouds_read_end(env->db);
    }
    if (s == AG_OK && version != base)
        s = ag_error_set(err, AG_ERR_STALE, (long)version,
                         "model %lld is at version %lld, not %lld", (long long)model,
                         (long long)version, (long long)base);
    ag_pointmodel *pm = s == AG_OK ? k->pm : NULL;
    if (s == AG_OK)
        s = ag_model_tree_check_node(pm->em, op->node, "node", err);
    ag_box *solved = NULL;
    ag_edit_report rep = {0};
    if (s == AG_OK) {
        ag_edit_op local = ag_usecase_points_local_op(pm, op);
        s = ag_edit_preview(pm->em, &local, &solved, &rep, err);
    }
    if (s == AG_OK && !(*boxes = ag__edit_ops_moved_boxes(pm->em->proc->tree, solved, pm->offset)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK)
        *solve_ms = rep.solve_ms;
    ag_edit_report_clear(&rep);
    free(solved);
    ag_edit_session_release(env->sessions, held);
    return s;
}

/* ---- grammar text edits ------------------------------------------------------------------- */

ag_status ag_store_ws_points_grammar_edit(const ag_store_env *env, int64_t model, int64_t base,
                                          const char *author, const char *cid, const char *text,
                                          size_t len, int64_t *version, ag_error *err, long *col)
{
    *version = 0;
    /* the text names terminals the model keeps (a text edit brings no new point sets, so none
     * is stored again); the state is the text as it came and the model it reads as */
    ag__store_ws_terminals ts = {env->db, model};
    ag_points_state st = {0};
    ag_status s = ag_points_state_read(text, len, ag__store_ws_terminal_lookup, &ts, &st.pm, err, col);
    if (s != AG_OK)
        return s;
    if (!(st.text = malloc(len + 1))) {
        ag_points_state_clear(&st);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    memcpy(st.text, text, len);
    st.text[len] = 0;
    st.text_len = len;
    json_t *op = json_pack("{s:s, s:I}", "kind", "grammar", "bytes", (json_int_t)len);
    if (!op) {
        ag_points_state_clear(&st);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){
                             .env = *env, .model = model, .base = base, .author = author,
                             .cid = cid, .op = op});
    ag_edit_outcome o = {0};
    s = ag__store_ws_save_points(&w.ws, &st, NULL, &o, err);
    if (s == AG_OK)
        *version = w.version;
    ag_store_ws_end(&w, s);
    json_decref(op);
    return s;
}
