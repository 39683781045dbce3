#include "lod.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/radix.h"
#include "../extrude/keysort.h"
#include "rng.h"

#define DEFAULT_SEED 0x6c6f642d6f726465ull /* "lod-orde" */
#define BITS 21                            /* per axis: three of them fit a 64-bit code */
#define LEVELS (BITS + 1)                  /* level BITS: the finest cells */

static uint32_t quantize(double v, double lo, double scale)
{
    double q = floor((v - lo) * scale);
    if (!(q > 0))
        return 0;
    return q >= (double)((1u << BITS) - 1) ? (1u << BITS) - 1 : (uint32_t)q;
}

ag_status ag_lod_order(const ag_cloud *c, uint64_t seed, uint32_t *order, ag_error *err)
{
    size_t n = c->n;
    if (n >= UINT32_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points are too many to order", n);
    if (n == 0)
        return AG_OK;
    ag_keyed *cells = malloc(n * sizeof *cells), *tmp = malloc(n * sizeof *tmp);
    uint64_t *key = malloc(n * sizeof *key);
    uint8_t *level = malloc(n);
    if (!cells || !tmp || !key || !level) {
        free(cells);
        free(tmp);
        free(key);
        free(level);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory ordering %zu points", n);
    }
    double lo[3], hi[3];
    ag_cloud_bounds(c, lo, hi);
    double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    double scale = size > 0 ? (double)(1u << BITS) / size : 0;
    ag_rng rng;
    ag_rng_seed(&rng, seed ? seed : DEFAULT_SEED);
    for (size_t i = 0; i < n; i++) {
        const double *p = c->xyz + 3 * i;
        uint64_t code = ag_radix_morton_spread(quantize(p[0], lo[0], scale)) |
                        ag_radix_morton_spread(quantize(p[1], lo[1], scale)) << 1 |
                        ag_radix_morton_spread(quantize(p[2], lo[2], scale)) << 2;
        cells[i] = (ag_keyed){code, (uint32_t)i};
        key[i] = ag_rng_next(&rng);
        level[i] = LEVELS; /* below the finest level: a point sharing its finest cell */
    }
    /* In Morton order every cell of every level is one run of consecutive points. */
    ag_status st = ag_keysort(cells, n, tmp);
    for (int L = 0; st == AG_OK && L < LEVELS; L++) {
        int shift = 3 * (BITS - L);
        for (size_t a = 0; a < n;) {
            uint64_t cell = cells[a].key >> shift; /* shift <= 63: level 0 is one cell */
            size_t best = a, b = a + 1;
            for (; b < n && cells[b].key >> shift == cell; b++)
                if (key[cells[b].val] < key[cells[best].val])
                    best = b;
            if (level[cells[best].val] == LEVELS)
                level[cells[best].val] = (uint8_t)L;
            a = b;
        }
    }
    /* by level, then key: ties are as likely as two equal 59-bit random numbers */
    for (size_t i = 0; st == AG_OK && i < n; i++)
        cells[i] = (ag_keyed){(uint64_t)level[i] << 59 | key[i] >> 5, (uint32_t)i};
    if (st == AG_OK)
        st = ag_keysort(cells, n, tmp);
    if (st == AG_OK)
        for (size_t i = 0; i < n; i++)
            order[i] = cells[i].val;
    else
        ag_error_set(err, st, 0, "out of memory ordering %zu points", n);
    free(cells);
    free(tmp);
    free(key);
    free(level);
    return st;
}
