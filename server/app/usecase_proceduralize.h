/* The proceduralize use case, over any workspace (app/workspace.h): the workspace's mesh →
 * segment, label, tree, rules, patterns, export (core/proc) → verify: the grammar printed with
 * its terminals as they will be kept, read back, derived and compared with the input → the
 * model state read back from that grammar (its tree is the numbering a reload gives) → saved.
 * `archgram proceduralize` runs it into a folder, the proceduralize job into the store.
 *
 * Progress (to the workspace): each stage at a fixed fraction (segment 0.02 … verify 0.8,
 * 0.95 once verified); a cancellation is honoured between stages and before the save. */
#ifndef AG_USECASE_PROCEDURALIZE_H
#define AG_USECASE_PROCEDURALIZE_H

#include "../core/proc/proceduralize.h"
#include "workspace.h"

typedef struct {
    ag_segment_options segment;
    ag_label_options label;
    /* Save a grammar that does not reproduce every input triangle (a person looks at what went
     * wrong; the result says how many are missing). Otherwise nothing is saved and the use case
     * fails with AG_ERR_INTERNAL. */
    int save_unfaithful;
    /* A mesh with more triangles is refused before any work (AG_ERR_RESULT_TOO_LARGE);
     * 0: no limit. */
    size_t max_triangles;
} ag_usecase_proceduralize_params;

typedef struct {
    size_t triangles, components, labels, variants, rules, patterns, terminals;
    size_t grammar_bytes, terminal_bytes;
    double label_tolerance; /* file units: labels and shared terminals */
    ag_units units;         /* the file's length unit, given or decided (core/proc/units.h) */
    ag_fidelity fidelity;
    double total_s; /* up to the save, verify excluded */
} ag_usecase_proceduralize_result;

ag_status ag_usecase_proceduralize_run(ag_workspace *ws, const ag_usecase_proceduralize_params *p,
                                       ag_usecase_proceduralize_result *out, ag_error *err);

#endif
