/* A point cloud proceduralized in one call (§3-§4 of "Procedural editing of building point
 * clouds"): segment decomposition (segment_cloud.h, with ROI refinement) → repetition
 * decomposition (repeat.h: a person's templates, then the automatic elements) → segments
 * carved down below the smallest segment's size dissolved, and unsegmented points given to the
 * nearest segment within T_C (farther ones are outliers) → consensus models per label of
 * repeated elements (consensus.h) → terminals and placements (the other segments as they are)
 * → split tree,
 * rules, patterns and grammar (pointmodel.h, core/proc). The seconds of each stage and the
 * completion per consensus label (points before and after) are reported. Core: no I/O. */
#ifndef AG_PROCEDURALIZE_CLOUD_H
#define AG_PROCEDURALIZE_CLOUD_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"
#include "cloud.h"
#include "consensus.h"
#include "pointmodel.h"
#include "repeat.h"
#include "segment_cloud.h"

typedef enum {
    AG_PCLOUD_SEGMENT,   /* §3.1, ROI refinement included */
    AG_PCLOUD_REPEAT,    /* §3.2 */
    AG_PCLOUD_ABSORB,    /* unsegmented points to their nearest segment */
    AG_PCLOUD_CONSENSUS, /* §4.1 */
    AG_PCLOUD_TREE,      /* §4.2-4.3: split tree, rules, patterns */
    AG_PCLOUD_GRAMMAR,   /* grammar export */
    AG_PCLOUD_STAGES
} ag_pcloud_stage;

const char *ag_proceduralize_cloud_stage_name(ag_pcloud_stage s);

typedef struct {
    ag_segment_cloud_options segment;
    const ag_box *rois;        /* cloud-local boxes segmented again, finer, in order */
    size_t nrois;
    const ag_box *templates;   /* cloud-local template boxes (repetition marking) */
    size_t ntemplates;
    int no_auto;               /* no automatic repetition */
    ag_repeat_options repeat;
    ag_consensus_options consensus; /* spacing 0: the segmentation's */
    /* Called at each stage; non-zero cancels (AG_ERR_CANCELLED). */
    int (*progress)(void *user, ag_pcloud_stage stage, double fraction);
    void *user;
} ag_proceduralize_cloud_options;

typedef struct {
    int32_t label;          /* the segmentation's label */
    int32_t terminal;       /* the model's terminal */
    size_t members, merged;
    size_t points_before;   /* the base member's */
    double mean_before;     /* per member */
    size_t points_after;    /* the consensus's */
    double cell;            /* thinning radius, metres */
} ag_pcloud_completion;

typedef struct ag_proceduralize_cloud_result {
    ag_pointmodel *model;              /* built */
    ag_segment_cloud_result *seg;      /* per point: segment, label (elements included) */
    size_t ntemplates;
    ag_repeat_report *templates;       /* per template */
    size_t auto_elements;
    size_t absorbed, outliers;         /* unsegmented points given to a segment, left out */
    size_t ncompletion;
    ag_pcloud_completion *completion;  /* per consensus label */
    double seconds[AG_PCLOUD_STAGES];
    double cpu_seconds[AG_PCLOUD_STAGES];
} ag_proceduralize_cloud_result;

/* Proceduralizes c (normals are added when it has none). AG_ERR_EMPTY when the cloud has no
 * points or no segment; AG_ERR_PARSE naming the first point that is not finite. */
ag_status ag_proceduralize_cloud_run(ag_cloud *c, const ag_proceduralize_cloud_options *opt,
                                     ag_proceduralize_cloud_result **out, ag_error *err);
void ag_proceduralize_cloud_free(ag_proceduralize_cloud_result *r);

#endif
