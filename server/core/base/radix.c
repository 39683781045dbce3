#include "radix.h"

#include <stdlib.h>
#include <string.h>

#define RADIX_BITS 11
#define RADIX_SIZE (1u << RADIX_BITS)
#define RADIX_PASSES ((64 + RADIX_BITS - 1) / RADIX_BITS) /* 6 */

/* Below this a comparison-free insertion sort beats the histogram set-up. */
#define RADIX_SMALL 64

static void insertion_sort(ag_radix_item *a, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        ag_radix_item x = a[i];
        size_t j = i;
        while (j > 0 && a[j - 1].key > x.key) {
            a[j] = a[j - 1];
            j--;
        }
        a[j] = x;
    }
}

ag_status ag_radix_sort(ag_radix_item *a, size_t n)
{
    if (n < RADIX_SMALL) {
        insertion_sort(a, n);
        return AG_OK;
    }
    size_t(*count)[RADIX_SIZE] = calloc(RADIX_PASSES, sizeof *count);
    ag_radix_item *tmp = malloc(n * sizeof *tmp);
    if (!count || !tmp) {
        free(count);
        free(tmp);
        return AG_ERR_NOMEM;
    }
    /* every digit's histogram in one read of the keys */
    for (size_t i = 0; i < n; i++) {
        uint64_t k = a[i].key;
        for (int p = 0; p < RADIX_PASSES; p++)
            count[p][(k >> (p * RADIX_BITS)) & (RADIX_SIZE - 1)]++;
    }
    ag_radix_item *src = a, *dst = tmp;
    for (int p = 0; p < RADIX_PASSES; p++) {
        size_t *c = count[p];
        /* a digit every key shares leaves the order as it is */
        int trivial = 0;
        for (size_t d = 0; d < RADIX_SIZE && !trivial; d++)
            trivial = c[d] == n;
        if (trivial)
            continue;
        size_t sum = 0;
        for (size_t d = 0; d < RADIX_SIZE; d++) {
            size_t k = c[d];
            c[d] = sum;
            sum += k;
        }
        int shift = p * RADIX_BITS;
        for (size_t i = 0; i < n; i++)
            dst[c[(src[i].key >> shift) & (RADIX_SIZE - 1)]++] = src[i];
        ag_radix_item *s = src;
        src = dst;
        dst = s;
    }
    if (src != a)
        memcpy(a, src, n * sizeof *a);
    free(tmp);
    free(count);
    return AG_OK;
}
