#include "members.h"

#include <stdlib.h>
#include <string.h>

#include "models.h"

static const char *const role_names[] = {"none", "viewer", "editor", "owner"};

const char *ag_members_role_name(ag_model_role role)
{
    return role >= AG_ROLE_NONE && role <= AG_ROLE_OWNER ? role_names[role] : "none";
}

ag_status ag_members_role_parse(const char *text, ag_model_role *role, ag_error *err)
{
    for (int r = AG_ROLE_VIEWER; text && r <= AG_ROLE_OWNER; r++)
        if (strcmp(text, role_names[r]) == 0) {
            *role = (ag_model_role)r;
            return AG_OK;
        }
    return ag_error_set(err, AG_ERR_INVALID, 0,
                        "a role on a model is \"owner\", \"editor\" or \"viewer\"");
}

ag_status ag_members_access(ag_db *db, int64_t model, int64_t user, ag_model_role *role,
                            int *public_read, ag_error *err)
{
    *role = AG_ROLE_NONE;
    *public_read = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT m.public_read, (SELECT role FROM model_members "
                                 "WHERE model_id = m.id AND user_id = ?) FROM models m "
                                 "WHERE m.id = ?",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, user);
    sqlite3_bind_int64(st, 2, model);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        *public_read = sqlite3_column_int(st, 0) != 0;
        const char *r = (const char *)sqlite3_column_text(st, 1);
        if (r && ag_members_role_parse(r, role, NULL) != AG_OK)
            *role = AG_ROLE_NONE;
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    } else {
        s = ag_db_fail(db, err, "reading who may use a model");
    }
    sqlite3_reset(st);
    return s;
}

ag_status ag_members_put(ag_db *db, int64_t model, int64_t user, ag_model_role role,
                         ag_error *err)
{
    if (role < AG_ROLE_VIEWER || role > AG_ROLE_OWNER)
        return ag_error_set(err, AG_ERR_INVALID, 0, "no such role on a model");
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "INSERT INTO model_members (model_id, user_id, role) "
                                 "VALUES (?, ?, ?) ON CONFLICT (model_id, user_id) "
                                 "DO UPDATE SET role = excluded.role",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, user);
    sqlite3_bind_text(st, 3, role_names[role], -1, SQLITE_STATIC);
    return ag_db_step_done(db, st, "sharing a model", err);
}

ag_status ag_members_remove(ag_db *db, int64_t model, int64_t user, int *removed,
                            ag_error *err)
{
    *removed = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "DELETE FROM model_members WHERE model_id = ? AND user_id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, user);
    if ((s = ag_db_step_done(db, st, "removing a member of a model", err)) == AG_OK)
        *removed = sqlite3_changes(ag_db_handle(db)) > 0;
    return s;
}

ag_status ag_members_list(ag_db *db, int64_t model, size_t limit, ag_member_row **rows,
                          size_t *count, ag_error *err)
{
    *rows = NULL;
    *count = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT u.id, u.name, mm.role FROM model_members mm "
                                 "JOIN users u ON u.id = mm.user_id WHERE mm.model_id = ? "
                                 "ORDER BY u.name LIMIT ?",
                                 err);
    if (s != AG_OK)
        return s;
    ag_member_row *out = calloc(limit ? limit : 1, sizeof *out);
    if (!out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory listing members");
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int64(st, 2, (sqlite3_int64)limit);
    size_t n = 0;
    int rc = SQLITE_DONE;
    while (n < limit && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        ag_member_row *m = &out[n++];
        m->user = sqlite3_column_int64(st, 0);
        ag_db_column_copy(st, 1, m->name, sizeof m->name);
        if (ag_members_role_parse((const char *)sqlite3_column_text(st, 2), &m->role, NULL) !=
            AG_OK)
            m->role = AG_ROLE_NONE;
    }
    if (n < limit && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "listing the members of a model");
    sqlite3_reset(st);
    if (s != AG_OK) {
        free(out);
        return s;
    }
    *rows = out;
    *count = n;
    return AG_OK;
}

int64_t ag_members_owners(ag_db *db, int64_t model)
{
    sqlite3_stmt *st = ag_db_prepare(
        db, "SELECT count(*) FROM model_members WHERE model_id = ? AND role = 'owner'", NULL);
    int64_t n = -1;
    if (!st)
        return n;
    sqlite3_bind_int64(st, 1, model);
    if (sqlite3_step(st) == SQLITE_ROW)
        n = sqlite3_column_int64(st, 0);
    sqlite3_reset(st);
    return n;
}

ag_status ag_members_own_from_job(ag_db *db, int64_t model, int64_t job, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "SELECT user_id FROM jobs WHERE id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, job);
    int rc = sqlite3_step(st);
    int64_t user = rc == SQLITE_ROW ? sqlite3_column_int64(st, 0) : 0;
    sqlite3_reset(st);
    if (rc != SQLITE_ROW && rc != SQLITE_DONE)
        return ag_db_fail(db, err, "reading who asked for a job");
    if (user)
        return ag_members_put(db, model, user, AG_ROLE_OWNER, err);
    return ag_models_set_public_read(db, model, 1, err);
}
