/* Binary search over sorted arrays of records: the first record whose key is not less than
 * (lower bound) or greater than (upper bound) a key, in O(log n).
 *
 * key points at the key field of record 0 and stride is the size of one record, so one
 * function serves every array of structs sorted by such a field:
 *     size_t i = ag_search_lower_u64(&rows[0].key, n, sizeof *rows, want);
 * A result of n means every key is smaller (lower) or not greater (upper). The keys must be
 * sorted ascending (for doubles: no NaN). */
#ifndef AG_SEARCH_H
#define AG_SEARCH_H

#include <stddef.h>
#include <stdint.h>

size_t ag_search_lower_u64(const void *key, size_t n, size_t stride, uint64_t want);
size_t ag_search_upper_u64(const void *key, size_t n, size_t stride, uint64_t want);
size_t ag_search_lower_double(const void *key, size_t n, size_t stride, double want);
size_t ag_search_upper_double(const void *key, size_t n, size_t stride, double want);

#endif
