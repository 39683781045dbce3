/* Reading a cloud segmentation against the generated building's truth, shared by the
 * segmentation tests. */
#ifndef AG_TEST_SEGMENT_FIXTURE_H
#define AG_TEST_SEGMENT_FIXTURE_H

#include <stdint.h>
#include <stdlib.h>

#include "core/points/cloud.h"
#include "core/points/segment_cloud.h"

/* The segment most of the points of truth plane `plane` went to (-1: none). */
static inline int32_t sf_majority(const ag_cloud *c, const int32_t *truth,
                                  const ag_segment_cloud_result *r, int32_t plane)
{
    size_t *votes = calloc(r->nsegments + 1, sizeof *votes);
    int32_t best = -1;
    for (size_t i = 0; votes && i < c->n; i++)
        if (truth[i] == plane && r->segment[i] >= 0) {
            votes[r->segment[i]]++;
            if (best < 0 || votes[r->segment[i]] > votes[best])
                best = r->segment[i];
        }
    free(votes);
    return best;
}

#endif
