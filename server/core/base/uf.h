/* Union-find (disjoint sets) over the elements 0..n-1: path compression and union by rank.
 *
 * With offsets it keeps a potential per element as well: value(x) = value(root) + offset(x),
 * so a union states value(a) - value(b) = d (the coordinate classes of a resize, where two
 * coordinates tied by a hard equality become one unknown). */
#ifndef AG_UF_H
#define AG_UF_H

#include <assert.h>
#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef struct {
    uint32_t *parent;
    uint8_t *rank;
    double *offset; /* NULL without offsets; else value(x) - value(parent[x]) */
    size_t n;
} ag_uf;

/* Every element its own set. n < UINT32_MAX. AG_ERR_NOMEM, AG_ERR_TOO_LARGE. */
ag_status ag_uf_init(ag_uf *uf, size_t n, int with_offsets);
void ag_uf_free(ag_uf *uf);

/* The root of x's set, for a path longer than one step (compressing it, offsets kept). */
uint32_t ag__uf_find_path(ag_uf *uf, uint32_t x);

/* The root of x's set (compressing the path, offsets kept). Inline for the usual case of a
 * root or a path compressed already: finds run in the innermost loops of segmentation and of
 * the resize system. */
static inline uint32_t ag_uf_find(ag_uf *uf, uint32_t x)
{
    assert(x < uf->n);
    uint32_t p = uf->parent[x];
    if (p == x || uf->parent[p] == p)
        return p;
    return ag__uf_find_path(uf, x);
}
/* value(x) - value(root of x); call ag_uf_find(x) first. 0 without offsets. */
double ag_uf_offset(const ag_uf *uf, uint32_t x);
/* Joins the sets of a and b; returns the root of the joined set. With offsets the two roots
 * get equal values: state value(a) - value(b) = d with ag_uf_link instead. */
uint32_t ag_uf_union(ag_uf *uf, uint32_t a, uint32_t b);
/* Hangs root child under root `root` (both roots, distinct) with value(child) - value(root) =
 * offset: for callers whose sets carry a state that decides which root must stay. */
void ag_uf_link(ag_uf *uf, uint32_t child, uint32_t root, double offset);
/* Makes x a set of its own again; only for an x whose whole set is being reset. */
void ag_uf_reset(ag_uf *uf, uint32_t x);

#endif
