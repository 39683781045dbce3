#include "sharing.h"

#include <stdlib.h>

#include "../store/members.h"
#include "../store/models.h"
#include "../store/users.h"
#include "auth.h"

#define MEMBERS_MAX 10000

static ag_status read_doc(ag_db *db, int64_t model, json_t **doc, ag_error *err)
{
    *doc = NULL;
    ag_model_role unused;
    int public_read = 0;
    ag_status s = ag_members_access(db, model, 0, &unused, &public_read, err);
    ag_member_row *rows = NULL;
    size_t n = 0;
    if (s == AG_OK)
        s = ag_members_list(db, model, MEMBERS_MAX, &rows, &n, err);
    if (s != AG_OK)
        return s;
    json_t *items = json_array();
    for (size_t i = 0; items && i < n; i++)
        json_array_append_new(items, json_pack("{s:s, s:s}", "user", rows[i].name, "role",
                                               ag_members_role_name(rows[i].role)));
    free(rows);
    *doc = items ? json_pack("{s:I, s:b, s:o}", "model", (json_int_t)model, "public_read",
                             public_read, "items", items)
                 : NULL;
    return *doc ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

ag_status ag_sharing_get(ag_app *app, int64_t model, json_t **doc, ag_error *err)
{
    *doc = NULL;
    ag_db *db = ag_app_db(app, err);
    return db ? read_doc(db, model, doc, err) : err ? err->code : AG_ERR_DB;
}

/* One change: change(db) inside BEGIN IMMEDIATE, the owner rule checked before the commit,
 * the sharing read back, the change announced. */
typedef struct {
    int64_t model;
    const char *user;
    ag_model_role role; /* put */
    int remove;
    int set_public, public_read;
} change;

static ag_status apply(ag_db *db, const change *c, ag_error *err)
{
    ag_model_role unused;
    int public_read;
    ag_status s = ag_members_access(db, c->model, 0, &unused, &public_read, err);
    if (s != AG_OK)
        return s;
    if (c->set_public)
        return ag_models_set_public_read(db, c->model, c->public_read, err);
    ag_user_row user;
    if ((s = ag_users_find(db, c->user, &user, err)) != AG_OK)
        return s;
    /* models made before accounts, or by the server, may have none: admins manage them */
    int64_t owners = ag_members_owners(db, c->model);
    if (c->remove) {
        int removed = 0;
        s = ag_members_remove(db, c->model, user.id, &removed, err);
        if (s == AG_OK && !removed)
            s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "%s has no role on model %lld",
                             user.name, (long long)c->model);
    } else {
        s = ag_members_put(db, c->model, user.id, c->role, err);
    }
    if (s == AG_OK && owners > 0 && ag_members_owners(db, c->model) < 1)
        s = ag_error_set(err, AG_ERR_CONFLICT, 0,
                         "model %lld would have no owner: make someone else owner first",
                         (long long)c->model);
    return s;
}

static ag_status run(ag_app *app, const change *c, json_t **doc, ag_error *err)
{
    *doc = NULL;
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    if ((s = apply(db, c, err)) == AG_OK)
        s = read_doc(db, c->model, doc, err);
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    if (s != AG_OK) {
        json_decref(*doc);
        *doc = NULL;
        return s;
    }
    ag_auth_forget(app); /* before the room is told: its roles are read again */
    ag_event ev = {.kind = AG_EVENT_ACCESS, .model = c->model};
    ag_events_publish(ag_app_events(app), &ev);
    return AG_OK;
}

ag_status ag_sharing_put(ag_app *app, int64_t model, const char *user, const char *role,
                         json_t **doc, ag_error *err)
{
    *doc = NULL;
    change c = {.model = model, .user = user};
    ag_status s = ag_members_role_parse(role, &c.role, err);
    return s != AG_OK ? s : run(app, &c, doc, err);
}

ag_status ag_sharing_remove(ag_app *app, int64_t model, const char *user, json_t **doc,
                            ag_error *err)
{
    change c = {.model = model, .user = user, .remove = 1};
    return run(app, &c, doc, err);
}

ag_status ag_sharing_set_public(ag_app *app, int64_t model, int public_read, json_t **doc,
                                ag_error *err)
{
    change c = {.model = model, .set_public = 1, .public_read = public_read};
    return run(app, &c, doc, err);
}
