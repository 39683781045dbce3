/* The point operations of the folder workspace (app/folder_ws.h), the layout `archgram
 * proceduralize CLOUD` and `archgram edit` of a point model write:
 *
 *   DIR/grammar.txt   the grammar (schema/grammar.md), its axiom in the input's coordinates
 *   DIR/terminals/    the PLY terminals it names
 *   DIR/tree.json     the split tree with the node ids edit ops name (app/model_tree.h), boxes
 *                     in the input's coordinates
 *   DIR/summary.json  what the proceduralization (per-stage seconds, counts, completion per
 *                     label, fidelity) or the edit found (app/points_summary.h)
 *
 * A folder keeps only the grammar and its terminals: a model is read as its grammar derived
 * (the states saved are read back already, so tree.json holds the ids the next load gives).
 * The cloud to proceduralize is the options' cloud_path, read with every property; a folder
 * keeps no segmentation of it. */
#ifndef AG_POINTS_FOLDER_WS_H
#define AG_POINTS_FOLDER_WS_H

#include "../core/points/pointmodel.h"
#include "folder_ws.h"

/* Whether DIR/grammar.txt names point terminals (a point model's folder). */
int ag_points_folder_is_point_model(const char *dir);
/* Whether a grammar file names point terminals. */
int ag_points_grammar_file_is_points(const char *grammar_path);

/* A point model from a grammar file and the PLY terminals next to it (`archgram derive`). */
ag_status ag_points_folder_read_grammar(const char *grammar_path, ag_pointmodel **out,
                                        ag_error *err, long *col);

#endif
