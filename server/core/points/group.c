#include "group.h"

#include <stdlib.h>
#include <string.h>

void ag_group_free(ag_group *g)
{
    free(g->start);
    free(g->members);
    memset(g, 0, sizeof *g);
}

ag_status ag_group_build(ag_group *g, const int32_t *group, size_t n, size_t ngroups,
                         ag_error *err)
{
    memset(g, 0, sizeof *g);
    if (n >= UINT32_MAX || ngroups >= UINT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points are too many to group", n);
    size_t total = 0;
    for (size_t i = 0; i < n; i++) {
        if (group[i] < 0)
            continue;
        if ((size_t)group[i] >= ngroups)
            return ag_error_set(err, AG_ERR_INVALID, 0, "point %zu is in group %d of %zu", i + 1,
                                (int)group[i], ngroups);
        total++;
    }
    g->start = calloc(ngroups + 1, sizeof *g->start);
    g->members = malloc((total ? total : 1) * sizeof *g->members);
    uint32_t *fill = malloc((ngroups + 1) * sizeof *fill);
    if (!g->start || !g->members || !fill) {
        free(fill);
        ag_group_free(g);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    g->ngroups = ngroups;
    for (size_t i = 0; i < n; i++)
        if (group[i] >= 0)
            g->start[group[i] + 1]++;
    for (size_t k = 0; k < ngroups; k++)
        g->start[k + 1] += g->start[k];
    memcpy(fill, g->start, (ngroups + 1) * sizeof *fill);
    for (size_t i = 0; i < n; i++)
        if (group[i] >= 0)
            g->members[fill[group[i]]++] = (uint32_t)i;
    free(fill);
    return AG_OK;
}
