/* Binary search over sorted arrays of records: the first record whose key is not less than
 * (lower bound) or greater than (upper bound) a key, in O(log n).
 *
 * key points at the key field of record 0 and stride is the size of one record, so one
 * function serves every array of structs sorted by such a field:
 *     size_t i = ag_search_lower_u64(&rows[0].key, n, sizeof *rows, want);
 * A result of n means every key is smaller (lower) or not greater (upper). The keys must be
 * sorted ascending (for doubles: no NaN).
 *
 * Inline, and only here: the searches run in innermost loops (triangle matching probes 27
 * cells per triangle), where a call and a stride not known at compile time cost more than
 * the search itself. */
#ifndef AG_SEARCH_H
#define AG_SEARCH_H

#include <assert.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ag__search_u64 / ag__search_double: the first index whose key is not below want
 * (or_equal: not at or below want), one body for both key types. Keys are read with memcpy:
 * records need not align their key to its type. lo + hi cannot overflow: records of at
 * least 8 bytes number far fewer than SIZE_MAX / 2. */
#define AG__SEARCH_PARTITION(name, type)                                                   \
    static inline size_t name(const void *key, size_t n, size_t stride, type want,         \
                              int or_equal)                                                \
    {                                                                                      \
        assert(key || n == 0);                                                             \
        size_t lo = 0, hi = n;                                                             \
        while (lo < hi) {                                                                  \
            size_t mid = (lo + hi) / 2;                                                    \
            type v;                                                                        \
            memcpy(&v, (const char *)key + mid * stride, sizeof v);                        \
            if (v < want || (or_equal && v == want))                                       \
                lo = mid + 1;                                                              \
            else                                                                           \
                hi = mid;                                                                  \
        }                                                                                  \
        return lo;                                                                         \
    }

AG__SEARCH_PARTITION(ag__search_u64, uint64_t)
AG__SEARCH_PARTITION(ag__search_double, double)

static inline size_t ag_search_lower_u64(const void *key, size_t n, size_t stride,
                                         uint64_t want)
{
    return ag__search_u64(key, n, stride, want, 0);
}

static inline size_t ag_search_upper_u64(const void *key, size_t n, size_t stride,
                                         uint64_t want)
{
    return ag__search_u64(key, n, stride, want, 1);
}

static inline size_t ag_search_lower_double(const void *key, size_t n, size_t stride,
                                            double want)
{
    return ag__search_double(key, n, stride, want, 0);
}

static inline size_t ag_search_upper_double(const void *key, size_t n, size_t stride,
                                            double want)
{
    return ag__search_double(key, n, stride, want, 1);
}

#endif
