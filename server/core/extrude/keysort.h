/* Sorting of (64-bit key, 32-bit value) pairs by key, without a comparison callback: the
 * shell's linking, welding and the building check sort many small arrays per building,
 * where qsort's indirect comparisons were a tenth of a city's time. Insertion sort for
 * short arrays, quicksort (median of three) for medium ones, radix sort (core/base/radix)
 * for long ones. Not stable. */
#ifndef AG_EXTRUDE_KEYSORT_H
#define AG_EXTRUDE_KEYSORT_H

#include <stddef.h>
#include <stdint.h>

#include "../base/radix.h"
#include "../status.h"

typedef ag_radix_item ag_keyed;

/* Sorts v (n entries) by key; tmp must hold n entries (may be NULL: then it is allocated
 * when needed, and AG_ERR_NOMEM is possible). */
ag_status ag_keysort(ag_keyed *v, size_t n, ag_keyed *tmp);

/* A key that orders doubles as numbers (NaN after everything). */
static inline uint64_t ag_keysort_double(double d)
{
    union {
        double d;
        uint64_t u;
    } x = {d};
    return x.u >> 63 ? ~x.u : x.u | 0x8000000000000000ULL;
}

#endif
