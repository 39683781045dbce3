/* The model_members table: an account's role on a model (owner, editor, viewer), and the
 * model's public-read flag that the access checks read with it. */
#ifndef AG_MEMBERS_H
#define AG_MEMBERS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"
#include "users.h"

typedef enum {
    AG_ROLE_NONE = 0,
    AG_ROLE_VIEWER = 1, /* reads the model, its ops, tree, grammar, plan, members */
    AG_ROLE_EDITOR = 2, /* also sends ops, proceduralizes, edits the grammar */
    AG_ROLE_OWNER = 3,  /* also deletes it and shares it */
} ag_model_role;

typedef struct {
    int64_t user;
    char name[AG_USER_NAME_MAX + 1];
    ag_model_role role;
} ag_member_row;

/* "none", "viewer", "editor", "owner". */
const char *ag_members_role_name(ag_model_role role);
/* "viewer", "editor" or "owner" (AG_ERR_INVALID otherwise). */
ag_status ag_members_role_parse(const char *text, ag_model_role *role, ag_error *err);

/* What the access checks need of a model in one read: user's role on it (AG_ROLE_NONE when
 * it has none; user 0 has none) and its public-read flag. AG_ERR_NOT_FOUND when there is no
 * such model. */
ag_status ag_members_access(ag_db *db, int64_t model, int64_t user, ag_model_role *role,
                            int *public_read, ag_error *err);
/* Inside the caller's transaction: gives user role on model (replacing the one it had). */
ag_status ag_members_put(ag_db *db, int64_t model, int64_t user, ag_model_role role,
                         ag_error *err);
/* Inside the caller's transaction: *removed = 1 when user had a role on model. */
ag_status ag_members_remove(ag_db *db, int64_t model, int64_t user, int *removed,
                            ag_error *err);
/* The members of a model, by name, at most limit; *rows is malloc'd. */
ag_status ag_members_list(ag_db *db, int64_t model, size_t limit, ag_member_row **rows,
                          size_t *count, ag_error *err);
/* How many owners the model has (-1 when it cannot be read). */
int64_t ag_members_owners(ag_db *db, int64_t model);
/* Inside the caller's transaction, for a model a job made: the account that asked for the job
 * owns it; a job the server asked for itself (no account: the demo content) makes it
 * readable by every account. */
ag_status ag_members_own_from_job(ag_db *db, int64_t model, int64_t job, ag_error *err);

#endif
