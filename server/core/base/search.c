#include "search.h"

#include <assert.h>
#include <string.h>

/* Keys are read with memcpy: records need not align their key to its type. */
static uint64_t u64_at(const void *key, size_t i, size_t stride)
{
    uint64_t v;
    memcpy(&v, (const char *)key + i * stride, sizeof v);
    return v;
}

static double double_at(const void *key, size_t i, size_t stride)
{
    double v;
    memcpy(&v, (const char *)key + i * stride, sizeof v);
    return v;
}

/* The first index whose key is not below want (or_equal: not at or below want). */
static size_t partition_u64(const void *key, size_t n, size_t stride, uint64_t want, int or_equal)
{
    assert(key || n == 0);
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        uint64_t v = u64_at(key, mid, stride);
        if (v < want || (or_equal && v == want))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static size_t partition_double(const void *key, size_t n, size_t stride, double want,
                               int or_equal)
{
    assert(key || n == 0);
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        double v = double_at(key, mid, stride);
        if (v < want || (or_equal && v == want))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

size_t ag_search_lower_u64(const void *key, size_t n, size_t stride, uint64_t want)
{
    return partition_u64(key, n, stride, want, 0);
}

size_t ag_search_upper_u64(const void *key, size_t n, size_t stride, uint64_t want)
{
    return partition_u64(key, n, stride, want, 1);
}

size_t ag_search_lower_double(const void *key, size_t n, size_t stride, double want)
{
    return partition_double(key, n, stride, want, 0);
}

size_t ag_search_upper_double(const void *key, size_t n, size_t stride, double want)
{
    return partition_double(key, n, stride, want, 1);
}
