#include "modelops.h"

#include <stdlib.h>
#include <string.h>

#include "../store/models.h"
#include "../store/ops.h"
#include "rebase.h"

#define AG_NOTE_MAX 4000

static size_t utf8_chars(const char *s)
{
    size_t n = 0;
    for (; *s; s++)
        if (((unsigned char)*s & 0xc0) != 0x80)
            n++;
    return n;
}

ag_status ag_modelops_only_members(const json_t *op, const char *const *allowed, ag_error *err)
{
    const char *key;
    json_t *value;
    json_object_foreach((json_t *)op, key, value) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++)
            ok |= strcmp(key, *a) == 0;
        if (!ok)
            return ag_error_set(err, AG_ERR_INVALID, 0, "op member \"%s\" is not known", key);
    }
    return AG_OK;
}

ag_status ag__modelops_rename_validate(const json_t *op, ag_error *err)
{
    static const char *const allowed[] = {"kind", "name", NULL};
    const char *name = json_string_value(json_object_get(op, "name"));
    if (!name)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a rename op needs a string \"name\"");
    ag_status s = ag_models_check_name(name, err);
    return s != AG_OK ? s : ag_modelops_only_members(op, allowed, err);
}

ag_status ag__modelops_rename_effect(ag_db *db, int64_t model, const json_t *op, ag_error *err)
{
    return ag_models_set_name(db, model, json_string_value(json_object_get(op, "name")), err);
}

ag_status ag__modelops_note_validate(const json_t *op, ag_error *err)
{
    static const char *const allowed[] = {"kind", "text", NULL};
    const char *text = json_string_value(json_object_get(op, "text"));
    if (!text || !*text)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a note op needs a non-empty \"text\"");
    if (utf8_chars(text) > AG_NOTE_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a note holds at most %d characters",
                            AG_NOTE_MAX);
    return ag_modelops_only_members(op, allowed, err);
}

ag_status ag_modelops_validate(const json_t *op, ag_error *err)
{
    const ag_op_kind *row;
    ag_status s = ag_optable_lookup(op, &row, err);
    if (s != AG_OK)
        return s;
    if (!(row->flags & AG_OP_CLIENT))
        return ag_error_set(err, AG_ERR_INVALID, 0, "\"%s\" ops are made by the server: %s",
                            row->kind, row->made_by ? row->made_by : "no client sends them");
    return row->validate(op, err);
}

ag_status ag_modelops_check_token(const char *what, const char *value, ag_error *err)
{
    if (!value || !*value)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s is required", what);
    size_t n = strlen(value);
    if (n > 100)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s is longer than 100 characters", what);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)value[i] < 0x20 || (unsigned char)value[i] > 0x7e)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "%s may hold printable ASCII characters only", what);
    return AG_OK;
}

/* The op at rq->base, once. */
static ag_status apply_once(const ag_store_env *env, const ag_op_request *rq,
                            const ag_op_kind *row, int64_t *version, int *duplicate,
                            ag_error *err)
{
    /* structural kinds compute off the commit lock, then commit as one change */
    if (row->run)
        return row->run(env, rq, version, duplicate, err);
    ag_seq_txn t;
    int64_t seen = 0;
    ag_status s;
    if ((s = ag_sequencer_begin(env->seq, env->db, rq->model, rq->base, rq->author, rq->cid, &t,
                                &seen, err)) != AG_OK)
        return s;
    if (seen) {
        *duplicate = 1;
        *version = seen;
        return AG_OK;
    }
    t.origin = rq->origin;
    if (row->effect && (s = row->effect(t.db, rq->model, rq->op, err)) != AG_OK) {
        ag_sequencer_abort(&t);
        return s;
    }
    int64_t v = t.version;
    if ((s = ag_sequencer_commit(&t, rq->author, rq->cid, rq->op, err)) == AG_OK)
        *version = v;
    return s;
}

/* A live op may meet ops committed between its rebase and its own commit: rebased again, a
 * few times. */
#define AG_REBASE_ATTEMPTS 8

ag_status ag_modelops_apply(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
                            int *duplicate, ag_error *err)
{
    *duplicate = 0;
    *version = 0;
    ag_status s;
    if ((s = ag_modelops_check_token("the client id (cid)", rq->cid, err)) != AG_OK ||
        (s = ag_models_check_name(rq->author, err)) != AG_OK ||
        (s = ag_modelops_validate(rq->op, err)) != AG_OK)
        return s;
    const ag_op_kind *row = ag_optable_find(json_string_value(json_object_get(rq->op, "kind")));
    if (!rq->rebase)
        return apply_once(env, rq, row, version, duplicate, err);
    for (int attempt = 0;; attempt++) {
        /* a retry of an op applied before is answered as such, never rebased again */
        int64_t seen = 0, current = 0;
        if ((s = ag_ops_find_cid(env->db, rq->model, rq->author, rq->cid, &seen, err)) != AG_OK)
            return s;
        if (seen) {
            *duplicate = 1;
            *version = seen;
            return AG_OK;
        }
        ag_model_row m;
        if ((s = ag_models_get(env->db, rq->model, &m, err)) != AG_OK)
            return s;
        current = m.version;
        ag_models_row_clear(&m);
        ag_op_request at = *rq;
        json_t *rewritten = NULL;
        if ((s = ag_rebase_op(env, rq, row, current, &at.base, &rewritten, err)) != AG_OK)
            return s;
        if (rewritten)
            at.op = rewritten;
        s = apply_once(env, &at, row, version, duplicate, err);
        json_decref(rewritten);
        if (s != AG_ERR_STALE || attempt + 1 >= AG_REBASE_ATTEMPTS)
            return s;
        /* an op came in between: rebase again onto the newer version */
    }
}