/* Growth of dynamic arrays: the one place where core and io compute a new capacity.
 *
 * An array is a pointer, a length kept by the caller and a capacity in elements. Reserving
 * room at least doubles the capacity (from AG_ARRAY_MIN_CAP), so n appends cost O(n), and
 * every size computation is checked: a count or byte size that does not fit a size_t gives
 * AG_ERR_TOO_LARGE, a failed allocation AG_ERR_NOMEM; on either the array is unchanged.
 *
 *     if ((st = AG_ARRAY_RESERVE(g->rules, g->cap_rules, g->nrules + 1)))
 *         return st;
 */
#ifndef AG_ARRAY_H
#define AG_ARRAY_H

#include <stddef.h>

#include "../status.h"

/* The smallest capacity a growing array gets: small, since some structures hold thousands of
 * short arrays (a grammar's rule bodies of a few statements each). */
#define AG_ARRAY_MIN_CAP 8

/* The capacity an array of capacity cap that needs need elements of elem bytes grows to: cap
 * when it suffices, else at least double it (never below AG_ARRAY_MIN_CAP, never more than
 * fits a size_t in bytes); AG_ERR_TOO_LARGE when need elements do not fit. For arrays that
 * share one capacity (a struct of arrays). */
ag_status ag_array_capacity(size_t cap, size_t need, size_t elem, size_t *out);

/* Makes *items (elements of elem bytes, capacity *cap) hold at least need elements. */
ag_status ag_array_reserve(void **items, size_t *cap, size_t need, size_t elem);
/* The same for len + more elements, the sum checked too. */
ag_status ag_array_reserve_more(void **items, size_t *cap, size_t len, size_t more, size_t elem);
/* Exactly need elements when the capacity is smaller (no doubling): for a known final size. */
ag_status ag_array_reserve_exact(void **items, size_t *cap, size_t need, size_t elem);
/* *items reallocated to exactly n elements (at least one), *items kept when that fails: for
 * the arrays of a struct that share one capacity (ag_array_capacity). */
ag_status ag_array_resize(void **items, size_t n, size_t elem);

/* The size of an open-addressing hash table for n keys: a power of two of at least 2 n + 16,
 * so the table is at most half full. AG_ERR_TOO_LARGE when that does not fit a size_t. */
ag_status ag_array_hash_size(size_t n, size_t *size);

/* n * elem into *bytes, or AG_ERR_TOO_LARGE when it does not fit a size_t. */
ag_status ag_array_bytes(size_t n, size_t elem, size_t *bytes);
/* a + b into *sum, or AG_ERR_TOO_LARGE. */
ag_status ag_array_sum(size_t a, size_t b, size_t *sum);

/* Typed forms: items is an lvalue of pointer type, cap an lvalue of type size_t. */
#define AG_ARRAY_RESERVE(items, cap, need) \
    ag_array_reserve((void **)&(items), &(cap), (need), sizeof *(items))
#define AG_ARRAY_RESERVE_MORE(items, cap, len, more) \
    ag_array_reserve_more((void **)&(items), &(cap), (len), (more), sizeof *(items))
#define AG_ARRAY_RESERVE_EXACT(items, cap, need) \
    ag_array_reserve_exact((void **)&(items), &(cap), (need), sizeof *(items))
#define AG_ARRAY_RESIZE(items, n) ag_array_resize((void **)&(items), (n), sizeof *(items))

#endif
