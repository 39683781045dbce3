/* The edit state the service keeps per model: the proceduralized model in memory with its
 * cached solver state (core/edit/edit.h), for the version it describes, and the map from the
 * node ids of GET /api/v1/models/{id}/tree to the nodes of the in-memory split tree (the
 * served tree is read off the grammar's derivation, the in-memory one off its
 * proceduralization: same boxes, other numbering).
 *
 * A state is borrowed with ag_edit_session_acquire and given back with _release; while it is
 * borrowed nobody else gets the same model's state, so edits and previews of one model run
 * one at a time, in order. A state whose version is no longer the model's (changed by anything
 * else) is loaded again: the model's mesh (the derived mesh of its grammar) is proceduralized.
 * At most AG_EDIT_SESSIONS_MAX models are kept; the least recently used idle one goes. */
#ifndef AG_EDIT_SESSION_H
#define AG_EDIT_SESSION_H

#include <stddef.h>
#include <stdint.h>

#include "../core/edit/edit.h"
#include "../core/status.h"
#include "app.h"

#define AG_EDIT_SESSIONS_MAX 16

typedef struct ag_edit_sessions ag_edit_sessions;

typedef struct {
    int64_t model;
    int64_t version;        /* the model version em describes; 0 = nothing loaded */
    ag_edit_model *em;
    size_t ntree;           /* nodes of the served tree */
    int32_t *tree_to_node;  /* served tree id → em's tree node, -1 where none matches */
    int32_t *node_to_tree;  /* em's tree node → served tree id, -1 (em->proc->tree->nnodes) */
    double load_ms;         /* time of the last load */
} ag_edit_state;

ag_edit_sessions *ag_edit_sessions_create(void);
void ag_edit_sessions_free(ag_edit_sessions *s);

/* The model's state at its current version, loaded when needed. AG_ERR_NOT_FOUND without the
 * model; AG_ERR_CONFLICT (detail "model N is not proceduralized: ...") when no grammar
 * describes its current mesh. On success the state is borrowed until ag_edit_session_release. */
ag_status ag_edit_session_acquire(ag_app *app, int64_t model, ag_edit_state **state,
                                  ag_error *err);
void ag_edit_session_release(ag_app *app, ag_edit_state *state);
/* Borrows the model's state as it is, loading nothing (a restore only needs to keep the
 * model's edits waiting); release it the same way. */
ag_status ag_edit_session_hold(ag_app *app, int64_t model, ag_edit_state **state, ag_error *err);

/* After a committed edit: em (taken) is the model at `version`, tree_json the tree served for
 * it. On failure the state is emptied (loaded again next time). */
ag_status ag_edit_session_replace(ag_edit_state *state, int64_t version, ag_edit_model *em,
                                  const char *tree_json, ag_error *err);

/* Forgets the loaded model (e.g. after a restore). */
void ag_edit_session_reset(ag_edit_state *state);

/* Served tree id → em node: AG_ERR_NOT_FOUND naming `field` when the id is not in the tree or
 * has no counterpart. */
ag_status ag_edit_session_node(const ag_edit_state *state, int32_t id, const char *field,
                               int32_t *node, ag_error *err);

/* Matches a served tree (JSON text, io/splittree_json.h) with t: *tree_to_node has *ntree
 * entries, *node_to_tree t->nnodes (both malloc'd, -1 where nothing matches). */
ag_status ag_edit_session_map(const char *tree_json, const ag_splittree *t, int32_t **tree_to_node,
                              size_t *ntree, int32_t **node_to_tree, ag_error *err);

#endif
