/* The model_states table (migration 0004): the mesh file, stats, grammar, split tree and
 * summary of model versions (and a point cloud's segmentation, store/pointclouds.h), written
 * around structural edits and restores so undo, redo and restoring an old version bring back
 * exactly that version's state.
 *
 * Every call runs inside the caller's transaction (ag_db_begin). */
#ifndef AG_STATES_H
#define AG_STATES_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

typedef struct {
    int64_t model;
    int64_t version;   /* the version the state was kept for */
    int64_t mesh_blob;
    char *stats_json;  /* malloc'd */
    char *grammar;     /* malloc'd; NULL when that version had no grammar */
    size_t grammar_len;
    char *tree_json;   /* malloc'd; NULL with grammar */
    int tree_numbering;
    char *summary_json;
} ag_state_row;

void ag_states_row_clear(ag_state_row *row);

/* Keeps the model's current state (its mesh file, stats and the grammar that describes that
 * mesh, if any) as the state of `version` — the version the model has or had while its mesh
 * was this one. A version already kept is left as it is. */
ag_status ag_states_keep(ag_db *db, int64_t model, int64_t version, ag_error *err);

/* Keeps the model's current state with tree_json as the state of `version`, the version
 * being written, whose grammar row (ag_grammars_put just before, tree_json "") names this
 * row for its tree: the tree is written once. */
ag_status ag_states_keep_with_tree(ag_db *db, int64_t model, int64_t version,
                                   const char *tree_json, ag_error *err);

/* The state of `version`: the newest kept state at or before it, when only ops that leave
 * the geometry alone (rename, note) came between. AG_ERR_NOT_FOUND (message says why) when
 * the version does not exist or its state was not kept. */
ag_status ag_states_get(ag_db *db, int64_t model, int64_t version, ag_state_row *row,
                        ag_error *err);

/* Makes row the model's current state, for the version `version` being written: its mesh
 * file and stats, and its grammar (or none). */
ag_status ag_states_restore(ag_db *db, int64_t model, int64_t version, const ag_state_row *row,
                            ag_error *err);

#endif
