#include "uf.h"

#include <assert.h>
#include <stdlib.h>

ag_status ag_uf_init(ag_uf *uf, size_t n, int with_offsets)
{
    assert(uf);
    *uf = (ag_uf){0};
    if (n >= UINT32_MAX)
        return AG_ERR_TOO_LARGE;
    uf->parent = malloc((n + 1) * sizeof *uf->parent);
    uf->rank = calloc(n + 1, 1);
    uf->offset = with_offsets ? calloc(n + 1, sizeof *uf->offset) : NULL;
    if (!uf->parent || !uf->rank || (with_offsets && !uf->offset)) {
        ag_uf_free(uf);
        return AG_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        uf->parent[i] = (uint32_t)i;
    uf->n = n;
    return AG_OK;
}

void ag_uf_free(ag_uf *uf)
{
    if (!uf)
        return;
    free(uf->parent);
    free(uf->rank);
    free(uf->offset);
    *uf = (ag_uf){0};
}

uint32_t ag__uf_find_path(ag_uf *uf, uint32_t x)
{
    assert(x < uf->n);
    uint32_t *p = uf->parent;
    /* two passes: find the root (and x's offset from it), then point the path at the root */
    uint32_t r = x;
    if (!uf->offset) {
        while (p[r] != r)
            r = p[r];
        while (p[x] != r) {
            uint32_t next = p[x];
            p[x] = r;
            x = next;
        }
        return r;
    }
    double *off = uf->offset, acc = 0;
    while (p[r] != r) {
        acc += off[r];
        r = p[r];
    }
    double rest = acc;
    while (p[x] != x) {
        uint32_t next = p[x];
        double o = off[x];
        p[x] = r;
        off[x] = rest;
        rest -= o;
        x = next;
    }
    return r;
}

double ag_uf_offset(const ag_uf *uf, uint32_t x)
{
    assert(x < uf->n);
    return uf->offset && uf->parent[x] != x ? uf->offset[x] : 0;
}

void ag_uf_link(ag_uf *uf, uint32_t child, uint32_t root, double offset)
{
    assert(child < uf->n && root < uf->n && child != root);
    assert(uf->parent[child] == child && uf->parent[root] == root);
    uf->parent[child] = root;
    if (uf->offset)
        uf->offset[child] = offset;
    /* saturating: links chosen by the caller can build paths longer than 255 */
    if (uf->rank[root] <= uf->rank[child] && uf->rank[child] < UINT8_MAX)
        uf->rank[root] = (uint8_t)(uf->rank[child] + 1);
}

uint32_t ag_uf_union(ag_uf *uf, uint32_t a, uint32_t b)
{
    uint32_t ra = ag_uf_find(uf, a), rb = ag_uf_find(uf, b);
    if (ra == rb)
        return ra;
    /* the lower rank goes under the higher; on a tie the lower index stays the root */
    if (uf->rank[ra] < uf->rank[rb] || (uf->rank[ra] == uf->rank[rb] && rb < ra)) {
        uint32_t s = ra;
        ra = rb;
        rb = s;
    }
    ag_uf_link(uf, rb, ra, 0);
    return ra;
}

void ag_uf_reset(ag_uf *uf, uint32_t x)
{
    assert(x < uf->n);
    uf->parent[x] = x;
    uf->rank[x] = 0;
    if (uf->offset)
        uf->offset[x] = 0;
}
