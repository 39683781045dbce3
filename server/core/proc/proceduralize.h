/* The proceduralization pipeline in one call: segment → label → split tree → rules →
 * patterns → grammar, with the seconds spent in each stage. Import and file output are the
 * caller's (io layer). */
#ifndef AG_PROCEDURALIZE_H
#define AG_PROCEDURALIZE_H

#include "../mesh.h"
#include "../status.h"
#include "grammar.h"
#include "label.h"
#include "patterns.h"
#include "rules.h"
#include "segment.h"
#include "splittree.h"

typedef enum {
    AG_STAGE_SEGMENT,
    AG_STAGE_LABEL,
    AG_STAGE_TREE,
    AG_STAGE_RULES,
    AG_STAGE_PATTERNS,
    AG_STAGE_EXPORT,
    AG_STAGE_VERIFY,
    AG_STAGE_COUNT
} ag_stage;

const char *ag_proceduralize_stage_name(ag_stage s);

typedef struct {
    ag_segment_options segment;
    ag_label_options label;
    ag_patterns_options patterns;
    int verify;  /* non-zero: derive the grammar in memory and measure the fidelity */
    /* Called when a stage starts; non-zero return cancels (AG_ERR_CANCELLED). May be NULL. */
    int (*progress)(void *user, ag_stage stage);
    void *user;
} ag_proceduralize_options;

typedef struct {
    ag_mesh *mesh;            /* the segmented mesh */
    ag_segment_info segment;
    ag_labels *labels;
    ag_splittree *tree;
    ag_grammar *grammar;
    ag_grammar_export_info info;
    ag_fidelity fidelity;     /* when verify was asked */
    double seconds[AG_STAGE_COUNT];
} ag_proceduralize_result;

ag_status ag_proceduralize_run(const ag_mesh *in, const ag_proceduralize_options *opt,
                               ag_proceduralize_result **out, ag_error *err);
void ag_proceduralize_result_free(ag_proceduralize_result *r);

#endif
