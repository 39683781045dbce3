/* Composing a part into a building (paper section 4.2), over any workspace (app/workspace.h):
 * the workspace's model and the part it names → the target's grammar rewritten
 * (core/parts/compose.h) → the new model state: the composed grammar as it was made, its
 * terminals, what it derives, and its tree: the model's tree with the part's components
 * grafted in (core/parts/graft.h: the nodes outside the target keep their ids, nothing is
 * proceduralized again) in a workspace that keeps the tree (the store), or the derivation
 * proceduralized (app/model_state.h) where the graft does not apply and in one that keeps
 * only the grammar (a folder, whose reload numbers the tree so) → saved. The target is an id
 * of the workspace's tree (app/model_tree.h), checked before anything is computed. `archgram
 * part compose` runs it between folders, the "compose" op (app/compose_ops.h) on the store.
 * A preview (the service's, before the op is sent) runs the same steps without the save. */
#ifndef AG_USECASE_COMPOSE_H
#define AG_USECASE_COMPOSE_H

#include <jansson.h>

#include "../core/parts/graft.h"
#include "workspace.h"

/* The budget of one composition: what it derives (the whole model afterwards) is proceduralized
 * again before it is saved, so its growth is bounded (a fill with a small part can ask for a
 * million cells): at most this many triangles, or twice the model's own if that is more. */
#define AG_USECASE_COMPOSE_MAX_TRIANGLES ((size_t)1000000)

typedef struct {
    const ag_part_ref *part;
    ag_compose_op op;
    size_t max_triangles; /* 0: the budget above */
} ag_usecase_compose_params;

typedef struct {
    ag_compose_report report;
    const ag_part *part;     /* the part composed (the workspace's until it closes) */
    double load_ms;          /* reading the model and the part */
    double compose_ms;       /* rewriting the grammar (core/parts/compose.h) */
    double state_ms;         /* the new state (a preview: derived) */
    ag_graft_report graft;   /* report.grafted: the state's tree is the model's with the part
                                grafted in (core/parts/graft.h); else its derivation was
                                proceduralized (report.fallback: why the graft did not apply,
                                "" when it was not tried) */
} ag_usecase_compose_result;

/* Problems naming the target or the mode are AG_ERR_INVALID or AG_ERR_NOT_FOUND ("target:
 * ..."); a part that cannot be read is the workspace's (a bundle's problem names its
 * element); a result past the budget is AG_ERR_TOO_LARGE. */
ag_status ag_usecase_compose_run(ag_workspace *ws, const ag_usecase_compose_params *p,
                                 ag_usecase_compose_result *out, ag_error *err);

/* The composition without saving: *st receives the state the run would save (clear it),
 * its read-back check still running (app/model_state.h ag_model_state_from_grammar_start):
 * its text and terms are its own once ag_model_state_checked says AG_OK. */
ag_status ag_usecase_compose_make(ag_workspace *ws, const ag_usecase_compose_params *p,
                                  ag_model_state *st, ag_usecase_compose_result *out,
                                  ag_error *err);

/* The composition derived, for a preview: *mesh (one component per placed terminal, grouped
 * by label) is what the saved model would show; nothing is saved. */
ag_status ag_usecase_compose_preview(ag_workspace *ws, const ag_usecase_compose_params *p,
                                     ag_mesh **mesh, ag_usecase_compose_result *out,
                                     ag_error *err);

/* What a composition did, as the folder's summary.json and the store's op log report it:
 * {"part":{"name","version","root"},"root_rule","target_rule","instances","counts","turn",
 * "fitted","grammar":{...},"fit":{...}} (a new object). */
json_t *ag_usecase_compose_report_json(const ag_compose_outcome *o);

#endif
