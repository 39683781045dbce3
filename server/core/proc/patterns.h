/* Pattern discovery by transformation-space analysis.
 *
 * Among the children of one node, the roots of one rule with one turn are compared by their
 * pairwise offsets along x, y and z: per axis, the smallest offset that divides all others
 * (within the tolerance) is the step. When the roots fill a complete grid of
 * counts[0] x counts[1] x counts[2] cells at that step (k <= 3 translation groups), they are
 * moved under a new PATTERN node whose box spans them, emitted as `subdivide`. When they do
 * not, rows along one axis that are complete are tried; the rest stay separate applications
 * of the rule (irregular or rotated repetitions). */
#ifndef AG_PATTERNS_H
#define AG_PATTERNS_H

#include "../status.h"
#include "splittree.h"

typedef struct {
    size_t min_instances; /* smallest repetition emitted as a pattern; 0 = 2 */
} ag_patterns_options;

ag_status ag_patterns_find(ag_splittree *t, const ag_patterns_options *opt, ag_error *err);

#endif
