#include "keysort.h"

#include <stdlib.h>
#include <string.h>

/* Arrays up to this long are sorted by insertion, up to LONG by quicksort, longer ones by
 * radix sort (whose passes cost a table each, too much for the small arrays of one
 * building). */
#define SHORT 24
#define LONG 4096

static void insertion(ag_keyed *v, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        ag_keyed x = v[i];
        size_t j = i;
        for (; j > 0 && v[j - 1].key > x.key; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
}

static void quick(ag_keyed *v, size_t n)
{
    size_t lo_stack[64], hi_stack[64], sp = 0;
    lo_stack[sp] = 0;
    hi_stack[sp++] = n;
    while (sp) {
        size_t lo = lo_stack[--sp], hi = hi_stack[sp];
        while (hi - lo > SHORT) {
            size_t mid = lo + (hi - lo) / 2;
            /* median of three as the pivot */
            uint64_t a = v[lo].key, b = v[mid].key, c = v[hi - 1].key;
            uint64_t p = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
            size_t i = lo, j = hi - 1;
            for (;;) {
                while (v[i].key < p)
                    i++;
                while (v[j].key > p)
                    j--;
                if (i >= j)
                    break;
                ag_keyed t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                j--;
            }
            /* [lo, j] <= p <= [j + 1, hi): the smaller side first, the larger later */
            size_t split = j + 1;
            if (split - lo < hi - split) {
                lo_stack[sp] = split;
                hi_stack[sp++] = hi;
                hi = split;
            } else {
                lo_stack[sp] = lo;
                hi_stack[sp++] = split;
                lo = split;
            }
        }
        insertion(v + lo, hi - lo);
    }
}

ag_status ag_keysort(ag_keyed *v, size_t n, ag_keyed *tmp)
{
    if (n <= SHORT) {
        insertion(v, n);
        return AG_OK;
    }
    if (n <= LONG) {
        quick(v, n);
        return AG_OK;
    }
    return ag_radix_sort_with(v, n, tmp);
}
