#include "weld_points.h"

#include <stdlib.h>

#include "../base/uf.h"

ag_status ag_weld_points(const double *pos, ag_keyed *order, size_t n, double tol,
                         uint32_t *par)
{
    if (ag_keysort(order, n, NULL) != AG_OK)
        return AG_ERR_NOMEM;
    /* the sets are over the entries of order (a vertex listed twice is at distance 0 from
     * itself, so its entries join) */
    ag_uf uf;
    ag_status st = ag_uf_init(&uf, n, 0);
    uint32_t *smallest = st == AG_OK ? malloc((n ? n : 1) * sizeof *smallest) : NULL;
    if (!smallest) {
        ag_uf_free(&uf);
        return st == AG_OK ? AG_ERR_NOMEM : st;
    }
    double t2 = tol * tol;
    for (size_t i = 0; i < n; i++) {
        const double *a = &pos[3 * order[i].val];
        for (size_t j = i + 1; j < n; j++) {
            const double *b = &pos[3 * order[j].val];
            if (b[0] - a[0] > tol)
                break;
            double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
            if (dx * dx + dy * dy + dz * dz <= t2)
                ag_uf_union(&uf, (uint32_t)i, (uint32_t)j);
        }
    }
    /* each vertex goes to the smallest vertex of its set */
    for (size_t i = 0; i < n; i++)
        smallest[i] = UINT32_MAX;
    for (size_t i = 0; i < n; i++) {
        uint32_t r = ag_uf_find(&uf, (uint32_t)i);
        if (order[i].val < smallest[r])
            smallest[r] = order[i].val;
    }
    for (size_t i = 0; i < n; i++)
        par[order[i].val] = smallest[ag_uf_find(&uf, (uint32_t)i)];
    free(smallest);
    ag_uf_free(&uf);
    return AG_OK;
}
