/* Pattern discovery by transformation-space analysis.
 *
 * Among the children of one node, the roots of one rule with one turn are compared by their
 * offsets. Per axis, the smallest offset that divides all others (within the tolerance) is
 * the step; when the roots fill a complete grid of counts[0] x counts[1] x counts[2] cells at
 * those steps (k <= 3 translation groups) they become one axis-aligned pattern (`subdivide`).
 * Otherwise the offsets are fitted to a lattice in any direction (the shortest offset, then
 * the shortest one off its line): a complete lattice is one pattern (`repeat`, e.g. windows
 * of a facade at an angle); an incomplete one gives its unbroken runs along the first vector.
 * Instances left over stay separate applications of the rule (irregular or rotated
 * repetitions). Each pattern's roots move under a new PATTERN node spanning them. */
#ifndef AG_PATTERNS_H
#define AG_PATTERNS_H

#include "../status.h"
#include "splittree.h"

typedef struct {
    size_t min_instances; /* smallest repetition emitted as a pattern; 0 = 2 */
} ag_patterns_options;

ag_status ag_patterns_find(ag_splittree *t, const ag_patterns_options *opt, ag_error *err);

#endif
