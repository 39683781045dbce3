#include "modelops.h"

#include <stdlib.h>
#include <string.h>

#include "../store/models.h"
#include "../store/ops.h"
#include "edit_ops.h"
#include "plan_edit.h"

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

ag_status ag_modelops_validate(const json_t *op, ag_error *err)
{
    if (!json_is_object(op))
        return ag_error_set(err, AG_ERR_INVALID, 0, "an op must be a JSON object");
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (!kind)
        return ag_error_set(err, AG_ERR_INVALID, 0, "an op needs a string \"kind\"");
    if (strcmp(kind, "rename") == 0) {
        static const char *const allowed[] = {"kind", "name", NULL};
        const char *name = json_string_value(json_object_get(op, "name"));
        if (!name)
            return ag_error_set(err, AG_ERR_INVALID, 0, "a rename op needs a string \"name\"");
        ag_status s = ag_models_check_name(name, err);
        return s != AG_OK ? s : ag_modelops_only_members(op, allowed, err);
    }
    if (strcmp(kind, "note") == 0) {
        static const char *const allowed[] = {"kind", "text", NULL};
        const char *text = json_string_value(json_object_get(op, "text"));
        if (!text || !*text)
            return ag_error_set(err, AG_ERR_INVALID, 0, "a note op needs a non-empty \"text\"");
        if (utf8_chars(text) > AG_NOTE_MAX)
            return ag_error_set(err, AG_ERR_INVALID, 0, "a note holds at most %d characters",
                                AG_NOTE_MAX);
        return ag_modelops_only_members(op, allowed, err);
    }
    if (ag_plan_edit_handles(kind))
        return ag_plan_edit_validate(op, err);
    if (ag_edit_ops_handles(kind))
        return ag_edit_ops_validate(op, err);
    if (strcmp(kind, "proceduralize") == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "\"proceduralize\" ops are made by the server: POST "
                            "/api/v1/models/{id}/proceduralize");
    if (strcmp(kind, "grammar") == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "\"grammar\" ops are made by the server: PUT "
                            "/api/v1/models/{id}/grammar");
    return ag_error_set(err, AG_ERR_INVALID, 0, "unknown op kind \"%s\"", kind);
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

static ag_status apply_effect(ag_db *db, int64_t model, const json_t *op, ag_error *err)
{
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (strcmp(kind, "rename") == 0)
        return ag_models_set_name(db, model, json_string_value(json_object_get(op, "name")), err);
    if (ag_plan_edit_handles(kind))
        return ag_plan_edit_apply(db, model, op, err); /* re-extrudes what the op touches */
    return AG_OK; /* a note only lives in the log */
}

ag_status ag_modelops_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                            const char *cid, const json_t *op, uint64_t origin,
                            int64_t *version, int *duplicate, ag_error *err)
{
    *duplicate = 0;
    *version = 0;
    ag_status s;
    if ((s = ag_modelops_check_token("the client id (cid)", cid, err)) != AG_OK ||
        (s = ag_models_check_name(author, err)) != AG_OK ||
        (s = ag_modelops_validate(op, err)) != AG_OK)
        return s;
    /* structural edits, undo, redo, restore: computed off the op lock, then a server op */
    if (ag_edit_ops_handles(json_string_value(json_object_get(op, "kind"))))
        return ag_edit_ops_apply(app, model, base, author, cid, op, origin, version, duplicate,
                                 err);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    char *body = json_dumps(op, JSON_COMPACT | JSON_SORT_KEYS);
    if (!body)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");

    ag__app_lock_ops(app);
    if ((s = ag_db_begin(db, err)) != AG_OK)
        goto out;
    int64_t seen = 0;
    s = ag_ops_find_cid(db, model, author, cid, &seen, err);
    if (s == AG_OK && seen) {
        ag_db_rollback(db);
        *duplicate = 1;
        *version = seen;
        goto out;
    }
    if (s == AG_OK)
        s = ag_models_bump_version(db, model, base, version, err);
    if (s == AG_OK)
        s = apply_effect(db, model, op, err);
    if (s == AG_OK) {
        ag_op_row row = {.model = model,
                         .version = *version,
                         .author = author,
                         .cid = cid,
                         .kind = json_string_value(json_object_get(op, "kind")),
                         .body_json = body};
        s = ag_ops_insert(db, &row, err);
    }
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    if (s == AG_OK) {
        ag_event ev = {.kind = AG_EVENT_OP,
                       .model = model,
                       .version = *version,
                       .author = author,
                       .cid = cid,
                       .json = body,
                       .origin = origin};
        ag_events_publish(ag_app_events(app), &ev);
    }
out:
    ag__app_unlock_ops(app);
    free(body);
    return s;
}

ag_status ag_modelops_delete(ag_app *app, int64_t model, int64_t version, ag_error *err)
{
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag__app_lock_ops(app);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK) {
        s = ag_models_delete(db, model, version, err);
        s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    }
    if (s == AG_OK) {
        ag_event ev = {.kind = AG_EVENT_MODEL_GONE, .model = model};
        ag_events_publish(ag_app_events(app), &ev);
    }
    ag__app_unlock_ops(app);
    return s;
}

ag_status ag_modelops_server_begin(ag_app *app, int64_t model, int64_t base, ag_modelops_txn *t,
                                   ag_error *err)
{
    memset(t, 0, sizeof *t);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag__app_lock_ops(app);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK && (s = ag_models_bump_version(db, model, base, &t->version, err)) != AG_OK)
        ag_db_rollback(db);
    if (s != AG_OK) {
        ag__app_unlock_ops(app);
        return s;
    }
    t->app = app;
    t->db = db;
    t->model = model;
    return AG_OK;
}

void ag_modelops_server_abort(ag_modelops_txn *t)
{
    if (!t->app)
        return;
    ag_db_rollback(t->db);
    ag__app_unlock_ops(t->app);
    t->app = NULL;
}

ag_status ag_modelops_server_commit(ag_modelops_txn *t, const char *author, const char *cid,
                                   const json_t *op, ag_error *err)
{
    if (!t->app)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no server op under way");
    char *body = json_dumps(op, JSON_COMPACT | JSON_SORT_KEYS);
    ag_status s = body ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (s == AG_OK) {
        ag_op_row row = {.model = t->model,
                         .version = t->version,
                         .author = author,
                         .cid = cid,
                         .kind = kind ? kind : "",
                         .body_json = body};
        s = ag_ops_insert(t->db, &row, err);
    }
    s = s == AG_OK ? ag_db_commit(t->db, err) : (ag_db_rollback(t->db), s);
    if (s == AG_OK) {
        ag_event ev = {.kind = AG_EVENT_OP,
                       .model = t->model,
                       .version = t->version,
                       .author = author,
                       .cid = cid,
                       .json = body,
                       .origin = t->origin};
        ag_events_publish(ag_app_events(t->app), &ev);
    }
    ag__app_unlock_ops(t->app);
    t->app = NULL;
    free(body);
    return s;
}
