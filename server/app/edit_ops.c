#include "edit_ops.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/edit/edit.h"
#include "../io/edit_op_json.h"
#include "../store/ops.h"
#include "../store/states.h"
#include "cloud_pipeline.h"
#include "edit_session.h"
#include "model_tree.h"
#include "modelops.h"
#include "store_ws.h"
#include "usecase_edit.h"
#include "usecase_points.h"

ag_status ag_edit_ops_validate(const json_t *op, ag_error *err)
{
    ag_edit_op e = {0};
    ag_edit_op_origin o = {0};
    ag_status s = ag_edit_op_json_from_ex(op, &e, &o, err);
    if (s == AG_OK && o.dir)
        s = ag_error_set(err, AG_ERR_INVALID, 0,
                         "source_dir: a folder is for `archgram edit`; the service names "
                         "the model to paste from with source_model");
    ag_edit_op_clear(&e);
    ag_edit_op_origin_clear(&o);
    return s;
}

ag_status ag_edit_ops_validate_history(const json_t *op, ag_error *err)
{
    static const char *const allowed[] = {"kind", NULL};
    return ag_modelops_only_members(op, allowed, err);
}

ag_status ag_edit_ops_validate_restore(const json_t *op, ag_error *err)
{
    static const char *const allowed[] = {"kind", "version", NULL};
    json_t *v = json_object_get(op, "version");
    if (!json_is_integer(v) || json_integer_value(v) < 1)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a restore op needs \"version\", the model version to restore (>= 1)");
    return ag_modelops_only_members(op, allowed, err);
}

/* --- structural edits -------------------------------------------------------------------- */

/* What core may spend on one edit: the service's limits, the op's time and stop flag. */
static ag_edit_budget edit_budget(const ag_store_env *env, ag_task_budget *tb)
{
    ag_work_limits l = ag_work_limits_resolved(env->limits);
    return (ag_edit_budget){.max_triangles = l.max_triangles,
                            .max_components = l.max_nodes,
                            .cancelled = tb ? ag_task_budget_exhausted : NULL,
                            .user = tb};
}

ag_status ag_edit_ops_run_edit(const ag_store_env *env, const ag_op_request *rq,
                               int64_t *version, int *duplicate, ag_error *err)
{
    *version = 0;
    *duplicate = 0;
    /* a retry is answered before anything is computed */
    int64_t seen = 0;
    ag_status s = ag_ops_find_cid(env->db, rq->model, rq->author, rq->cid, &seen, err);
    if (s != AG_OK)
        return s;
    if (seen) {
        *duplicate = 1;
        *version = seen;
        return AG_OK;
    }
    ag_edit_op e = {0};
    ag_edit_op_origin from = {0};
    if ((s = ag_edit_op_json_from_ex(rq->op, &e, &from, err)) != AG_OK) {
        ag_edit_op_origin_clear(&from);
        return s;
    }
    ag_edit_budget budget = edit_budget(env, rq->budget);
    e.budget = &budget;
    ag_store_ws w;
    ag_store_ws_init_op(&w, env, rq);
    ag_usecase_edit_result r;
    ag_usecase_points_edit_result pr;
    /* a proceduralized point cloud is edited as a point model, keeping its density */
    int cloud = 0;
    s = ag_cloud_pipeline_is_cloud(env->db, rq->model, &cloud, err);
    if (s == AG_OK && cloud)
        s = ag_usecase_points_edit_run(&w.ws, &(ag_usecase_points_edit_params){&e, &from}, &pr,
                                       err);
    else if (s == AG_OK)
        s = ag_usecase_edit_run(&w.ws, &(ag_usecase_edit_params){&e, &from}, &r, err);
    s = ag_task_budget_explain(rq->budget, s, "the edit", err);
    ag_store_ws_end(&w, s);
    if (s == AG_OK) {
        *version = w.version;
        *duplicate = w.duplicate;
        ag_edit_report_clear(cloud ? &pr.report : &r.report);
    }
    ag_edit_op_clear(&e);
    ag_edit_op_origin_clear(&from);
    return s;
}

/* --- undo, redo, restore ------------------------------------------------------------------ */

#define STACK_MAX 4096

typedef struct {
    const char *author;
    int64_t undo[STACK_MAX], redo[STACK_MAX]; /* versions of edits / of the undos */
    int64_t redo_target[STACK_MAX];           /* the edit each undo undid */
    size_t nundo, nredo;
    /* the first geometry op by someone else after `after` */
    int64_t after, conflict;
    char conflict_author[801], conflict_kind[32];
} history;

static void walk(void *user, const ag_op_row *op)
{
    history *h = user;
    const ag_op_kind *row = ag_optable_find(op->kind);
    unsigned flags = row ? row->flags : AG_OP_GEOMETRY; /* a kind unknown today: assume it changed things */
    if (strcmp(op->author, h->author) != 0) {
        if ((flags & AG_OP_GEOMETRY) && op->version > h->after && !h->conflict) {
            h->conflict = op->version;
            snprintf(h->conflict_author, sizeof h->conflict_author, "%s", op->author);
            snprintf(h->conflict_kind, sizeof h->conflict_kind, "%s", op->kind);
        }
        return;
    }
    int edit = (flags & AG_OP_UNDOABLE) != 0, undoes = 0, redoes = 0;
    if (strcmp(op->kind, "restore") == 0) {
        json_t *b = json_loads(op->body_json, 0, NULL);
        undoes = json_is_integer(json_object_get(b, "undoes"));
        redoes = json_is_integer(json_object_get(b, "redoes"));
        json_decref(b);
        edit = !undoes && !redoes; /* a restore someone asked for is an edit of its own */
    }
    if (edit) {
        if (h->nundo == STACK_MAX) {
            memmove(h->undo, h->undo + 1, (STACK_MAX - 1) * sizeof *h->undo);
            h->nundo--;
        }
        h->undo[h->nundo++] = op->version;
        h->nredo = 0;
    } else if (undoes && h->nundo) {
        h->redo_target[h->nredo] = h->undo[--h->nundo];
        h->redo[h->nredo++] = op->version;
    } else if (redoes && h->nredo) {
        h->undo[h->nundo++] = h->redo_target[--h->nredo];
    }
}

/* The restore op an undo or redo becomes, or a problem. */
static ag_status resolve_undo(ag_db *db, int64_t model, const char *author, int redo,
                              json_t **restore, ag_error *err)
{
    *restore = NULL;
    history *h = calloc(1, sizeof *h);
    if (!h)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    h->author = author;
    h->after = INT64_MAX;
    ag_status s = ag_ops_each_since(db, model, 0, 0, walk, h, err);
    if (s != AG_OK) {
        free(h);
        return s;
    }
    int64_t target, since;
    if (!redo) {
        if (!h->nundo) {
            free(h);
            return ag_error_set(err, AG_ERR_UNDO_CONFLICT, 0,
                                "%s has no edit of model %lld left to undo",
                                author, (long long)model);
        }
        target = h->undo[h->nundo - 1];
        since = target;
    } else {
        if (!h->nredo) {
            free(h);
            return ag_error_set(err, AG_ERR_UNDO_CONFLICT, 0,
                                "%s has no undone edit of model %lld to redo",
                                author, (long long)model);
        }
        target = h->redo_target[h->nredo - 1];
        since = h->redo[h->nredo - 1];
    }
    /* a second pass finds the first geometry op by someone else after `since` */
    h->after = since;
    h->conflict = 0;
    h->nundo = h->nredo = 0;
    if ((s = ag_ops_each_since(db, model, since, 0, walk, h, err)) == AG_OK && h->conflict)
        s = ag_error_set(err, AG_ERR_UNDO_CONFLICT, h->conflict,
                         "the %s op of version %lld by %s came after the edit of "
                         "version %lld; restore a version instead",
                         h->conflict_kind, (long long)h->conflict, h->conflict_author,
                         (long long)target);
    if (s == AG_OK) {
        *restore = redo ? json_pack("{s:s, s:I, s:I}", "kind", "restore", "version",
                                    (json_int_t)target, "redoes", (json_int_t)target)
                        : json_pack("{s:s, s:I, s:I}", "kind", "restore", "version",
                                    (json_int_t)(target - 1), "undoes", (json_int_t)target);
        if (!*restore)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    free(h);
    return s;
}

ag_status ag_edit_ops_run_restore(const ag_store_env *env, const ag_op_request *rq,
                                  int64_t *version, int *duplicate, ag_error *err)
{
    *version = 0;
    *duplicate = 0;
    /* a retried undo is answered before it is resolved again (it would undo the next edit) */
    int64_t seen = 0;
    ag_status s = ag_ops_find_cid(env->db, rq->model, rq->author, rq->cid, &seen, err);
    if (s != AG_OK || seen) {
        *duplicate = seen != 0;
        *version = seen;
        return s;
    }
    const char *kind = json_string_value(json_object_get(rq->op, "kind"));
    json_t *body = NULL;
    if (strcmp(kind, "restore") == 0)
        body = json_deep_copy(rq->op);
    else
        s = resolve_undo(env->db, rq->model, rq->author, strcmp(kind, "redo") == 0, &body, err);
    if (s == AG_OK && !body)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s != AG_OK)
        return s;
    int64_t target = json_integer_value(json_object_get(body, "version"));
    /* held so a concurrent edit of this model waits for the restore */
    ag_edit_state *st = NULL;
    if ((s = ag_edit_session_hold(env->sessions, rq->model, &st, err)) != AG_OK) {
        json_decref(body);
        return s;
    }
    ag_seq_txn t;
    ag_state_row row = {0};
    if ((s = ag_sequencer_begin(env->seq, env->db, rq->model, rq->base, rq->author, rq->cid, &t,
                                &seen, err)) == AG_OK && seen) {
        *duplicate = 1;
        *version = seen;
    } else if (s == AG_OK) {
        t.origin = rq->origin;
        s = ag_states_get(t.db, rq->model, target, &row, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, rq->model, t.version - 1, err);
        if (s == AG_OK)
            s = ag_states_restore(t.db, rq->model, t.version, &row, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, rq->model, t.version, err);
        int64_t v = t.version;
        if (s == AG_OK) {
            if ((s = ag_sequencer_commit(&t, rq->author, rq->cid, body, err)) == AG_OK)
                *version = v;
        } else {
            ag_sequencer_abort(&t);
        }
        if (s == AG_OK)
            ag_edit_session_reset(st); /* loaded again from the restored mesh when edited */
    }
    ag_edit_session_release(env->sessions, st);
    ag_states_row_clear(&row);
    json_decref(body);
    return s;
}

/* --- live drag ----------------------------------------------------------------------------- */

json_t *ag__edit_ops_moved_boxes(const ag_splittree *t, const ag_box *solved,
                                 const double offset[3])
{
    json_t *list = json_array();
    double eps = 1e-9 * fmax(1.0, ag_box_diagonal(&t->nodes[0].box));
    for (size_t n = 0; list && n < t->nnodes; n++) {
        if (t->nodes[n].kind == AG_NODE_DEAD)
            continue;
        const ag_box *a = &t->nodes[n].box, *b = &solved[n];
        double d = 0;
        for (int k = 0; k < 3; k++)
            d = fmax(d, fmax(fabs(a->min[k] - b->min[k]), fabs(a->max[k] - b->max[k])));
        if (d <= eps)
            continue;
        json_array_append_new(list, json_pack("{s:I, s:[f,f,f,f,f,f]}", "node", (json_int_t)n,
                                              "box", b->min[0] + offset[0], b->min[1] + offset[1],
                                              b->min[2] + offset[2], b->max[0] + offset[0],
                                              b->max[1] + offset[1], b->max[2] + offset[2]));
    }
    return list;
}

ag_status ag_edit_ops_preview(const ag_store_env *env, int64_t model, int64_t base,
                              const json_t *op, json_t **boxes, double *solve_ms, ag_error *err)
{
    *boxes = NULL;
    *solve_ms = 0;
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (!kind || strcmp(kind, "resize") != 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a preview carries a resize op");
    ag_edit_op e = {0};
    ag_status s = ag_edit_op_json_from(op, &e, err);
    if (s != AG_OK)
        return s;
    int cloud = 0;
    s = ag_cloud_pipeline_is_cloud(env->db, model, &cloud, err);
    if (s == AG_OK && cloud) { /* boxes in the cloud's coordinates: app/store_ws_points.c */
        s = ag_store_ws_points_preview(env, model, base, &e, boxes, solve_ms, err);
        ag_edit_op_clear(&e);
        return s;
    }
    ag_box *solved = NULL;
    ag_edit_report rep = {0};
    ag_edit_state *st = NULL;
    if (s == AG_OK &&
        (s = ag_edit_session_acquire(env->sessions, env->db, model, &st, err)) == AG_OK) {
        if (base != st->version)
            s = ag_error_set(err, AG_ERR_STALE, (long)st->version,
                             "model %lld is at version %lld, not %lld", (long long)model,
                             (long long)st->version, (long long)base);
        if (s == AG_OK && (s = ag_model_tree_check_node(st->em, e.node, "node", err)) == AG_OK)
            s = ag_edit_preview(st->em, &e, &solved, &rep, err);
    }
    static const double origin[3] = {0, 0, 0};
    json_t *list = s == AG_OK ? ag__edit_ops_moved_boxes(st->em->proc->tree, solved, origin) : NULL;
    if (s == AG_OK && !list)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK) {
        *boxes = list;
        *solve_ms = rep.solve_ms;
    }
    if (st)
        ag_edit_session_release(env->sessions, st);
    free(solved);
    ag_edit_report_clear(&rep);
    ag_edit_op_clear(&e);
    return s;
}
