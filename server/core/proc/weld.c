#include "weld.h"

#include <math.h>
#include <stdlib.h>

#include "../base/array.h"

ag_status ag__weld(const double *pos, size_t n, double cell, uint32_t *ids, size_t *count)
{
    size_t cap;
    if (ag_array_hash_size(n, &cap))
        return AG_ERR_TOO_LARGE;
    uint32_t *slot = malloc(cap * sizeof *slot); /* first vertex of the id + 1, 0 = empty */
    int64_t *key = malloc(3 * n * sizeof *key);
    if (!slot || !key) {
        free(slot);
        free(key);
        return AG_ERR_NOMEM;
    }
    for (size_t i = 0; i < cap; i++)
        slot[i] = 0;
    size_t next = 0;
    for (size_t v = 0; v < n; v++) {
        for (int a = 0; a < 3; a++)
            key[3 * v + a] = (int64_t)floor(pos[3 * v + a] / cell + 0.5);
        uint64_t h = ag__cell_hash(key[3 * v], key[3 * v + 1], key[3 * v + 2]);
        size_t i = h & (cap - 1);
        for (;;) {
            if (!slot[i]) {
                slot[i] = (uint32_t)v + 1;
                ids[v] = (uint32_t)next++;
                break;
            }
            uint32_t w = slot[i] - 1;
            if (key[3 * w] == key[3 * v] && key[3 * w + 1] == key[3 * v + 1] &&
                key[3 * w + 2] == key[3 * v + 2]) {
                ids[v] = ids[w];
                break;
            }
            i = (i + 1) & (cap - 1);
        }
    }
    free(slot);
    free(key);
    *count = next;
    return AG_OK;
}
