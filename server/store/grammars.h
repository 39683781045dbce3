/* The grammars and terminals tables (migration 0002): the split grammar that derives a
 * model's mesh, its split tree and summary (JSON text, written by the app layer), and the
 * terminal OBJ files the grammar names, by path.
 *
 * A grammar describes its model while the model's mesh is still the one it was stored with
 * (models.mesh_blob): ops that leave the geometry alone (rename, note) keep it current; a new
 * mesh without a grammar would end it. Only a model's newest grammar row is kept. Every write
 * runs inside the caller's transaction (ag_db_begin).
 *
 * A grammar row whose tree is '' (schema 11) has its tree in the model_states row of its
 * version (ag_states_keep_with_tree): an edit writes its large tree once, not once here and
 * once more as the version's kept state. Reads give the tree either way. */
#ifndef AG_GRAMMARS_H
#define AG_GRAMMARS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

typedef struct {
    int64_t model;
    int64_t version;       /* the model version that stored it */
    int64_t model_version; /* the model's current version (ag_grammars_current) */
    int64_t mesh_blob;
    char *text;            /* malloc'd, NUL-terminated */
    size_t text_len;
    char *tree_json;       /* malloc'd; NULL unless asked for */
    int tree_numbering;    /* which numbering tree_json uses (the app's, see migration 0005) */
    char *summary_json;    /* malloc'd */
} ag_grammar_row;

void ag_grammars_row_clear(ag_grammar_row *row);

typedef struct {
    int64_t model;
    int64_t version;
    int64_t mesh_blob;
    const char *text;
    size_t text_len;
    const char *tree_json;
    int tree_numbering;       /* stored as given */
    const char *summary_json; /* NULL = "{}" */
} ag_grammar_new;

/* Stores a grammar and drops the model's older ones. */
ag_status ag_grammars_put(ag_db *db, const ag_grammar_new *g, ag_error *err);

/* The grammar of the model's current mesh. with_tree: also read the tree JSON (it can be
 * large). AG_ERR_NOT_FOUND when the model does not exist or has no current grammar (the
 * message says which). */
ag_status ag_grammars_current(ag_db *db, int64_t model, int with_tree, ag_grammar_row *row,
                              ag_error *err);

/* Replaces the tree of the model's grammar for mesh_blob (a tree rebuilt in another
 * numbering); AG_OK and nothing changed when that grammar is no longer the model's. */
ag_status ag_grammars_set_tree(ag_db *db, int64_t model, int64_t mesh_blob, const char *tree_json,
                               int tree_numbering, ag_error *err);

/* *yes = 1 when the model (with this mesh file) has a current grammar. */
ag_status ag_grammars_is_current(ag_db *db, int64_t model, int64_t mesh_blob, int *yes,
                                 ag_error *err);

/* Removes every terminal of the model. */
ag_status ag_grammars_clear_terminals(ag_db *db, int64_t model, ag_error *err);
/* Stores a terminal; a path already stored keeps its content (paths name their content). */
ag_status ag_grammars_put_terminal(ag_db *db, int64_t model, const char *path, const char *obj,
                                   size_t len, ag_error *err);
/* *obj malloc'd and NUL-terminated; AG_ERR_NOT_FOUND when the model has no such terminal. */
ag_status ag_grammars_get_terminal(ag_db *db, int64_t model, const char *path, char **obj,
                                   size_t *len, ag_error *err);
size_t ag_grammars_count_terminals(ag_db *db, int64_t model);

#endif
