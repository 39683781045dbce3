/* Grammar text → derived model: parse, load the terminals a model has stored, derive the mesh
 * and read the split tree off the derivation (io/splittree_json.h). The proceduralize job
 * stores its result through the same path, so a stored grammar, its mesh and its tree always
 * agree, and PUT of the same text gives the same mesh.
 *
 * PUT /api/v1/models/{id}/grammar: ag_grammar_edit_apply stores the derived mesh, the text
 * and the tree as a new model version in one transaction and logs the op
 * {"kind":"grammar","bytes":N}. The states before and after are kept (store/states.h), so
 * the grammar edit is one undo step of its author like a structural edit. The terminals stay
 * as they were: a grammar may use any of the model's stored terminals (by their path) and no
 * other. */
#ifndef AG_GRAMMAR_EDIT_H
#define AG_GRAMMAR_EDIT_H

#include <stddef.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "../core/proc/grammar.h"
#include "app.h"

/* Largest grammar text accepted by PUT. */
#define AG_GRAMMAR_TEXT_MAX ((size_t)8 << 20)
/* Derivations larger than this are refused (AG_ERR_TOO_LARGE). */
#define AG_GRAMMAR_EDIT_MAX_TRIANGLES ((size_t)20000000)

/* OBJ text of the terminal stored under path: AG_OK with *obj malloc'd, AG_ERR_NOT_FOUND
 * when there is none. */
typedef ag_status (*ag_terminal_lookup)(void *user, const char *path, char **obj, size_t *len,
                                        ag_error *err);

typedef struct {
    ag_grammar *grammar; /* parsed, terminals loaded */
    ag_mesh *mesh;       /* derived */
    char *tree_json;     /* io/splittree_json.h */
    size_t ncomponents;  /* placed terminals = components of mesh */
} ag_grammar_derived;

void ag_grammar_derived_clear(ag_grammar_derived *d);

/* Parse errors (syntax, names): AG_ERR_PARSE with the line in err->element and the column in
 * *col. A terminal whose path lookup does not know: AG_ERR_PARSE at the terminal's
 * declaration, naming it. A grammar that derives nothing: AG_ERR_EMPTY. */
ag_status ag_grammar_edit_derive(const char *text, size_t len, ag_terminal_lookup lookup,
                                 void *user, ag_grammar_derived *out, ag_error *err, long *col);

/* The whole PUT: AG_ERR_NOT_FOUND when the model does not exist or was never proceduralized,
 * parse errors as above, AG_ERR_STALE when base is not the current version. *version gets
 * the new version. */
ag_status ag_grammar_edit_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                                const char *cid, const char *text, size_t len, int64_t *version,
                                ag_error *err, long *col);

/* Stores a derived grammar for the version a server op is raising (the caller's transaction):
 * the mesh and its stats, the text, the tree and the summary JSON. */
ag_status ag_grammar_edit_store(ag_db *db, int64_t model, int64_t version,
                                const ag_grammar_derived *d, const char *text, size_t len,
                                const char *summary_json, ag_error *err);

#endif
