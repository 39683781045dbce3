/* What the tests measure on a mesh themselves, independently of the code under test: triangle
 * and per-group areas, and the welded vertex set (corners rounded onto a grid, sorted, one
 * each) with a lookup that forgives a corner rounded into a neighbouring cell. Header-only. */
#ifndef AG_TEST_MESH_MEASURE_FIXTURE_H
#define AG_TEST_MESH_MEASURE_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/mesh.h"

static inline double mm_tri_area(const ag_mesh *m, size_t t)
{
    const double *a = &m->pos[3 * m->tri[3 * t]], *b = &m->pos[3 * m->tri[3 * t + 1]],
                 *c = &m->pos[3 * m->tri[3 * t + 2]];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
           z = u[0] * v[1] - u[1] * v[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

static inline double mm_total_area(const ag_mesh *m)
{
    double s = 0;
    for (size_t t = 0; t < m->ntris; t++)
        s += mm_tri_area(m, t);
    return s;
}

static inline int mm_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The areas of the component groups that hold triangles, sorted (groups are compared by what
 * they cover, not by their numbers); *n gets their count. */
static inline double *mm_group_areas(const ag_mesh *m, size_t *n)
{
    double *a = calloc(m->ngroups + 1, sizeof *a);
    for (size_t t = 0; t < m->ntris; t++) {
        int32_t g = m->component_group[m->tri_component[t]];
        if (g >= 0)
            a[g] += mm_tri_area(m, t);
    }
    size_t k = 0;
    for (size_t g = 0; g < m->ngroups; g++)
        if (a[g] > 0)
            a[k++] = a[g];
    qsort(a, k, sizeof *a, mm_cmp_double);
    *n = k;
    return a;
}

typedef struct {
    int64_t k[3];
} mm_cell;

static inline int mm_cmp_cell(const void *a, const void *b)
{
    const mm_cell *x = a, *y = b;
    for (int i = 0; i < 3; i++)
        if (x->k[i] != y->k[i])
            return x->k[i] < y->k[i] ? -1 : 1;
    return 0;
}

/* Sorts c[0..k) and drops repeats; gives the count left. */
static inline size_t mm_cells_unique(mm_cell *c, size_t k)
{
    qsort(c, k, sizeof *c, mm_cmp_cell);
    size_t u = 0;
    for (size_t i = 0; i < k; i++)
        if (!u || mm_cmp_cell(&c[i], &c[u - 1]))
            c[u++] = c[i];
    return u;
}

/* The triangles' corners on a grid of cell size step from origin, one cell each. */
static inline mm_cell *mm_welded(const ag_mesh *m, const double origin[3], double step, size_t *n)
{
    mm_cell *c = malloc((3 * m->ntris + 1) * sizeof *c);
    for (size_t t = 0; t < 3 * m->ntris; t++) {
        const double *p = &m->pos[3 * m->tri[t]];
        for (int i = 0; i < 3; i++)
            c[t].k[i] = (int64_t)floor((p[i] - origin[i]) / step + 0.5);
    }
    *n = mm_cells_unique(c, 3 * m->ntris);
    return c;
}

/* How many cells of a have no cell of b within one step (rounding puts a point near a cell
 * border into either neighbour). */
static inline size_t mm_unmatched(const mm_cell *a, size_t na, const mm_cell *b, size_t nb)
{
    size_t miss = 0;
    for (size_t i = 0; i < na; i++) {
        int found = 0;
        for (int d = 0; d < 27 && !found; d++) {
            mm_cell q = {{a[i].k[0] + d % 3 - 1, a[i].k[1] + (d / 3) % 3 - 1,
                          a[i].k[2] + d / 9 - 1}};
            found = bsearch(&q, b, nb, sizeof *b, mm_cmp_cell) != NULL;
        }
        miss += !found;
    }
    return miss;
}

#endif
