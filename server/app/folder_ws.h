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
 * the model's.
 *
 * The same folder keeps point models (app/points_folder_ws.h: the point operations, PLY
 * terminals): `archgram proceduralize CLOUD` reads the cloud file (cloud_path) and `archgram
 * edit` a point model's folder. */
#ifndef AG_FOLDER_WS_H
#define AG_FOLDER_WS_H

#include <stddef.h>

#include "../core/mesh.h"
#include "../io/obj.h"
#include "workspace.h"

struct ag_pointmodel;

typedef struct {
    const char *mesh_path; /* proceduralize: the mesh file, read with `up` */
    const char *cloud_path; /* proceduralize a cloud: the cloud file (PLY, LAS, LAZ, XYZ) */
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
    struct ag_pointmodel *pm, *pm_source; /* a point model edit's */
    ag_part **parts;       /* the bundle a composition read */
    size_t nparts;
    size_t input_bytes;    /* the mesh or cloud file's size */
    ag_up_decision up;     /* how its up axis was decided */
    double import_s;       /* reading it */
    int blamed;
    char blame[4200];
} ag_folder_ws;

void ag_folder_ws_init(ag_folder_ws *w, const ag_folder_ws_options *o);

/* mkdir -p: 0, or -1 with errno set. */
int ag_folder_ws_make_dirs(const char *dir);

/* For the point operations (app/points_folder_ws.c): the file a problem is about (NULL: the
 * message names it); writing a file (blaming nothing: the message names it); the out folder
 * and, with terminals, its terminals/ made; the folder a paste's source_dir names (relative to
 * the op file's folder) checked to be a folder, into dir. */
void ag__folder_ws_blame(ag_folder_ws *w, const char *file);
ag_status ag__folder_ws_write_file(ag_folder_ws *w, const char *path, const char *data,
                                   size_t len, ag_error *err);
/* j (may be NULL: out of memory) as JSON with flags. */
ag_status ag__folder_ws_write_json(ag_folder_ws *w, const char *path, json_t *j, size_t flags,
                                   ag_error *err);
ag_status ag__folder_ws_make_out(ag_folder_ws *w, int terminals, ag_error *err);
ag_status ag__folder_ws_source_dir(ag_folder_ws *w, const char *sdir, char *dir, size_t cap,
                                   ag_error *err);
/* A paste's source_model is the service's: refused, naming the op file. */
ag_status ag__folder_ws_check_origin(ag_folder_ws *w, const ag_edit_op_origin *from,
                                     ag_error *err);
/* grammar.txt and the terminal files it names into the out folder. */
ag_status ag__folder_ws_write_grammar(ag_folder_ws *w, const char *text, size_t len,
                                      const ag_terminal_set *terms, ag_error *err);
/* The split tree's figures summaries give: {"nodes","visible","invisible","depth",
 * "adjacent_pairs"} (a new reference, NULL when out of memory). */
json_t *ag__folder_ws_tree_figures(const ag_splittree *t);
/* Sets "patterns" (rule, counts, step, kind, vectors, rot, instances of each), "grammar_bytes"
 * and "terminal_bytes" on summary j. */
void ag__folder_ws_model_figures(json_t *j, const ag_proceduralize_result *r, size_t grammar_bytes,
                                 size_t terminal_bytes);
/* The point operations of the folder workspace (app/points_folder_ws.c). */
ag_status ag__folder_ws_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                    ag_cloud_state *cs, ag_error *err);
ag_status ag__folder_ws_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                          struct ag_pointmodel **pm,
                                          const struct ag_pointmodel **source, ag_error *err);
ag_status ag__folder_ws_save_points(ag_workspace *ws, struct ag_points_state *st,
                                    const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                    ag_error *err);

#endif
