#include "array.h"

#include <assert.h>
#include <stdint.h>
#include <stdlib.h>

ag_status ag_array_bytes(size_t n, size_t elem, size_t *bytes)
{
    if (elem && n > SIZE_MAX / elem)
        return AG_ERR_TOO_LARGE;
    *bytes = n * elem;
    return AG_OK;
}

ag_status ag_array_sum(size_t a, size_t b, size_t *sum)
{
    if (a > SIZE_MAX - b)
        return AG_ERR_TOO_LARGE;
    *sum = a + b;
    return AG_OK;
}

ag_status ag_array_hash_size(size_t n, size_t *size)
{
    if (n > (SIZE_MAX / 2 - 16) / 2)
        return AG_ERR_TOO_LARGE;
    size_t want = 2 * n + 16, s = 16;
    while (s < want)
        s <<= 1;
    *size = s;
    return AG_OK;
}

ag_status ag_array_resize(void **items, size_t n, size_t elem)
{
    assert(items && elem > 0);
    size_t bytes;
    if (ag_array_bytes(n ? n : 1, elem, &bytes))
        return AG_ERR_TOO_LARGE;
    void *p = realloc(*items, bytes);
    if (!p)
        return AG_ERR_NOMEM;
    *items = p;
    return AG_OK;
}

ag_status ag_array_reserve_exact(void **items, size_t *cap, size_t need, size_t elem)
{
    assert(items && cap && elem > 0);
    if (need <= *cap)
        return AG_OK;
    ag_status s = ag_array_resize(items, need, elem);
    if (s == AG_OK)
        *cap = need;
    return s;
}

ag_status ag_array_capacity(size_t cap, size_t need, size_t elem, size_t *out)
{
    assert(out && elem > 0);
    size_t limit = SIZE_MAX / elem; /* the most elements whose bytes fit a size_t */
    if (need > limit)
        return AG_ERR_TOO_LARGE;
    if (need <= cap) {
        *out = cap;
        return AG_OK;
    }
    size_t n = cap < AG_ARRAY_MIN_CAP ? AG_ARRAY_MIN_CAP : cap;
    if (n > limit)
        n = need;
    /* doubling that would not fit settles for exactly what is needed */
    while (n < need)
        n = n > limit / 2 ? need : 2 * n;
    *out = n;
    return AG_OK;
}

ag_status ag_array_reserve(void **items, size_t *cap, size_t need, size_t elem)
{
    assert(items && cap && elem > 0);
    if (need <= *cap)
        return AG_OK;
    size_t n;
    if (ag_array_capacity(*cap, need, elem, &n))
        return AG_ERR_TOO_LARGE;
    return ag_array_reserve_exact(items, cap, n, elem);
}

ag_status ag_array_reserve_more(void **items, size_t *cap, size_t len, size_t more, size_t elem)
{
    size_t need;
    if (ag_array_sum(len, more, &need))
        return AG_ERR_TOO_LARGE;
    return ag_array_reserve(items, cap, need, elem);
}
