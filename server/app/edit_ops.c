#include "edit_ops.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/edit/edit.h"
#include "../io/edit_op_json.h"
#include "../io/grammar_text.h"
#include "../io/terminals.h"
#include "../store/grammars.h"
#include "../store/ops.h"
#include "../store/states.h"
#include "edit_session.h"
#include "grammar_edit.h"
#include "modelops.h"

static const char *const EDIT_KINDS[] = {"resize", "split", "join", "paste", "remove", NULL};

static int is_edit(const char *kind)
{
    for (const char *const *k = EDIT_KINDS; kind && *k; k++)
        if (strcmp(kind, *k) == 0)
            return 1;
    return 0;
}

int ag_edit_ops_handles(const char *kind)
{
    return kind && (is_edit(kind) || strcmp(kind, "undo") == 0 || strcmp(kind, "redo") == 0 ||
                    strcmp(kind, "restore") == 0);
}

ag_status ag_edit_ops_validate(const json_t *op, ag_error *err)
{
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (is_edit(kind)) {
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
    if (strcmp(kind, "undo") == 0 || strcmp(kind, "redo") == 0) {
        static const char *const allowed[] = {"kind", NULL};
        return ag_modelops_only_members(op, allowed, err);
    }
    static const char *const allowed[] = {"kind", "version", NULL};
    json_t *v = json_object_get(op, "version");
    if (!json_is_integer(v) || json_integer_value(v) < 1)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a restore op needs \"version\", the model version to restore (>= 1)");
    return ag_modelops_only_members(op, allowed, err);
}

/* --- structural edits -------------------------------------------------------------------- */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Served tree ids in the op → the edit state's nodes. */
static ag_status translate(const ag_edit_state *st, ag_edit_op *e, ag_error *err)
{
    ag_status s = AG_OK;
    if (e->kind != AG_EDIT_JOIN && e->kind != AG_EDIT_REMOVE)
        s = ag_edit_session_node(st, e->node, e->kind == AG_EDIT_PASTE ? "target" : "node",
                                 &e->node, err);
    for (size_t i = 0; s == AG_OK && i < e->nnodes; i++) {
        char field[48];
        snprintf(field, sizeof field, "%s[%zu]", e->kind == AG_EDIT_PASTE ? "source" : "nodes",
                 i);
        s = ag_edit_session_node(st, e->nodes[i], field, &e->nodes[i], err);
    }
    return s;
}

static ag_status stale(int64_t model, int64_t base, int64_t current, ag_error *err)
{
    return ag_error_set(err, AG_ERR_STALE, (long)current,
                        "model %lld is at version %lld, not %lld", (long long)model,
                        (long long)current, (long long)base);
}

static ag_status duplicate_of(ag_app *app, int64_t model, const char *author, const char *cid,
                              int64_t *seen, ag_error *err)
{
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    return ag_ops_find_cid(db, model, author, cid, seen, err);
}

/* The model a paste copies from, borrowed read-only (its nodes are ids of its served tree
 * at its current version): the problem names the source_model field. */
static ag_status acquire_source(ag_app *app, int64_t src, ag_edit_state **st, ag_error *err)
{
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_edit_session_acquire(app, src, st, &e);
    if (s == AG_ERR_NOT_FOUND)
        return ag_error_set(err, s, 0, "source_model: there is no model %lld", (long long)src);
    if (s != AG_OK)
        return ag_error_set(err, s, e.element, "source_model: %s", e.text);
    return AG_OK;
}

/* The paste's source nodes (served tree ids of model src) → the source state's nodes. */
static ag_status translate_source(const ag_edit_state *st, int64_t src, ag_edit_op *e,
                                  ag_error *err)
{
    for (size_t i = 0; i < e->nnodes; i++) {
        char field[64];
        snprintf(field, sizeof field, "source[%zu] (of model %lld)", i, (long long)src);
        ag_status s = ag_edit_session_node(st, e->nodes[i], field, &e->nodes[i], err);
        if (s != AG_OK)
            return s;
    }
    return AG_OK;
}

static ag_status apply_edit(ag_app *app, int64_t model, int64_t base, const char *author,
                            const char *cid, const json_t *op, uint64_t origin, int64_t *version,
                            ag_error *err)
{
    ag_edit_op e = {0};
    ag_edit_op_origin from = {0};
    ag_status s = ag_edit_op_json_from_ex(op, &e, &from, err);
    if (s == AG_OK && from.dir)
        s = ag_error_set(err, AG_ERR_INVALID, 0,
                         "source_dir: a folder is for `archgram edit`; the service names the "
                         "model to paste from with source_model");
    if (s != AG_OK) {
        ag_edit_op_clear(&e);
        ag_edit_op_origin_clear(&from);
        return s;
    }
    /* another model as the source: both states are borrowed, the lower model id first, so
     * two pastes between the same models in opposite directions cannot wait on each other */
    int64_t src = from.model != model ? from.model : 0;
    ag_edit_state *st = NULL, *sst = NULL;
    if (src && src < model && (s = acquire_source(app, src, &sst, err)) != AG_OK) {
        ag_edit_op_clear(&e);
        return s;
    }
    if ((s = ag_edit_session_acquire(app, model, &st, err)) != AG_OK) {
        ag_edit_session_release(app, sst);
        ag_edit_op_clear(&e);
        return s;
    }
    if (src && src > model && (s = acquire_source(app, src, &sst, err)) != AG_OK) {
        ag_edit_session_release(app, st);
        ag_edit_op_clear(&e);
        return s;
    }
    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_terminal_set terms = {0};
    ag_grammar_derived d = {0};
    char *text = NULL, *summary = NULL;
    size_t tlen = 0;
    json_t *body = NULL;
    double t0 = now_ms();
    if (base != st->version) {
        s = stale(model, base, st->version, err);
        goto done;
    }
    if (src) {
        /* the target alone is this model's; the source nodes are the other model's */
        ag_edit_op dst = e;
        dst.nnodes = 0;
        if ((s = translate(st, &dst, err)) != AG_OK ||
            (s = translate_source(sst, src, &e, err)) != AG_OK)
            goto done;
        e.node = dst.node;
        e.source = sst->em->proc;
    } else if ((s = translate(st, &e, err)) != AG_OK) {
        goto done;
    }
    /* the session maps GET …/tree ids onto the kept model itself: no read-back needed */
    if ((s = ag_edit_apply_ex(st->em, &e, 0, &out, &rep, err)) != AG_OK ||
        (s = ag_terminals_collect(out->proc->grammar, &terms, err)) != AG_OK ||
        (s = ag_grammar_text_print(out->proc->grammar, &text, &tlen, err)) != AG_OK)
        goto done;
    long col = 0;
    ag_error de;
    ag_error_clear(&de);
    if ((s = ag_grammar_edit_derive(text, tlen, ag_terminals_set_lookup, &terms, &d, &de, &col)) != AG_OK) {
        s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                         "the edited grammar does not read back (line %ld, column %ld): %s",
                         de.element, col, de.text);
        goto done;
    }
    double edit_ms = now_ms() - t0;
    json_t *report = ag_edit_op_json_report(&rep);
    body = json_deep_copy(op);
    if (report)
        json_object_set_new(report, "edit_ms", json_real(edit_ms));
    if (report && src) /* the version of the source model whose nodes were copied */
        json_object_set_new(report, "source_version", json_integer((json_int_t)sst->version));
    if (!report || !body || json_object_set_new(body, "report", report) != 0) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    json_t *sj = json_pack("{s:s, s:s, s:I, s:I, s:I, s:I, s:I}", "source", "edit", "op",
                           json_string_value(json_object_get(op, "kind")), "rules",
                           (json_int_t)out->proc->grammar->nrules, "terminals",
                           (json_int_t)out->proc->grammar->nterminals, "grammar_bytes",
                           (json_int_t)tlen, "triangles", (json_int_t)d.mesh->ntris,
                           "components", (json_int_t)d.mesh->ncomponents);
    summary = sj ? json_dumps(sj, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(sj);
    if (!summary) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }

    ag_modelops_txn t;
    if ((s = ag_modelops_server_begin(app, model, base, &t, err)) != AG_OK)
        goto done;
    t.origin = origin;
    s = ag_states_keep(t.db, model, t.version - 1, err);
    if (s == AG_OK)
        s = ag_grammar_edit_store(t.db, model, t.version, &d, text, tlen, summary, err);
    for (size_t i = 0; s == AG_OK && i < terms.n; i++)
        s = ag_grammars_put_terminal(t.db, model, terms.path[i], terms.obj[i], terms.len[i], err);
    if (s == AG_OK)
        s = ag_states_keep(t.db, model, t.version, err);
    if (s != AG_OK) {
        ag_modelops_server_abort(&t);
        goto done;
    }
    int64_t v = t.version;
    if ((s = ag_modelops_server_commit(&t, author, cid, body, err)) != AG_OK)
        goto done;
    *version = v;
    /* the next edit starts from this one's model; a failure here only costs a reload */
    ag_error ignored;
    ag_edit_session_replace(st, v, out, d.tree_json, &ignored);
    out = NULL;
done:
    if (s != AG_OK && st && s != AG_ERR_STALE && s != AG_ERR_INVALID && s != AG_ERR_NOT_FOUND &&
        s != AG_ERR_CONFLICT && s != AG_ERR_PARSE && s != AG_ERR_NOT_PROCEDURALIZED)
        ag_edit_session_reset(st); /* an unexpected failure: load afresh next time */
    e.source = NULL;
    ag_edit_session_release(app, sst);
    ag_edit_session_release(app, st);
    ag_edit_model_free(out);
    ag_edit_report_clear(&rep);
    ag_grammar_derived_clear(&d);
    ag_terminals_set_clear(&terms);
    free(text);
    free(summary);
    json_decref(body);
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

static int geometry_kind(const char *kind)
{
    return strcmp(kind, "rename") != 0 && strcmp(kind, "note") != 0;
}

static void walk(void *user, const ag_op_row *op)
{
    history *h = user;
    if (strcmp(op->author, h->author) != 0) {
        if (geometry_kind(op->kind) && op->version > h->after && !h->conflict) {
            h->conflict = op->version;
            snprintf(h->conflict_author, sizeof h->conflict_author, "%s", op->author);
            snprintf(h->conflict_kind, sizeof h->conflict_kind, "%s", op->kind);
        }
        return;
    }
    /* a grammar text edit (PUT …/grammar) is an undo step like a structural edit */
    int edit = is_edit(op->kind) || strcmp(op->kind, "grammar") == 0, undoes = 0, redoes = 0;
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

static ag_status apply_restore(ag_app *app, int64_t model, int64_t base, const char *author,
                               const char *cid, const json_t *op, uint64_t origin,
                               int64_t *version, ag_error *err)
{
    const char *kind = json_string_value(json_object_get(op, "kind"));
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    json_t *body = NULL;
    ag_status s = AG_OK;
    if (strcmp(kind, "restore") == 0)
        body = json_deep_copy(op);
    else
        s = resolve_undo(db, model, author, strcmp(kind, "redo") == 0, &body, err);
    if (s == AG_OK && !body)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s != AG_OK)
        return s;
    int64_t target = json_integer_value(json_object_get(body, "version"));
    /* held so a concurrent edit of this model waits for the restore */
    ag_edit_state *st = NULL;
    if ((s = ag_edit_session_hold(app, model, &st, err)) != AG_OK) {
        json_decref(body);
        return s;
    }
    ag_modelops_txn t;
    ag_state_row row = {0};
    if ((s = ag_modelops_server_begin(app, model, base, &t, err)) == AG_OK) {
        t.origin = origin;
        s = ag_states_get(t.db, model, target, &row, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, model, t.version - 1, err);
        if (s == AG_OK)
            s = ag_states_restore(t.db, model, t.version, &row, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, model, t.version, err);
        int64_t v = t.version;
        if (s == AG_OK) {
            if ((s = ag_modelops_server_commit(&t, author, cid, body, err)) == AG_OK)
                *version = v;
        } else {
            ag_modelops_server_abort(&t);
        }
    }
    if (s == AG_OK)
        ag_edit_session_reset(st); /* loaded again from the restored grammar when edited */
    ag_edit_session_release(app, st);
    ag_states_row_clear(&row);
    json_decref(body);
    return s;
}

ag_status ag_edit_ops_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                            const char *cid, const json_t *op, uint64_t origin, int64_t *version,
                            int *duplicate, ag_error *err)
{
    *version = 0;
    *duplicate = 0;
    int64_t seen = 0;
    ag_status s = duplicate_of(app, model, author, cid, &seen, err);
    if (s != AG_OK)
        return s;
    if (seen) {
        *duplicate = 1;
        *version = seen;
        return AG_OK;
    }
    const char *kind = json_string_value(json_object_get(op, "kind"));
    return is_edit(kind) ? apply_edit(app, model, base, author, cid, op, origin, version, err)
                         : apply_restore(app, model, base, author, cid, op, origin, version, err);
}

/* --- live drag ----------------------------------------------------------------------------- */

ag_status ag_edit_ops_preview(ag_app *app, int64_t model, int64_t base, const json_t *op,
                              json_t **boxes, double *solve_ms, ag_error *err)
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
    ag_edit_state *st = NULL;
    if ((s = ag_edit_session_acquire(app, model, &st, err)) != AG_OK) {
        ag_edit_op_clear(&e);
        return s;
    }
    ag_box *solved = NULL;
    ag_edit_report rep = {0};
    if (base != st->version)
        s = stale(model, base, st->version, err);
    if (s == AG_OK && (s = translate(st, &e, err)) == AG_OK)
        s = ag_edit_preview(st->em, &e, &solved, &rep, err);
    json_t *list = s == AG_OK ? json_array() : NULL;
    if (s == AG_OK && !list)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    const ag_splittree *t = st->em ? st->em->proc->tree : NULL;
    double eps = t ? 1e-9 * fmax(1.0, ag_box_diagonal(&t->nodes[0].box)) : 0;
    for (size_t id = 0; s == AG_OK && id < st->ntree; id++) {
        int32_t n = st->tree_to_node[id];
        if (n < 0)
            continue;
        const ag_box *a = &t->nodes[n].box, *b = &solved[n];
        double d = 0;
        for (int k = 0; k < 3; k++)
            d = fmax(d, fmax(fabs(a->min[k] - b->min[k]), fabs(a->max[k] - b->max[k])));
        if (d <= eps)
            continue;
        json_array_append_new(list, json_pack("{s:I, s:[f,f,f,f,f,f]}", "node", (json_int_t)id,
                                              "box", b->min[0], b->min[1], b->min[2], b->max[0],
                                              b->max[1], b->max[2]));
    }
    if (s == AG_OK) {
        *boxes = list;
        *solve_ms = rep.solve_ms;
    } else {
        json_decref(list);
    }
    ag_edit_session_release(app, st);
    free(solved);
    ag_edit_report_clear(&rep);
    ag_edit_op_clear(&e);
    return s;
}
