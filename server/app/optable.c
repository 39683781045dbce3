#include "optable.h"

#include <string.h>

#include "cloud_ops.h"
#include "compose_ops.h"
#include "edit_ops.h"
#include "modelops.h"
#include "plan_edit.h"

#define EDIT (AG_OP_CLIENT | AG_OP_UNDOABLE | AG_OP_GEOMETRY)

const ag_op_kind ag_optable[] = {
    /* kind         validate                       effect                      run                      flags                         lane              made_by, rebase */
    {"rename",      ag__modelops_rename_validate,  ag__modelops_rename_effect, NULL,                    AG_OP_CLIENT,                 AG_OP_FAST,       NULL, AG_REBASE_UNLESS_SAME},
    {"note",        ag__modelops_note_validate,    NULL,                       NULL,                    AG_OP_CLIENT,                 AG_OP_FAST,       NULL, AG_REBASE_UNLESS_SAME},
    {"resize",      ag_edit_ops_validate,          NULL,                       ag_edit_ops_run_edit,    EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    {"split",       ag_edit_ops_validate,          NULL,                       ag_edit_ops_run_edit,    EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    {"join",        ag_edit_ops_validate,          NULL,                       ag_edit_ops_run_edit,    EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    {"paste",       ag_edit_ops_validate,          NULL,                       ag_edit_ops_run_edit,    EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    {"remove",      ag_edit_ops_validate,          NULL,                       ag_edit_ops_run_edit,    EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    {"compose",     ag_compose_ops_validate,       NULL,                       ag_compose_ops_run,      EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_NODES},
    /* point clouds: they name boxes of the cloud, so any geometry op since conflicts */
    {"segment_roi", ag_cloud_ops_validate_roi,     NULL,                       ag_cloud_ops_run,        EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_OVER_CONTENT},
    {"mark_template", ag_cloud_ops_validate_template, NULL,                    ag_cloud_ops_run,        EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_OVER_CONTENT},
    /* undo and redo are logged as the restore they become; they name no version's content */
    {"undo",        ag_edit_ops_validate_history,  NULL,                       ag_edit_ops_run_restore, AG_OP_CLIENT | AG_OP_GEOMETRY, AG_OP_STRUCTURAL, NULL, AG_REBASE_ALWAYS},
    {"redo",        ag_edit_ops_validate_history,  NULL,                       ag_edit_ops_run_restore, AG_OP_CLIENT | AG_OP_GEOMETRY, AG_OP_STRUCTURAL, NULL, AG_REBASE_ALWAYS},
    /* an undo step unless it carries "undoes"/"redoes" (an undo or redo logged) */
    {"restore",     ag_edit_ops_validate_restore,  NULL,                       ag_edit_ops_run_restore, EDIT,                         AG_OP_STRUCTURAL, NULL, AG_REBASE_OVER_CONTENT},
    {"plan",        ag_plan_edit_validate,         ag_plan_edit_apply,         NULL,                    AG_OP_CLIENT | AG_OP_GEOMETRY, AG_OP_STRUCTURAL, NULL, AG_REBASE_OVER_CONTENT},
    {"profile",     ag_plan_edit_validate,         ag_plan_edit_apply,         NULL,                    AG_OP_CLIENT | AG_OP_GEOMETRY, AG_OP_STRUCTURAL, NULL, AG_REBASE_OVER_CONTENT},
    {"proceduralize", NULL,                        NULL,                       NULL,                    AG_OP_GEOMETRY,               AG_OP_STRUCTURAL, "POST /api/v1/models/{id}/proceduralize", AG_REBASE_NEVER},
    {"segment",     NULL,                          NULL,                       NULL,                    AG_OP_GEOMETRY,               AG_OP_STRUCTURAL, "POST /api/v1/models/{id}/segment", AG_REBASE_NEVER},
    {"grammar",     NULL,                          NULL,                       NULL,                    AG_OP_UNDOABLE | AG_OP_GEOMETRY, AG_OP_STRUCTURAL, "PUT /api/v1/models/{id}/grammar", AG_REBASE_NEVER},
};
const size_t ag_optable_count = sizeof ag_optable / sizeof ag_optable[0];

const ag_op_kind *ag_optable_find(const char *kind)
{
    for (size_t i = 0; kind && i < ag_optable_count; i++)
        if (strcmp(ag_optable[i].kind, kind) == 0)
            return &ag_optable[i];
    return NULL;
}

ag_status ag_optable_lookup(const json_t *op, const ag_op_kind **row, ag_error *err)
{
    *row = NULL;
    if (!json_is_object(op))
        return ag_error_set(err, AG_ERR_INVALID, 0, "an op must be a JSON object");
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (!kind)
        return ag_error_set(err, AG_ERR_INVALID, 0, "an op needs a string \"kind\"");
    if (!(*row = ag_optable_find(kind)))
        return ag_error_set(err, AG_ERR_INVALID, 0, "unknown op kind \"%s\"", kind);
    return AG_OK;
}
