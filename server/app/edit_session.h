/* The edit models the service keeps: per model, its edit model (core/edit/edit.h) with the
 * solver state drags reuse, for the version it describes. Node ids everyone names are the edit
 * model's node indices (app/model_tree.h), so nothing needs mapping.
 *
 * A state is borrowed with ag_edit_session_acquire and given back with _release; while it is
 * borrowed nobody else gets the same model's state, so edits and previews of one model run
 * one at a time, in order. A state whose version is no longer the model's (changed by anything
 * else) is loaded again from the model's mesh (app/model_state.h: the same edit model, node
 * for node). A registry keeps at most AG_EDIT_SESSIONS_MAX models; the least recently used
 * idle one goes. Without a registry (NULL) every acquire loads a state of its own that
 * release frees: tools and tests edit the store without a daemon. */
#ifndef AG_EDIT_SESSION_H
#define AG_EDIT_SESSION_H

#include <stddef.h>
#include <stdint.h>

#include "../core/edit/edit.h"
#include "../core/parts/trace.h"
#include "../core/status.h"
#include "../store/db.h"

#define AG_EDIT_SESSIONS_MAX 16

typedef struct ag_edit_sessions ag_edit_sessions;

typedef struct {
    int64_t model;
    int64_t version;  /* the model version em describes; 0 = nothing loaded */
    ag_edit_model *em;
    double load_ms;   /* time of the last load */
    /* a point cloud's point model kept for live drags (app/store_ws_points.c), freed with the
     * state (reset, replace, eviction) by points_free */
    void *points;
    void (*points_free)(void *points);
    /* em's derivation traced (core/parts/trace.h), made by the first part save or
     * composition of this version and kept for the next ones */
    ag_trace *trace;
    /* em's served tree text (app/model_tree.h), printed when first asked for: edits store
     * their tree bare (app/model_kept.h), so every reader of this version shares one print */
    char *served;
} ag_edit_state;

ag_edit_sessions *ag_edit_sessions_create(void);
void ag_edit_sessions_free(ag_edit_sessions *s);

/* The model's state at its current version, loaded when needed. AG_ERR_NOT_FOUND without the
 * model; AG_ERR_NOT_PROCEDURALIZED (detail "model N is not proceduralized: ...") when no
 * grammar describes its current mesh. A tree stored in an older numbering is rebuilt from the
 * loaded model and stored. On success the state is borrowed until ag_edit_session_release. */
ag_status ag_edit_session_acquire(ag_edit_sessions *reg, ag_db *db, int64_t model,
                                  ag_edit_state **state, ag_error *err);
void ag_edit_session_release(ag_edit_sessions *reg, ag_edit_state *state);
/* Borrows the model's state as it is, loading nothing (a restore only needs to keep the
 * model's edits waiting); release it the same way. */
ag_status ag_edit_session_hold(ag_edit_sessions *reg, int64_t model, ag_edit_state **state,
                               ag_error *err);

/* After a committed edit: em (taken) is the model at `version`. */
void ag_edit_session_replace(ag_edit_state *state, int64_t version, ag_edit_model *em);
/* Forgets the loaded model (e.g. after a restore). */
void ag_edit_session_reset(ag_edit_state *state);
/* The borrowed state's trace, made when it has none yet (it goes with em). */
ag_status ag_edit_session_trace(ag_edit_state *state, const ag_trace **trace, ag_error *err);

/* The borrowed state's served tree text (ag_model_tree_served_text of em), printed when it
 * has none yet (it goes with em): AG_ERR_NOMEM when out of memory. */
ag_status ag_edit_session_served(ag_edit_state *state, const char **text, ag_error *err);

#endif
