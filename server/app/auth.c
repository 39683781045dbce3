#include "auth.h"

#include <stdio.h>
#include <string.h>

#include "../store/jobs.h"
#include "../store/tokens.h"

void ag_auth_local(ag_identity *who)
{
    memset(who, 0, sizeof *who);
    snprintf(who->name, sizeof who->name, "local");
    who->role = AG_ACCOUNT_ADMIN;
}

ag_status ag_auth_token(ag_app *app, const char *token, ag_identity *who, ag_error *err)
{
    memset(who, 0, sizeof *who);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    int64_t user, id;
    ag_status s = ag_tokens_verify(db, token, &user, &id, err);
    ag_user_row row;
    if (s == AG_OK && (s = ag_users_get(db, user, &row, err)) == AG_ERR_NOT_FOUND)
        s = ag_error_set(err, AG_ERR_UNAUTHORIZED, 0, "the token's account is gone");
    if (s != AG_OK)
        return s;
    who->user = row.id;
    who->token = id;
    who->role = row.role;
    snprintf(who->name, sizeof who->name, "%s", row.name);
    return AG_OK;
}

ag_model_role ag_auth_role(const ag_identity *who, ag_model_role member, int public_read)
{
    if (who->role == AG_ACCOUNT_ADMIN)
        return AG_ROLE_OWNER;
    if (member != AG_ROLE_NONE)
        return member;
    return public_read ? AG_ROLE_VIEWER : AG_ROLE_NONE;
}

static const char *doing(ag_model_role need)
{
    return need == AG_ROLE_OWNER ? "only its owners may do this"
                                 : "only its editors and owners may change it";
}

static ag_status check_model(ag_db *db, const ag_identity *who, int64_t model,
                             ag_model_role need, ag_model_role *role, ag_error *err)
{
    ag_model_role member = AG_ROLE_NONE, have;
    int public_read = 0;
    if (who->role == AG_ACCOUNT_ADMIN) {
        have = AG_ROLE_OWNER; /* a missing model is the handler's to report */
    } else {
        ag_status s = ag_members_access(db, model, who->user, &member, &public_read, err);
        if (s != AG_OK)
            return s;
        have = ag_auth_role(who, member, public_read);
    }
    if (role)
        *role = have;
    if (have == AG_ROLE_NONE)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    if (have < need)
        return ag_error_set(err, AG_ERR_FORBIDDEN, 0, "%s is a %s of model %lld: %s", who->name,
                            ag_members_role_name(have), (long long)model, doing(need));
    return AG_OK;
}

static ag_status check_job(ag_db *db, const ag_identity *who, int64_t job, ag_error *err)
{
    if (who->role == AG_ACCOUNT_ADMIN)
        return AG_OK;
    ag_job_row row;
    ag_status s = ag_jobs_get(db, job, &row, err);
    int mine = s == AG_OK && row.user != 0 && row.user == who->user;
    ag_jobs_row_clear(&row);
    if (s != AG_OK && s != AG_ERR_NOT_FOUND)
        return s;
    return mine ? AG_OK
                : ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no job %lld", (long long)job);
}

ag_status ag_auth_check(ag_app *app, const ag_identity *who, ag_need need, int64_t id,
                        ag_model_role *role, ag_error *err)
{
    if (role)
        *role = AG_ROLE_NONE;
    if (need == AG_NEED_NOTHING)
        return AG_OK;
    if (!who || (!who->user && who->role != AG_ACCOUNT_ADMIN))
        return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                            "sign in: send Authorization: Bearer <token>");
    switch (need) {
    case AG_NEED_ACCOUNT:
        return AG_OK;
    case AG_NEED_EDITOR:
        return who->role >= AG_ACCOUNT_EDITOR
                   ? AG_OK
                   : ag_error_set(err, AG_ERR_FORBIDDEN, 0,
                                  "%s is a viewer account: only editors and admins may do this",
                                  who->name);
    case AG_NEED_ADMIN:
    case AG_NEED_UNDECLARED:
        return who->role == AG_ACCOUNT_ADMIN
                   ? AG_OK
                   : ag_error_set(err, AG_ERR_FORBIDDEN, 0, "only admins may do this");
    default:
        break;
    }
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    switch (need) {
    case AG_NEED_MODEL_VIEWER:
        return check_model(db, who, id, AG_ROLE_VIEWER, role, err);
    case AG_NEED_MODEL_EDITOR:
        return check_model(db, who, id, AG_ROLE_EDITOR, role, err);
    case AG_NEED_MODEL_OWNER:
        return check_model(db, who, id, AG_ROLE_OWNER, role, err);
    case AG_NEED_JOB:
        return check_job(db, who, id, err);
    default:
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "unknown access need %d", (int)need);
    }
}
