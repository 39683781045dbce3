/* Consensus models (§4.1, Algorithm 1): the members of one label (copies of one element,
 * each sampled partly) merged into one completed model.
 *
 * The base is the member with the most points, the most completely sampled one. The paper's
 * FINDBASE registers every pair of members (O(k^2) ICP runs at full resolution); here every
 * other member is registered once, to the base (O(k) runs, each on a subsample of the member:
 * register.h), starting from the caller's offsets when it has them (template matches), and
 * merged when its residual is below T_c and most of it pairs with the base. The merged set is
 * thinned back to the base's density (resample.h), keeping input points and their
 * properties, and gets kNN normals. The completion is reported per label: the base's points
 * before, the consensus's after. */
#ifndef AG_CONSENSUS_H
#define AG_CONSENSUS_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"
#include "cloud.h"
#include "register.h"

typedef struct {
    double spacing;     /* point spacing of the data, metres (> 0) */
    double max_rms;     /* T_c: members with a larger residual are not merged; 0 = 1.5 spacings */
    double min_inliers; /* share of a member's samples that must pair; 0 = 0.6 */
    unsigned samples;   /* ICP samples per member; 0 = 256 */
} ag_consensus_options;

typedef struct {
    int merged;               /* registered well enough to be part of the consensus */
    ag_register_result reg;   /* member -> base (the base's own: identity) */
} ag_consensus_member;

typedef struct {
    ag_cloud *points;            /* the consensus in the base's (cloud-local) coordinates, with
                                  * every property of the input and kNN normals */
    ag_box box;                  /* its bounds */
    size_t base;                 /* the base member */
    size_t nmembers;
    ag_consensus_member *members;
    size_t merged;               /* members merged, the base included */
    size_t points_before;        /* the base's points */
    double mean_before;          /* points per member, on average */
    size_t pooled;               /* points of the merged members before thinning */
    size_t points_after;         /* the consensus's points */
    double cell;                 /* thinning radius (0: nothing thinned) */
} ag_consensus_model;

/* The members: k point sets of c (member j: idx[start[j] .. start[j + 1])), their boxes and,
 * optionally, starting offsets (3 per member: the translation from member j's box min to the
 * base's box min, e.g. template matches; NULL: none). c needs normals. */
ag_status ag_consensus_build(const ag_cloud *c, const uint32_t *idx, const uint32_t *start,
                             const ag_box *boxes, size_t k, const double *offsets,
                             const ag_consensus_options *o, ag_consensus_model *out,
                             ag_error *err);
void ag_consensus_model_clear(ag_consensus_model *m);

#endif
