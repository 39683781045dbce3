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
    struct ag_pointmodel *points, *points_source; /* a point model edit's (app/store_ws_points.c) */
    int64_t source_version;         /* a paste from another point model: its version */
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

/* A model state's mesh file (the model's mesh and stats from now on) and the grammar that
 * describes it, with its stored tree (numbering AG_MODEL_TREE_NUMBERING) and summary, for
 * `version`, inside the caller's transaction. */
ag_status ag__store_ws_put_grammar(ag_db *db, int64_t model, int64_t version, const void *mesh,
                                   size_t mesh_len, const char *stats, const char *text,
                                   size_t text_len, const char *tree_json, const char *summary_json,
                                   ag_error *err);
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
/* The point model operations (app/store_ws_points.c): the point model of a proceduralized
 * cloud (its grammar and PLY terminals as stored) and a paste's source, and a proceduralized
 * or edited point model saved as a sequenced op (its grammar, served tree, summary and
 * terminals, with the states before and after kept for undo). */
ag_status ag__store_ws_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                         struct ag_pointmodel **pm,
                                         const struct ag_pointmodel **source, ag_error *err);
ag_status ag__store_ws_save_points(ag_workspace *ws, struct ag_points_state *st,
                                   const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                   ag_error *err);
/* The point model of a proceduralized cloud's current grammar, read from the stored text and
 * PLY terminals (inside a read transaction of the caller's, for one snapshot). field names
 * the op member the model comes from in problems ("" for none); *version gets the model's
 * version. AG_ERR_CONFLICT for a model that is not a point cloud, AG_ERR_NOT_PROCEDURALIZED
 * for one without a grammar. */
ag_status ag_store_ws_read_point_model(ag_db *db, int64_t model, const char *field,
                                       struct ag_pointmodel **pm, int64_t *version,
                                       ag_error *err);
/* A live drag of a point model (app/edit_ops.h, ag_edit_ops_preview): its model at base
 * (AG_ERR_STALE otherwise; kept in the model's edit session while its grammar stays, so a
 * drag reuses the solve's factorization as for meshes) and op's resize solved on its proxy;
 * *boxes as ag__edit_ops_moved_boxes, in the cloud's coordinates. */
ag_status ag_store_ws_points_preview(const ag_store_env *env, int64_t model, int64_t base,
                                     const ag_edit_op *op, json_t **boxes, double *solve_ms,
                                     ag_error *err);
/* Begins a save (ag_sequencer_begin at the workspace's base; by_client: under the client's
 * author and cid, so a retry is seen): a job's stale model is named as having changed while
 * it was being `doing`; *duplicate set (and w->duplicate, w->version) when the same op came in
 * meanwhile: nothing to do, nothing open. */
ag_status ag__store_ws_begin(ag_store_ws *w, const char *doing, int by_client, ag_seq_txn *t,
                             int *duplicate, ag_error *err);
/* Ends a save begun with ag__store_ws_begin, with s the status of its writes: a last
 * cancellation check of a job, the job's success with its result ({"model","version","href"}
 * and the links of what it made: the tree and grammar, or the points), then op logged and
 * committed (w->version set) — or everything rolled back. */
typedef enum { AG__STORE_WS_LINKS_GRAMMAR, AG__STORE_WS_LINKS_POINTS } ag__store_ws_links;
ag_status ag__store_ws_commit(ag_store_ws *w, ag_seq_txn *t, ag_status s,
                              ag__store_ws_links links, const json_t *op, ag_error *err);
/* PUT …/grammar of a proceduralized point cloud (app/grammar_edit.h): the text read with the
 * model's stored PLY terminals (a parse error: AG_ERR_PARSE with its line in err->element and
 * column in *col; a terminal the model does not keep: AG_ERR_PARSE naming it), read back and
 * saved as the op {"kind":"grammar","bytes"} with the states around it. */
ag_status ag_store_ws_points_grammar_edit(const ag_store_env *env, int64_t model, int64_t base,
                                          const char *author, const char *cid, const char *text,
                                          size_t len, int64_t *version, ag_error *err, long *col);
/* The terminals the store keeps for a model, as an ag_terminal_lookup (io/terminals.h): user
 * is an ag__store_ws_terminals. */
typedef struct {
    ag_db *db;
    int64_t model;
} ag__store_ws_terminals;
ag_status ag__store_ws_terminal_lookup(void *user, const char *path, char **data, size_t *len,
                                       ag_error *err);
/* Keeps st's edit model (taken) as the model's edit session at version. */
void ag__store_ws_keep_model(ag_edit_sessions *reg, int64_t model, int64_t version,
                             ag_model_state *st);

#endif
