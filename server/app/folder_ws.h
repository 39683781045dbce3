/* A folder as a workspace (app/workspace.h), the layout `archgram proceduralize` and
 * `archgram edit` write:
 *
 *   DIR/grammar.txt   the grammar (schema/grammar.md)
 *   DIR/terminals/    the terminal OBJ files it names
 *   DIR/tree.json     the split tree with the node ids edit ops name (app/model_tree.h)
 *   DIR/summary.json  what the proceduralization, the edit or the composition found and how
 *                     long it took
 *
 * Parts are bundle files (schema/part_bundle.md): a composition reads the one its ref names
 * (ag_part_ref.path, .name), a part save writes `bundle_out` through a temporary file, so a
 * failed save leaves nothing; a part's provenance is the folder's name, not a path.
 * A folder keeps only the grammar: a model is read as its grammar derived and proceduralized
 * anew, and the use cases save the model they read back (AG_MODEL_READ_BACK), so the ids in
 * tree.json are the ids the next load gives. The mesh to proceduralize comes from a mesh file
 * of any importable format. After a failure, when `blamed` is set, `blame` names the file the
 * problem is about ("" when the message names it itself); otherwise the problem is the op's or
 * the model's. */
#ifndef AG_FOLDER_WS_H
#define AG_FOLDER_WS_H

#include <stddef.h>

#include "../core/mesh.h"
#include "../io/obj.h"
#include "workspace.h"

typedef struct {
    const char *mesh_path; /* proceduralize: the mesh file, read with `up` */
    ag_up_axis up;
    const char *in_dir;    /* edit: the proceduralized folder to edit */
    const char *op_path;   /* edit: the op file; a paste's source_dir is relative to its folder */
    const char *out_dir;   /* where saves go (created with its parents) */
    const char *bundle_out; /* part save: the bundle file to write */
} ag_folder_ws_options;

typedef struct {
    ag_workspace ws;
    ag_folder_ws_options o;
    ag_edit_model *em, *source;
    ag_part **parts;       /* the bundle a composition read */
    size_t nparts;
    size_t input_bytes;    /* the mesh file's size */
    ag_up_decision up;     /* how its up axis was decided */
    double import_s;       /* reading it */
    int blamed;
    char blame[4200];
} ag_folder_ws;

void ag_folder_ws_init(ag_folder_ws *w, const ag_folder_ws_options *o);

/* mkdir -p: 0, or -1 with errno set. */
int ag_folder_ws_make_dirs(const char *dir);

#endif
