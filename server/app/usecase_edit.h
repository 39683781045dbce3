/* The edit use case, over any workspace (app/workspace.h): the workspace's model (and a
 * paste's source) → one structural edit (core/edit) → the new model state → saved. Node ids in
 * the op are ids of the workspace's tree (app/model_tree.h), checked before the edit runs.
 * A workspace that keeps only the grammar gets the edited model read back, so the ids of the
 * tree it saves are those its next load gives; one that keeps the mesh (the store) keeps the
 * edited model itself. `archgram edit` runs it between folders, structural edit ops on the
 * store. */
#ifndef AG_USECASE_EDIT_H
#define AG_USECASE_EDIT_H

#include "workspace.h"

/* op: parsed (io/edit_op_json.h), op->source unset; from: where a paste's source lives. */
typedef struct {
    const ag_edit_op *op;
    const ag_edit_op_origin *from;
} ag_usecase_edit_params;

typedef struct {
    ag_edit_report report; /* clear it with ag_edit_report_clear */
    double load_ms, edit_ms;
} ag_usecase_edit_result;

/* Problems that name an op field are AG_ERR_INVALID or AG_ERR_NOT_FOUND (a node); the rest
 * are the model's. */
ag_status ag_usecase_edit_run(ag_workspace *ws, const ag_usecase_edit_params *p,
                              ag_usecase_edit_result *out, ag_error *err);

#endif
