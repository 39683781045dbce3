/* A folder as a workspace for point models (app/workspace.h, the point operations), the layout
 * `archgram proceduralize CLOUD` and `archgram edit` of a point model write:
 *
 *   DIR/grammar.txt   the grammar (schema/grammar.md), its axiom in the input's coordinates
 *   DIR/terminals/    the PLY terminals it names
 *   DIR/tree.json     the split tree with the node ids edit ops name (app/model_tree.h)
 *   DIR/summary.json  what the proceduralization (per-stage seconds, counts, completion per
 *                     label, fidelity) or the edit found
 *
 * A folder keeps only the grammar and its terminals: a model is read as its grammar derived
 * (the states saved are read back already, so tree.json holds the ids the next load gives).
 * After a failure, when `blamed` is set, `blame` names the file the problem is about. */
#ifndef AG_POINTS_FOLDER_WS_H
#define AG_POINTS_FOLDER_WS_H

#include <stddef.h>

#include "../core/points/pointmodel.h"
#include "workspace.h"

typedef struct {
    const char *cloud_path; /* proceduralize: the cloud file (PLY, LAS, LAZ, XYZ) */
    const char *in_dir;     /* edit: the point model's folder */
    const char *op_path;    /* edit: the op file; a paste's source_dir is relative to its folder */
    const char *out_dir;    /* where saves go (created with its parents) */
} ag_points_folder_ws_options;

typedef struct {
    ag_workspace ws;
    ag_points_folder_ws_options o;
    ag_pointmodel *pm, *source;
    size_t input_bytes; /* the cloud file's size */
    double read_s;      /* reading it */
    int blamed;
    char blame[4200];
} ag_points_folder_ws;

void ag_points_folder_ws_init(ag_points_folder_ws *w, const ag_points_folder_ws_options *o);

/* Whether DIR/grammar.txt names point terminals (a point model's folder). */
int ag_points_folder_is_point_model(const char *dir);
/* Whether a grammar file names point terminals. */
int ag_points_grammar_file_is_points(const char *grammar_path);

/* A point model from a grammar file and the PLY terminals next to it (`archgram derive`). */
ag_status ag_points_folder_read_grammar(const char *grammar_path, ag_pointmodel **out,
                                        ag_error *err, long *col);

#endif
