/* Sharing a model: its members (an account and a role each, store/members.h) and its
 * public-read flag, changed by its owners (the REST routes declare that need) in one
 * transaction each, outside the model's versions and op log. A model keeps at least one owner.
 * Each change is announced (AG_EVENT_ACCESS) so live sessions in its room learn their role.
 *
 * Every call answers the model's sharing as it is then:
 * {"model", "public_read", "items": [{"user", "role"}, ...]} (members by name). */
#ifndef AG_SHARING_H
#define AG_SHARING_H

#include <jansson.h>
#include <stdint.h>

#include "app.h"

ag_status ag_sharing_get(ag_app *app, int64_t model, json_t **doc, ag_error *err);
/* Gives the account user the role ("owner", "editor", "viewer") on model. AG_ERR_NOT_FOUND
 * when there is no such account, AG_ERR_CONFLICT when it would leave the model no owner. */
ag_status ag_sharing_put(ag_app *app, int64_t model, const char *user, const char *role,
                         json_t **doc, ag_error *err);
/* Takes user's role on model away (AG_ERR_NOT_FOUND when it has none). */
ag_status ag_sharing_remove(ag_app *app, int64_t model, const char *user, json_t **doc,
                            ag_error *err);
ag_status ag_sharing_set_public(ag_app *app, int64_t model, int public_read, json_t **doc,
                                ag_error *err);

#endif
