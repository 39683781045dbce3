/* A workspace: where the use cases (app/usecase_*.h) read a model and save what they made.
 * Two kinds, one interface, so the CLI and the service run the same pipeline:
 *
 *   the store (app/store_ws.h)    one model of the SQLite store, changed by one op at a known
 *                                 version; saves are server ops (sequenced, logged, announced)
 *                                 and keep the model's mesh, so a reload is exact
 *   a folder (app/folder_ws.h)    `archgram`'s --out DIR layout: grammar.txt, terminals/,
 *                                 tree.json, summary.json; it keeps only the grammar, so its
 *                                 models are read back (grammar derived and proceduralized)
 *
 * Parts (app/usecase_save_part.h, app/usecase_compose.h) go through it too: a folder reads and
 * writes part bundle files, the store its parts library (app/part_library.h).
 *
 * Point clouds too (app/cloud_state.h): an upload becomes a cloud model
 * (app/usecase_import_cloud.h), segmentations are read and saved through it
 * (app/usecase_segment.h, app/usecase_mark_template.h); only the store keeps cloud models.
 * A cloud is also proceduralized into a point model, point models are edited and their
 * grammar and PLY terminals saved (app/usecase_points.h; app/points_folder_ws.h for folders,
 * app/store_ws.h for the store).
 *
 * A workspace that cannot do something answers AG_ERR_UNSUPPORTED. */
#ifndef AG_WORKSPACE_H
#define AG_WORKSPACE_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/edit/edit.h"
#include "../core/parts/compose.h"
#include "../core/parts/graft.h"
#include "../core/parts/part.h"
#include "../core/points/cloud.h"
#include "../core/points/pointmodel.h"
#include "../core/status.h"
#include "../io/edit_op_json.h"
#include "../io/import.h"
#include "cloud_state.h"
#include "model_state.h"

typedef struct ag_workspace ag_workspace;
struct ag_extrude_batch;
struct ag_points_state;
struct ag_pointmodel;
struct ag_proceduralize_cloud_result;

/* What a proceduralization found and how long it took, for the saved summary. */
typedef struct {
    const ag_mesh *input;                 /* the mesh proceduralized */
    const ag_proceduralize_result *proc;  /* its result (labels, tree, patterns, grammar) */
    ag_fidelity fidelity;                 /* the saved grammar's derivation against the input */
    double seconds[AG_STAGE_COUNT];       /* per stage; AG_STAGE_EXPORT includes printing */
    double total_s;                       /* everything up to the save, verify excluded */
} ag_proc_outcome;

/* What an edit did, for the saved summary and the log. */
typedef struct {
    const ag_edit_op *op;
    const ag_edit_op_origin *from;
    ag_edit_report report;  /* instances per label counted on the saved model */
    double load_ms, edit_ms;
    int64_t source_version; /* a paste from another model of the store: its version */
} ag_edit_outcome;

/* What a point cloud proceduralization found and how long it took (app/usecase_points.h). */
typedef struct {
    const ag_cloud *input;                            /* the cloud proceduralized */
    const struct ag_proceduralize_cloud_result *proc; /* its result */
    ag_pointmodel_fidelity fidelity;                  /* the saved grammar's derivation against
                                                       * the input */
    size_t derived_points;
    double verify_s, total_s;                         /* total: up to the save, verify excluded */
} ag_points_outcome;

/* Which part a composition brings, as the workspace knows parts. */
typedef struct {
    const char *path;  /* a folder: the bundle file */
    const char *name;  /* its part of that name; NULL: the bundle's only part */
    int64_t id;        /* the store: the library's part */
    int64_t version;   /* its version; 0: the newest */
} ag_part_ref;

/* What a part save did. */
typedef struct {
    int32_t node;      /* the node saved (a selection's common ancestor) */
    double load_ms, save_ms;
} ag_part_outcome;

/* What a composition did, for the saved summary and the log. */
typedef struct {
    const ag_compose_op *op;
    const ag_part *part;          /* its name and version */
    ag_compose_report report;
    double load_ms, compose_ms, state_ms; /* reading; the rewrite; the new state */
    ag_graft_report graft; /* the graft (report.grafted) with its stages' times */
} ag_compose_outcome;

typedef struct {
    /* Stores a mesh as a new model (an import); source (the file as it came, may be NULL),
     * its format and how its up axis was decided (may be NULL) are kept with it. *model gets
     * its id. */
    ag_status (*add_model)(ag_workspace *ws, const char *name, const ag_mesh *mesh,
                           const void *source, size_t source_len, const char *source_format,
                           const ag_up_decision *up, int64_t *model, ag_error *err);
    /* Stores an extruded batch (app/usecase_extrude.h) as a new model of kind "extrusion":
     * its mesh, each building's description, mesh and outcome, the input as its source, and
     * the report (for a job's result). */
    ag_status (*add_extrusion)(ag_workspace *ws, const char *name,
                               const struct ag_extrude_batch *batch, const ag_mesh *mesh,
                               const char *source, size_t source_len, const json_t *report,
                               int64_t *model, ag_error *err);
    /* The mesh to proceduralize. */
    ag_status (*input_mesh)(ag_workspace *ws, ag_mesh **mesh, ag_error *err);
    /* The model to edit and, for a paste from elsewhere (from), its source; both are the
     * workspace's until close. *source_version: the source's version in the store, else 0. */
    ag_status (*open_models)(ag_workspace *ws, const ag_edit_op_origin *from, ag_edit_model **em,
                             const ag_edit_model **source, int64_t *source_version,
                             ag_error *err);
    /* Saves a proceduralized or edited model (st is the workspace's afterwards: taken and
     * cleared); exactly one of proc and edit is given. A state whose read-back check still
     * runs (ag_model_state_start) is kept only once ag_model_state_checked says it reads
     * back. */
    ag_status (*save)(ag_workspace *ws, ag_model_state *st, const ag_proc_outcome *proc,
                      const ag_edit_outcome *edit, ag_error *err);
    /* The derivation trace (core/parts/trace.h) of the model open_models gave, kept with it
     * for the next save or composition of the same version; without it (NULL), *trace = NULL
     * and the caller traces. */
    ag_status (*model_trace)(ag_workspace *ws, const ag_trace **trace, ag_error *err);
    /* The part a composition brings; the workspace's until close. */
    ag_status (*open_part)(ag_workspace *ws, const ag_part_ref *ref, const ag_part **part,
                           ag_error *err);
    /* Stores a part saved from the workspace's model (taken: the workspace frees it); the
     * workspace adds the provenance it knows (the model's name, its version). */
    ag_status (*save_part)(ag_workspace *ws, ag_part *part, const ag_part_outcome *o,
                           ag_error *err);
    /* Saves a composed model (st is taken and cleared, as for save). */
    ag_status (*save_composed)(ag_workspace *ws, ag_model_state *st, const ag_compose_outcome *o,
                               ag_error *err);
    /* Stores a point cloud as a new model of kind "pointcloud" (an import). */
    ag_status (*add_cloud)(ag_workspace *ws, const char *name, const ag_cloud_new *c,
                           int64_t *model, ag_error *err);
    /* The point cloud model to work on: its positions and normals (with_properties: every
     * property too) and its current segmentation; st is the caller's (ag_cloud_state_clear).
     * need_segmentation: a model that is not segmented is refused (AG_ERR_CONFLICT). */
    ag_status (*input_cloud)(ag_workspace *ws, int with_properties, int need_segmentation,
                             ag_cloud_state *st, ag_error *err);
    /* Saves st's segmentation (and the normals it computed for a cloud without) as the
     * model's, logged as o describes; st stays the caller's. */
    ag_status (*save_segmentation)(ag_workspace *ws, const ag_cloud_state *st,
                                   const ag_segment_outcome *o, ag_error *err);
    /* Point models (app/usecase_points.h), each may be NULL (the cloud to proceduralize is
     * input_cloud's). The point model to edit and, for a paste from elsewhere, its source (both the
     * workspace's until close); */
    ag_status (*open_point_models)(ag_workspace *ws, const ag_edit_op_origin *from,
                                   struct ag_pointmodel **pm,
                                   const struct ag_pointmodel **source, ag_error *err);
    /* saves a proceduralized or edited point model (st taken and cleared; exactly one of proc
     * and edit is given). */
    ag_status (*save_points)(ag_workspace *ws, struct ag_points_state *st,
                             const ag_points_outcome *proc, const ag_edit_outcome *edit,
                             ag_error *err);
    /* Non-zero when the work should stop (a cancelled job). May be NULL. */
    int (*cancelled)(ag_workspace *ws);
    /* Progress of long work (0..1, stage name); may be NULL. */
    void (*progress)(ag_workspace *ws, double fraction, const char *stage);
    void (*close)(ag_workspace *ws);
    /* AG_MODEL_READ_BACK when the workspace keeps only the grammar, else 0. */
    unsigned state_flags;
} ag_workspace_ops;

struct ag_workspace {
    const ag_workspace_ops *ops;
};

/* Dispatch, answering AG_ERR_UNSUPPORTED where the workspace has no such operation. */
ag_status ag_workspace_add_model(ag_workspace *ws, const char *name, const ag_mesh *mesh,
                                 const void *source, size_t source_len, const char *source_format,
                                 const ag_up_decision *up, int64_t *model, ag_error *err);
ag_status ag_workspace_add_extrusion(ag_workspace *ws, const char *name,
                                    const struct ag_extrude_batch *batch, const ag_mesh *mesh,
                                    const char *source, size_t source_len, const json_t *report,
                                    int64_t *model, ag_error *err);
ag_status ag_workspace_input_mesh(ag_workspace *ws, ag_mesh **mesh, ag_error *err);
ag_status ag_workspace_open_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                   ag_edit_model **em, const ag_edit_model **source,
                                   int64_t *source_version, ag_error *err);
ag_status ag_workspace_save(ag_workspace *ws, ag_model_state *st, const ag_proc_outcome *proc,
                            const ag_edit_outcome *edit, ag_error *err);
ag_status ag_workspace_model_trace(ag_workspace *ws, const ag_trace **trace, ag_error *err);
ag_status ag_workspace_open_part(ag_workspace *ws, const ag_part_ref *ref, const ag_part **part,
                                 ag_error *err);
ag_status ag_workspace_save_part(ag_workspace *ws, ag_part *part, const ag_part_outcome *o,
                                 ag_error *err);
ag_status ag_workspace_save_composed(ag_workspace *ws, ag_model_state *st,
                                     const ag_compose_outcome *o, ag_error *err);
ag_status ag_workspace_add_cloud(ag_workspace *ws, const char *name, const ag_cloud_new *c,
                                 int64_t *model, ag_error *err);
ag_status ag_workspace_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                   ag_cloud_state *st, ag_error *err);
ag_status ag_workspace_save_segmentation(ag_workspace *ws, const ag_cloud_state *st,
                                         const ag_segment_outcome *o, ag_error *err);
ag_status ag_workspace_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                         struct ag_pointmodel **pm,
                                         const struct ag_pointmodel **source, ag_error *err);
ag_status ag_workspace_save_points(ag_workspace *ws, struct ag_points_state *st,
                                   const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                   ag_error *err);
int ag_workspace_cancelled(ag_workspace *ws);
/* Reports progress; returns ag_workspace_cancelled. */
int ag_workspace_progress(ag_workspace *ws, double fraction, const char *stage);
void ag_workspace_close(ag_workspace *ws);

#endif
