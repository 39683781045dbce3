/* A proceduralized model as a workspace keeps it: its grammar text, the terminals the text
 * names (OBJ text by path), the mesh the grammar derives, and the edit model whose split tree
 * numbers the nodes (app/model_tree.h).
 *
 * The edit model's mesh (em->proc->mesh) is the model's mesh: the components in the order the
 * tree's components name them, in groups named as the grammar names its labels. An edit model
 * is rebuilt from that mesh and the tree stored with it (ag_model_state_reload_kept gives the
 * same tree, node for node: an edit keeps the ids of the nodes it did not remove, which
 * proceduralizing its mesh again would not), so a workspace that keeps the mesh and its tree
 * (the store) reloads exactly the model it saved; one that
 * keeps only the grammar (a folder) reads it back: the grammar derived and proceduralized
 * anew, which is the edit model AG_MODEL_READ_BACK makes before saving. */
#ifndef AG_MODEL_STATE_H
#define AG_MODEL_STATE_H

#include <stddef.h>

#include "../core/edit/edit.h"
#include "../core/status.h"
#include "../io/terminals.h"

/* Largest grammar text accepted from outside (PUT …/grammar). */
#define AG_GRAMMAR_TEXT_MAX ((size_t)8 << 20)
/* Derivations larger than this are refused (AG_ERR_TOO_LARGE). */
#define AG_GRAMMAR_MAX_TRIANGLES ((size_t)20000000)

/* Where making a state from a grammar spent its time (ag_model_state_from_grammar_ex). */
typedef struct {
    double terminals_ms; /* the terminals collected with their OBJ text */
    double text_ms;      /* the grammar printed */
    double read_back_ms; /* the text parsed, its terminals loaded and derived (a started
                            state: the grammar itself derived, the text read back beside) */
    double model_ms;     /* the edit model made (the maker, or proceduralized) */
    double check_ms;     /* a started state: the read-back check beside (once checked) */
} ag_model_state_times;

typedef struct {
    char *text;            /* the grammar, NUL-terminated */
    size_t text_len;
    ag_terminal_set terms; /* the terminals the text names (made states) */
    ag_mesh *derived;      /* what the text derives (with the terminals as kept) */
    ag_edit_model *em;     /* the edit model; em->proc->mesh is the model's mesh */
    ag_model_state_times times; /* made from a grammar: its stages */
    struct ag_model_state_check *check; /* a read-back check still running (ag_model_state_start) */
} ag_model_state;

void ag_model_state_clear(ag_model_state *s);

enum { AG_MODEL_READ_BACK = 1 };

/* The state of a model a proceduralization or an edit made: its grammar printed with its
 * terminals, checked to read back (the text, with the terminals as they will be kept, parses
 * and derives), and the edit model: with AG_MODEL_READ_BACK the derivation proceduralized
 * anew (*made stays the caller's), else *made itself, moved into out (*made = NULL), its
 * mesh's groups renamed to the grammar's label names. */
ag_status ag_model_state_make(ag_edit_model **made, unsigned flags, ag_model_state *out,
                              ag_error *err);

/* ag_model_state_make without AG_MODEL_READ_BACK whose check runs on: *made is moved into out
 * at once (its mesh's groups renamed) while the grammar is printed, read back and derived on a
 * thread of its own, so the caller can encode the model meanwhile. text, terms and derived
 * are out's only after ag_model_state_checked says AG_OK, and out stays where it is until
 * then (the check writes into it); with AG_MODEL_READ_BACK (which needs the derivation
 * first) it is ag_model_state_make. */
ag_status ag_model_state_start(ag_edit_model **made, unsigned flags, ag_model_state *out,
                               ag_error *err);
/* Waits for a started check: AG_OK when the grammar reads back (at once for a state made any
 * other way), else its problem (the state keeps its edit model; clear it). */
ag_status ag_model_state_checked(ag_model_state *st, ag_error *err);

/* Work on a state's derivation (read only) that needs nothing of its edit model. */
typedef ag_status (*ag_model_state_beside)(void *user, const ag_mesh *derived, ag_error *err);
/* ag_model_state_make that also runs beside on the derivation, with AG_MODEL_READ_BACK on a
 * thread of its own while the derivation is proceduralized (the two share no state), else
 * before *made is moved; a failure of beside is the call's (*made then stays the caller's). */
ag_status ag_model_state_make_beside(ag_edit_model **made, unsigned flags,
                                     ag_model_state_beside beside, void *user,
                                     ag_model_state *out, ag_error *err);

/* The state of a model given as a grammar (a composition's result, resolved, terminals with
 * geometry): the grammar itself printed with its terminals (g's terminal paths are set as
 * they will be kept), checked to read back, and the edit model of what it derives, so the
 * text kept is the grammar as it was made while the tree numbers the derived mesh as a reload
 * does. A derivation past max_triangles (0: AG_GRAMMAR_MAX_TRIANGLES) is AG_ERR_TOO_LARGE. */
ag_status ag_model_state_from_grammar(ag_grammar *g, size_t max_triangles, ag_model_state *out,
                                      ag_error *err);

/* Makes the edit model of what a state's grammar derives (the derivation stays the state's). */
typedef ag_status (*ag_model_state_maker)(void *user, const ag_mesh *derived, ag_edit_model **em,
                                          ag_error *err);
/* ag_model_state_from_grammar with the edit model made by make (NULL: the derivation
 * proceduralized, ag_model_state_reload). */
ag_status ag_model_state_from_grammar_ex(ag_grammar *g, size_t max_triangles,
                                         ag_model_state_maker make, void *user,
                                         ag_model_state *out, ag_error *err);

/* ag_model_state_from_grammar_ex whose read-back runs beside the maker: g (its terminals
 * given the geometry their kept text reads as) is derived at once and that derivation given
 * to make, while a thread prints g, reads the text back and checks that it derives the same
 * mesh, byte for byte (if not, the check is AG_ERR_INTERNAL naming what differs). The
 * check takes *g (*g = NULL; it frees it; where no thread can start it runs first and *g
 * stays the caller's). As for ag_model_state_start, text and terms are out's only after
 * ag_model_state_checked says AG_OK, and out stays where it is until then; clearing out
 * waits for the check. */
ag_status ag_model_state_from_grammar_start(ag_grammar **g, size_t max_triangles,
                                            ag_model_state_maker make, void *user,
                                            ag_model_state *out, ag_error *err);

/* OBJ text of the terminal kept under path: AG_OK with *obj malloc'd, AG_ERR_NOT_FOUND when
 * there is none. */
typedef ag_status (*ag_terminal_lookup)(void *user, const char *path, char **obj, size_t *len,
                                        ag_error *err);

/* A grammar text with its terminals from lookup (a grammar text edit): parsed, derived and
 * proceduralized; out->terms stays empty (the text names terminals the model keeps). Parse errors (syntax, names): AG_ERR_PARSE
 * with the line in err->element and the column in *col; a terminal path lookup does not know:
 * AG_ERR_PARSE at the terminal's declaration, naming it; a grammar that derives nothing:
 * AG_ERR_EMPTY; a derivation larger than AG_GRAMMAR_MAX_TRIANGLES: AG_ERR_TOO_LARGE. */
/* budget (may be NULL) bounds the derivation (AG_ERR_RESULT_TOO_LARGE past its limits) and
 * is asked between the stages of proceduralizing it. */
ag_status ag_model_state_from_text(const char *text, size_t len, ag_terminal_lookup lookup,
                                   void *user, const ag_edit_budget *budget,
                                   ag_model_state *out, ag_error *err, long *col);

/* The edit model of a model mesh proceduralized (a mesh kept without its tree). */
ag_status ag_model_state_reload(const ag_mesh *mesh, ag_edit_model **em, ag_error *err);

/* The edit model of a kept model mesh and its stored tree text (the store's reload): made
 * from what the tree keeps (app/model_kept.h), so an edited model comes back node for node;
 * a tree that keeps nothing (NULL, or stored before) proceduralizes the mesh. AG_ERR_PARSE
 * for a kept model that does not fit the mesh. */
ag_status ag_model_state_reload_kept(const ag_mesh *mesh, const char *tree_text,
                                     ag_edit_model **em, ag_error *err);

#endif
