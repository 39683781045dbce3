/* The store as a workspace (app/workspace.h): one model of the SQLite store, changed by one
 * op made on a known version by one author. Its saves are server ops (app/sequencer.h): the
 * model's mesh, grammar, split tree, summary and terminals are written with the version the
 * op raises, the op is logged and announced, in one transaction; a job doing the work records
 * its success in the same transaction after a last cancellation check. The saved edit model
 * is kept in the environment's edit sessions for the next edit. Imports and extrusions add
 * a new model. Parts come from and go to the store's parts library (app/part_library.h): a
 * composition is saved like an edit (logged with its report and the part version it used),
 * a part saved from the model gets the model's name and version as its provenance. */
#ifndef AG_STORE_WS_H
#define AG_STORE_WS_H

#include <jansson.h>
#include <stdint.h>

#include "jobqueue.h"
#include "optable.h"
#include "store_env.h"
#include "workspace.h"

typedef struct {
    ag_store_env env;
    int64_t model;      /* 0 for an import */
    int64_t base;       /* the version the change is made on */
    const char *author;
    const char *cid;
    uint64_t origin;    /* the live session the op came from, 0 = none */
    const json_t *op;   /* an edit: the client's op, logged with the edit's report */
    ag_jobctx *job;     /* the job doing the work (progress, cancellation, its outcome), or NULL */
    int64_t job_id;
    int64_t part_update; /* a part save: the part it makes a new version of (0: a new part) */
    int64_t part_base;   /* and the version that replaces */
} ag_store_ws_options;

typedef struct {
    ag_workspace ws;
    ag_store_ws_options o;
    ag_edit_state *target, *source; /* borrowed edit sessions */
    int64_t version;                /* what the save got (or the duplicate's version) */
    int duplicate;                  /* the cid was used before: nothing was applied */
    ag_part *part;                  /* the part a composition read */
    int64_t part_id, part_version;  /* where a part save went */
    char job_cid[32];               /* a job's cid, "job-<id>" */
} ag_store_ws;

void ag_store_ws_init(ag_store_ws *w, const ag_store_ws_options *o);
/* The workspace of a client's op (a structural kind's run): its model, base, author, cid,
 * origin and the op as logged. */
void ag_store_ws_init_op(ag_store_ws *w, const ag_store_env *env, const ag_op_request *rq);
/* The workspace of a job's run on a model: its cid is "job-<id>", the job reports progress
 * and is asked whether to stop. */
void ag_store_ws_init_job(ag_store_ws *w, const ag_store_env *env, ag_jobctx *ctx, int64_t job,
                          int64_t model, int64_t base, const char *author);
/* Gives the sessions back; after a failure that is not the op's or the model's fault the
 * target's kept model is dropped (it is loaded afresh next time). */
void ag_store_ws_end(ag_store_ws *w, ag_status outcome);

/* Stores a mesh as a new model inside the caller's transaction (imports, the demo content);
 * source may be NULL. */
ag_status ag_store_ws_insert_model(ag_db *db, const char *name, const ag_mesh *mesh,
                                   const void *source, size_t source_len,
                                   const char *source_format, int64_t *model, ag_error *err);

/* For the store's other writers of model states (a grammar text edit): writes st's mesh (its
 * edit model's mesh, with its stats), grammar text, served tree and summary for `version`
 * inside the caller's transaction. keep: also kept as the state of `version` (undo, restore),
 * the tree written once, in that state row (store/grammars.h). */
ag_status ag__store_ws_put_state(ag_db *db, int64_t model, int64_t version,
                                 const ag_model_state *st, const char *summary_json, int keep,
                                 ag_error *err);
/* The point cloud operations of the store workspace (app/store_ws_cloud.c): a cloud upload
 * is a new model of kind "pointcloud" (its points in the point cloud tables, its file kept
 * as the source up to 256 MiB); a segmentation is saved as a server op ("segment", a job) or
 * the client's op (segment_roi, mark_template) with its report, with the states before and
 * after kept for undo. */
ag_status ag__store_ws_add_cloud(ag_workspace *ws, const char *name, const ag_cloud_new *c,
                                 int64_t *model, ag_error *err);
ag_status ag__store_ws_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                   ag_cloud_state *st, ag_error *err);
ag_status ag__store_ws_save_segmentation(ag_workspace *ws, const ag_cloud_state *st,
                                         const ag_segment_outcome *o, ag_error *err);
/* Keeps st's edit model (taken) as the model's edit session at version. */
void ag__store_ws_keep_model(ag_edit_sessions *reg, int64_t model, int64_t version,
                             ag_model_state *st);

#endif
