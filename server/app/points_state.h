/* A point model as a workspace keeps it: its grammar text, the PLY terminals the text names,
 * and the model read back from them, whose split tree numbers the nodes (app/model_tree.h
 * serves and writes it as for meshes).
 *
 * The text's axiom box is in the input's coordinate system (RD New, UTM: the cloud's offset
 * added back), terminal points are local to their boxes; a reload moves the model to a local
 * origin again (ag_cloud_choose_origin). A state is always read back (the text printed, parsed
 * and derived), so the ids of its tree are those the next load gives; an edit's state is then
 * numbered as the model it edited numbers the nodes it left alone (ag_pointedit_keep_ids), and
 * the store keeps that tree with the text (app/model_kept.h) for a reload to give it back. */
#ifndef AG_POINTS_STATE_H
#define AG_POINTS_STATE_H

#include <stddef.h>

#include "../core/points/pointmodel.h"
#include "../core/status.h"
#include "../io/terminals.h"
#include "model_state.h"

typedef struct ag_points_state {
    char *text;            /* the grammar, NUL-terminated */
    size_t text_len;
    ag_terminal_set terms; /* PLY bytes by the paths the text names */
    ag_pointmodel *pm;     /* read back, built */
} ag_points_state;

void ag_points_state_clear(ag_points_state *s);

/* The state of a built model (made stays the caller's; its grammar's terminal paths are set). */
ag_status ag_points_state_make(ag_pointmodel *made, ag_points_state *out, ag_error *err);

/* A point model from grammar text and its terminals (lookup: PLY bytes by path). Parse errors:
 * AG_ERR_PARSE with the line in err->element and the column in *col; a grammar whose
 * terminals are meshes: AG_ERR_PARSE saying so; a terminal lookup does not know: its problem,
 * naming the terminal. */
ag_status ag_points_state_read(const char *text, size_t len, ag_terminal_lookup lookup,
                               void *user, ag_pointmodel **out, ag_error *err, long *col);

/* pm (read from its text) with the tree a store kept beside that text (tree_text, the stored
 * tree: app/model_kept.h), so that its nodes have the ids the saved state gave them. A tree
 * that keeps none (stored before point models kept theirs, or tree_text NULL) leaves pm as
 * the text numbers it; one that is not a tree over pm's proxy: AG_ERR_PARSE. */
ag_status ag_points_state_reload_kept(ag_pointmodel *pm, const char *tree_text, ag_error *err);

/* The grammar text of a built model with its axiom in the input's coordinates (terminal paths
 * as the grammar has them). */
ag_status ag_points_state_text(ag_pointmodel *pm, char **text, size_t *len, ag_error *err);

#endif
