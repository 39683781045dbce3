#include "cluster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/box.h"
#include "voxel.h"

ag_status ag_cluster_components(const ag_cloud *c, const ag_ransac_graph *g, double radius,
                                int32_t *labels, size_t min_size, size_t *ncomponents,
                                int32_t **comp_of_label, ag_error *err)
{
    size_t n = c->n;
    *ncomponents = 0;
    if (comp_of_label)
        *comp_of_label = NULL;
    int32_t *comp = malloc((n ? n : 1) * sizeof *comp);
    uint32_t *queue = malloc((n ? n : 1) * sizeof *queue);
    int32_t *from = NULL;
    size_t nfrom = 0, cap = 0;
    if (!comp || !queue) {
        free(comp);
        free(queue);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t i = 0; i < n; i++)
        comp[i] = -1;
    double r2 = radius > 0 ? radius * radius : 0;
    int32_t next = 0;
    for (size_t s = 0; s < n; s++) {
        if (labels[s] < 0 || comp[s] >= 0)
            continue;
        int32_t label = labels[s];
        size_t qn = 0;
        comp[s] = next;
        queue[qn++] = (uint32_t)s;
        for (size_t h = 0; h < qn; h++) {
            uint32_t q = queue[h];
            const double *pq = c->xyz + 3 * (size_t)q;
            const uint32_t *nb = g->ids + (size_t)q * g->k;
            for (unsigned j = 0; j < g->k; j++) {
                uint32_t r = nb[j];
                if (comp[r] >= 0 || labels[r] != label)
                    continue;
                if (r2 > 0) {
                    const double *pr = c->xyz + 3 * (size_t)r;
                    double dx = pr[0] - pq[0], dy = pr[1] - pq[1], dz = pr[2] - pq[2];
                    if (dx * dx + dy * dy + dz * dz > r2)
                        continue;
                }
                comp[r] = next;
                queue[qn++] = r;
            }
        }
        if (qn < min_size) {
            /* too small: its points leave the label (-2 marks them as seen) */
            for (size_t h = 0; h < qn; h++)
                comp[queue[h]] = -2;
            continue;
        }
        if (comp_of_label) {
            if (AG_ARRAY_RESERVE(from, cap, nfrom + 1)) {
                free(comp);
                free(queue);
                free(from);
                return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            }
            from[nfrom++] = label;
        }
        next++;
    }
    for (size_t i = 0; i < n; i++)
        labels[i] = comp[i] >= 0 ? comp[i] : -1;
    free(comp);
    free(queue);
    *ncomponents = (size_t)next;
    if (comp_of_label)
        *comp_of_label = from;
    return AG_OK;
}

ag_status ag_cluster_euclidean(const ag_cloud *c, const uint32_t *idx, size_t m, double tolerance,
                               size_t min_size, int32_t first_id, int32_t *out, size_t *nclusters,
                               ag_error *err)
{
    /* the grid of pieces with the tolerance as cell: linear time whatever the density (a
     * radius search per point is quadratic on a pile of duplicates) */
    *nclusters = 0;
    if (!m)
        return AG_OK;
    int32_t *labels = malloc(c->n * sizeof *labels), *piece = malloc(c->n * sizeof *piece);
    if (!labels || !piece) {
        free(labels);
        free(piece);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t i = 0; i < c->n; i++)
        labels[i] = -1;
    for (size_t j = 0; j < m; j++)
        labels[idx[j]] = 0;
    size_t np = 0;
    ag_status st = ag_cluster_pieces(c, labels, tolerance, min_size, piece, &np, err);
    if (st == AG_OK) {
        for (size_t j = 0; j < m; j++)
            out[idx[j]] = piece[idx[j]] >= 0 ? first_id + piece[idx[j]] : -1;
        *nclusters = np;
    }
    free(labels);
    free(piece);
    return st;
}

/* ---- pieces on a grid ------------------------------------------------------------------ */

#define CELL_BITS 14 /* per axis; the cell grows when a cloud would need more */
#define LABEL_BITS (64 - 3 * CELL_BITS)

static uint64_t cell_key(uint64_t label, uint64_t x, uint64_t y, uint64_t z)
{
    return label << (3 * CELL_BITS) | x << (2 * CELL_BITS) | y << CELL_BITS | z;
}


typedef struct {
    uint64_t *keys; /* UINT64_MAX = empty */
    uint32_t *cell;
    size_t mask;
} cell_table;

static uint32_t table_find(const cell_table *t, uint64_t key)
{
    for (size_t h = ag__voxel_mix(key) & t->mask;; h = (h + 1) & t->mask) {
        if (t->keys[h] == key)
            return t->cell[h];
        if (t->keys[h] == UINT64_MAX)
            return UINT32_MAX;
    }
}

ag_status ag_cluster_pieces(const ag_cloud *c, int32_t *labels, double cell, size_t min_size,
                            int32_t *piece, size_t *npieces, ag_error *err)
{
    size_t n = c->n;
    *npieces = 0;
    ag_box bounds = ag_box_empty();
    size_t m = 0;
    int32_t max_label = -1;
    for (size_t i = 0; i < n; i++) {
        piece[i] = -1;
        if (labels[i] < 0)
            continue;
        m++;
        if (labels[i] > max_label)
            max_label = labels[i];
        ag_box_extend_point(&bounds, c->xyz + 3 * i);
    }
    const double *mn = bounds.min, *mx = bounds.max;
    if (!m)
        return AG_OK;
    if ((uint64_t)max_label >= (1ull << LABEL_BITS))
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "too many planes (%d)", max_label + 1);
    double h = cell > 0 ? cell : 1;
    for (int a = 0; a < 3; a++)
        while ((mx[a] - mn[a]) / h >= (double)((1u << CELL_BITS) - 2))
            h *= 2;
    size_t cap = 64;
    while (cap < 2 * m)
        cap *= 2;
    cell_table t = {malloc(cap * sizeof(uint64_t)), malloc(cap * sizeof(uint32_t)), cap - 1};
    uint32_t *cell_of = malloc(n * sizeof *cell_of);
    uint64_t *cell_keys = malloc(m * sizeof *cell_keys);
    uint32_t *count = calloc(m + 1, sizeof *count);
    uint32_t *cell_piece = malloc(m * sizeof *cell_piece);
    uint32_t *queue = malloc(m * sizeof *queue);
    uint32_t *piece_size = NULL;
    ag_status st = AG_OK;
    if (!t.keys || !t.cell || !cell_of || !cell_keys || !count || !cell_piece || !queue) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto out;
    }
    memset(t.keys, 0xff, cap * sizeof(uint64_t));
    uint32_t ncells = 0;
    for (size_t i = 0; i < n; i++) {
        if (labels[i] < 0)
            continue;
        uint64_t q[3];
        for (int a = 0; a < 3; a++)
            q[a] = (uint64_t)((c->xyz[3 * i + a] - mn[a]) / h) + 1; /* +1: room for -1 */
        uint64_t key = cell_key((uint64_t)labels[i], q[0], q[1], q[2]);
        size_t slot = ag__voxel_mix(key) & t.mask;
        while (t.keys[slot] != UINT64_MAX && t.keys[slot] != key)
            slot = (slot + 1) & t.mask;
        if (t.keys[slot] == UINT64_MAX) {
            t.keys[slot] = key;
            t.cell[slot] = ncells;
            cell_keys[ncells++] = key;
        }
        cell_of[i] = t.cell[slot];
        count[t.cell[slot]]++;
    }
    /* pieces: breadth-first over touching cells of one label */
    for (uint32_t k = 0; k < ncells; k++)
        cell_piece[k] = UINT32_MAX;
    uint32_t npiece = 0;
    size_t cap_sizes = 0;
    const uint64_t cmask = (1ull << CELL_BITS) - 1;
    for (uint32_t s = 0; s < ncells; s++) {
        if (cell_piece[s] != UINT32_MAX)
            continue;
        size_t qn = 0;
        uint64_t size = 0;
        cell_piece[s] = npiece;
        queue[qn++] = s;
        for (size_t hq = 0; hq < qn; hq++) {
            uint64_t key = cell_keys[queue[hq]];
            size += count[queue[hq]];
            uint64_t label = key >> (3 * CELL_BITS);
            uint64_t x = (key >> (2 * CELL_BITS)) & cmask, y = (key >> CELL_BITS) & cmask,
                     z = key & cmask;
            for (int dx = -1; dx <= 1; dx++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dz = -1; dz <= 1; dz++) {
                        if (!dx && !dy && !dz)
                            continue;
                        uint64_t nk = cell_key(label, x + (uint64_t)(int64_t)dx,
                                               y + (uint64_t)(int64_t)dy, z + (uint64_t)(int64_t)dz);
                        uint32_t nc = table_find(&t, nk);
                        if (nc != UINT32_MAX && cell_piece[nc] == UINT32_MAX) {
                            cell_piece[nc] = npiece;
                            queue[qn++] = nc;
                        }
                    }
        }
        if (AG_ARRAY_RESERVE(piece_size, cap_sizes, (size_t)npiece + 1)) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto out;
        }
        piece_size[npiece++] = (uint32_t)(size > UINT32_MAX ? UINT32_MAX : size);
    }
    /* keep the pieces that are big enough, numbered in order */
    uint32_t *renumber = malloc((npiece ? npiece : 1) * sizeof *renumber);
    if (!renumber) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto out;
    }
    uint32_t kept = 0;
    for (uint32_t p = 0; p < npiece; p++)
        renumber[p] = piece_size[p] >= min_size ? kept++ : UINT32_MAX;
    for (size_t i = 0; i < n; i++) {
        if (labels[i] < 0)
            continue;
        uint32_t p = renumber[cell_piece[cell_of[i]]];
        if (p == UINT32_MAX) {
            labels[i] = -1;
        } else {
            piece[i] = (int32_t)p;
        }
    }
    free(renumber);
    *npieces = kept;
out:
    free(t.keys);
    free(t.cell);
    free(cell_of);
    free(cell_keys);
    free(count);
    free(cell_piece);
    free(queue);
    free(piece_size);
    return st;
}
