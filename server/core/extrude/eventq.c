#include "eventq.h"

#include <stdlib.h>

#include "../base/array.h"

static int before(const ag_event *a, const ag_event *b)
{
    if (a->z != b->z)
        return a->z < b->z;
    return a->type < b->type;
}

ag_status ag_eventq_push(ag_eventq *q, const ag_event *e)
{
    ag_status st = AG_ARRAY_RESERVE(q->h, q->cap, q->n + 1);
    if (st != AG_OK)
        return st;
    size_t i = q->n++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!before(e, &q->h[p]))
            break;
        q->h[i] = q->h[p];
        i = p;
    }
    q->h[i] = *e;
    return AG_OK;
}

int ag_eventq_pop(ag_eventq *q, ag_event *out)
{
    if (!q->n)
        return 0;
    *out = q->h[0];
    ag_event last = q->h[--q->n];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        const ag_event *best = &last;
        if (l < q->n && before(&q->h[l], best)) {
            m = l;
            best = &q->h[l];
        }
        if (r < q->n && before(&q->h[r], best))
            m = r;
        if (m == i)
            break;
        q->h[i] = q->h[m];
        i = m;
    }
    if (q->n)
        q->h[i] = last;
    return 1;
}

const ag_event *ag_eventq_peek(const ag_eventq *q)
{
    return q->n ? &q->h[0] : NULL;
}

void ag_eventq_free(ag_eventq *q)
{
    free(q->h);
    q->h = NULL;
    q->n = q->cap = 0;
}
