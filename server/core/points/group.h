/* Points grouped by an id: the members of each group in one array (compressed rows), the
 * layout segments, footprints, labels and placements share.
 *
 * group[i] in [0, ngroups) puts point i in that group; a negative id leaves it out. The
 * members of group g are members[start[g] .. start[g + 1]), ascending. */
#ifndef AG_GROUP_H
#define AG_GROUP_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef struct {
    size_t ngroups;
    uint32_t *start;   /* ngroups + 1 offsets */
    uint32_t *members; /* point indices, ascending within each group */
} ag_group;

/* Groups n points by group[i]; ids at or past ngroups are refused (AG_ERR_INVALID), n must be
 * below 2^32 (AG_ERR_TOO_LARGE). g is overwritten (free it with ag_group_free). */
ag_status ag_group_build(ag_group *g, const int32_t *group, size_t n, size_t ngroups,
                         ag_error *err);
void ag_group_free(ag_group *g);

/* Number of members of group k. */
static inline size_t ag_group_size(const ag_group *g, size_t k)
{
    return g->start[k + 1] - g->start[k];
}

/* The members of group k. */
static inline const uint32_t *ag_group_members(const ag_group *g, size_t k)
{
    return g->members + g->start[k];
}

#endif
