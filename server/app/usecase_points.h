/* The point cloud use cases, over any workspace (app/workspace.h), in the shape of the mesh
 * ones (usecase_proceduralize.h, usecase_edit.h):
 *
 *   proceduralize   the workspace's cloud → segment, repetition, consensus, tree, rules,
 *                   patterns, grammar (core/points/proceduralize_cloud.h) → the state read back
 *                   from its grammar text and PLY terminals (app/points_state.h) → verified: the
 *                   read-back model derived and compared with the input → saved
 *   edit            the workspace's point model (and a paste's source) → one structural edit
 *                   (core/points/pointedit.h: resize, split, join, paste, remove, the ops of
 *                   schema/edit_ops.md with node ids of the model's tree) → the state read back
 *                   → saved
 *
 * `archgram proceduralize CLOUD` and `archgram edit DIR` (for a point model) run them between
 * folders (app/points_folder_ws.h); the store workspace (app/store_ws.h, its point operations
 * in app/store_ws_points.c) runs them for the service: the proceduralize job of a pointcloud
 * model (app/cloud_pipeline.h) and its structural ops (app/edit_ops.h). Progress goes to the workspace by stage; a cancellation is
 * honoured between stages and before the save. */
#ifndef AG_USECASE_POINTS_H
#define AG_USECASE_POINTS_H

#include "../core/points/proceduralize_cloud.h"
#include "workspace.h"

typedef struct {
    ag_proceduralize_cloud_options options; /* progress and user are the use case's */
    int boxes_in_input; /* the options' templates and ROIs are in the input's coordinates (an
                         * RD New box a person drew), not the cloud's local frame */
} ag_usecase_points_proceduralize_params;

typedef struct {
    size_t points, segments, planes, clusters, elements, labels;
    size_t terminals, placements, rules, patterns, derived_points;
    size_t grammar_bytes, terminal_bytes;
    ag_pointmodel_fidelity fidelity;
    double total_s; /* up to the save, verify excluded */
} ag_usecase_points_proceduralize_result;

ag_status ag_usecase_points_proceduralize_run(ag_workspace *ws,
                                              const ag_usecase_points_proceduralize_params *p,
                                              ag_usecase_points_proceduralize_result *out,
                                              ag_error *err);

typedef struct {
    const ag_edit_op *op;
    const ag_edit_op_origin *from;
} ag_usecase_points_edit_params;

typedef struct {
    ag_edit_report report; /* clear it with ag_edit_report_clear */
    double load_ms, edit_ms;
    size_t placements;
} ag_usecase_points_edit_result;

/* op as the model works on it: boxes and split planes come in the input's coordinates
 * (tree.json's, the service's tree), the model works in its local frame (pm->offset). A
 * shallow copy (it shares op's lists). */
ag_edit_op ag_usecase_points_local_op(const ag_pointmodel *pm, const ag_edit_op *op);

/* Problems that name an op field are AG_ERR_INVALID or AG_ERR_NOT_FOUND (a node). */
ag_status ag_usecase_points_edit_run(ag_workspace *ws, const ag_usecase_points_edit_params *p,
                                     ag_usecase_points_edit_result *out, ag_error *err);

#endif
