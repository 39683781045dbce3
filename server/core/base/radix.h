/* Stable LSD radix sort of (64-bit key, 32-bit value) records, O(n) per digit.
 *
 * Several stages of proceduralization sort millions of such records (a triangle's edges or
 * corners keyed by vertex and component); a comparison sort through a function pointer
 * (qsort) spends most of their time. Stability makes the result equal to a sort by (key,
 * then position in the input): records filled in ascending value order come out exactly as
 * a qsort comparing (key, value) would leave them. Digits where every key agrees are
 * skipped, so keys that use few bits cost few passes (byte digits). libc has no radix sort and the
 * Debian libraries the core may use offer none, hence this one. */
#ifndef AG_RADIX_H
#define AG_RADIX_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../status.h"

typedef struct {
    uint64_t key;
    uint32_t val;
} ag_radix_item;

/* A key that sorts as the double x does (x not NaN; -0 and +0 equal). */
static inline uint64_t ag_radix_key_double(double x)
{
    x += 0.0; /* -0 -> +0 */
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u >> 63 ? ~u : u | (1ull << 63);
}

/* v's lowest 21 bits spread to every third bit: three of them interleaved make a Morton
 * (z-order) key, which sorts nearby points next to each other. */
static inline uint64_t ag_radix_morton_spread(uint64_t v)
{
    v &= 0x1fffffULL;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

/* The key of a cell (x, y, z) of grid level `level`: the cell grids hash their cells so. */
static inline uint64_t ag_radix_cell_key(int level, int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)level * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)x * 0xBF58476D1CE4E5B9ULL;
    h = (h ^ (h >> 31)) * 0x94D049BB133111EBULL;
    h ^= (uint64_t)y * 0xD6E8FEB86659FD93ULL;
    h = (h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ULL;
    h ^= (uint64_t)z * 0x94D049BB133111EBULL;
    return h ^ (h >> 32);
}

/* Sorts a[0..n) by key, stably. Needs n records of scratch: AG_ERR_NOMEM when it cannot get
 * them (a is then unchanged). */
ag_status ag_radix_sort(ag_radix_item *a, size_t n);
/* The same with the caller's scratch tmp (n records; NULL: allocated as above). */
ag_status ag_radix_sort_with(ag_radix_item *a, size_t n, ag_radix_item *tmp);

/* Where each key's run starts in an array sorted by ag_radix_sort: an open-addressing table
 * of the distinct keys, so a look-up costs a probe or two instead of a binary search's
 * cache misses (grids of cells looked up many times per item). */
typedef struct {
    uint64_t *key;
    uint32_t *start; /* UINT32_MAX: an empty slot */
    size_t mask;
    const ag_radix_item *items;
    size_t n;
} ag_radix_index;

/* Indexes sorted[0..n) (kept by pointer, n < UINT32_MAX). AG_ERR_NOMEM, AG_ERR_TOO_LARGE. */
ag_status ag_radix_index_build(ag_radix_index *x, const ag_radix_item *sorted, size_t n);
void ag_radix_index_free(ag_radix_index *x);

/* The first position of key in the indexed array, n when it is absent; the run goes on while
 * items[i].key == key. */
static inline size_t ag_radix_index_find(const ag_radix_index *x, uint64_t key)
{
    if (!x->start)
        return x->n;
    uint64_t h = (key ^ (key >> 29)) * 0xbf58476d1ce4e5b9ULL;
    for (size_t i = (size_t)(h >> 17) & x->mask;; i = (i + 1) & x->mask) {
        if (x->start[i] == UINT32_MAX)
            return x->n;
        if (x->key[i] == key)
            return x->start[i];
    }
}

#endif
