#include "keysort.h"

#include <stdlib.h>
#include <string.h>

/* Arrays up to this long are sorted by insertion. */
#define SHORT 32

ag_status ag_keysort(ag_keyed *v, size_t n, ag_keyed *tmp)
{
    if (n <= SHORT) {
        for (size_t i = 1; i < n; i++) {
            ag_keyed x = v[i];
            size_t j = i;
            for (; j > 0 && v[j - 1].key > x.key; j--)
                v[j] = v[j - 1];
            v[j] = x;
        }
        return AG_OK;
    }
    ag_keyed *own = NULL;
    if (!tmp) {
        tmp = own = malloc(n * sizeof *tmp);
        if (!own)
            return AG_ERR_NOMEM;
    }
    uint64_t all_or = 0, all_and = ~0ULL;
    for (size_t i = 0; i < n; i++) {
        all_or |= v[i].key;
        all_and &= v[i].key;
    }
    uint64_t differ = all_or ^ all_and; /* the bits some keys disagree on */
    ag_keyed *src = v, *dst = tmp;
    for (int shift = 0; shift < 64; shift += 8) {
        if (!((differ >> shift) & 0xff))
            continue;
        size_t count[257] = {0};
        for (size_t i = 0; i < n; i++)
            count[((src[i].key >> shift) & 0xff) + 1]++;
        for (int b = 0; b < 256; b++)
            count[b + 1] += count[b];
        for (size_t i = 0; i < n; i++)
            dst[count[(src[i].key >> shift) & 0xff]++] = src[i];
        ag_keyed *t = src;
        src = dst;
        dst = t;
    }
    if (src != v)
        memcpy(v, src, n * sizeof *v);
    free(own);
    return AG_OK;
}
