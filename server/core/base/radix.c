#include "radix.h"

#include <stdlib.h>
#include <string.h>

#include "array.h"

#define RADIX_BITS 8
#define RADIX_SIZE (1u << RADIX_BITS)
#define RADIX_PASSES (64 / RADIX_BITS)

/* Below this an insertion sort beats the histograms. */
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

ag_status ag_radix_sort_with(ag_radix_item *a, size_t n, ag_radix_item *tmp)
{
    if (n < RADIX_SMALL) {
        insertion_sort(a, n);
        return AG_OK;
    }
    ag_radix_item *own = NULL;
    if (!tmp && !(tmp = own = malloc(n * sizeof *tmp)))
        return AG_ERR_NOMEM;
    /* every digit's histogram in one read of the keys */
    size_t count[RADIX_PASSES][RADIX_SIZE];
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < n; i++) {
        uint64_t k = a[i].key;
        for (int p = 0; p < RADIX_PASSES; p++)
            count[p][(k >> (p * RADIX_BITS)) & (RADIX_SIZE - 1)]++;
    }
    ag_radix_item *src = a, *dst = tmp;
    for (int p = 0; p < RADIX_PASSES; p++) {
        size_t *c = count[p];
        /* a digit every key shares leaves the order as it is */
        if (c[(a[0].key >> (p * RADIX_BITS)) & (RADIX_SIZE - 1)] == n)
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
    free(own);
    return AG_OK;
}

ag_status ag_radix_sort(ag_radix_item *a, size_t n)
{
    return ag_radix_sort_with(a, n, NULL);
}

ag_status ag_radix_index_build(ag_radix_index *x, const ag_radix_item *sorted, size_t n)
{
    memset(x, 0, sizeof *x);
    x->items = sorted;
    x->n = n;
    if (n == 0)
        return AG_OK;
    if (n >= UINT32_MAX)
        return AG_ERR_TOO_LARGE;
    size_t runs = 1;
    for (size_t i = 1; i < n; i++)
        runs += sorted[i].key != sorted[i - 1].key;
    size_t cap;
    ag_status st = ag_array_hash_size(runs, &cap);
    if (st)
        return st;
    x->key = malloc(cap * sizeof *x->key);
    x->start = malloc(cap * sizeof *x->start);
    if (!x->key || !x->start) {
        ag_radix_index_free(x);
        return AG_ERR_NOMEM;
    }
    x->mask = cap - 1;
    for (size_t i = 0; i < cap; i++)
        x->start[i] = UINT32_MAX;
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && sorted[i].key == sorted[i - 1].key)
            continue;
        uint64_t k = sorted[i].key, h = (k ^ (k >> 29)) * 0xbf58476d1ce4e5b9ULL;
        size_t j = (size_t)(h >> 17) & x->mask;
        while (x->start[j] != UINT32_MAX)
            j = (j + 1) & x->mask;
        x->key[j] = k;
        x->start[j] = (uint32_t)i;
    }
    return AG_OK;
}

void ag_radix_index_free(ag_radix_index *x)
{
    free(x->key);
    free(x->start);
    x->key = NULL;
    x->start = NULL;
}
