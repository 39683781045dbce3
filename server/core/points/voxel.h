/* Internal to core/points: integer cells of a uniform grid and their hash, shared by the
 * grid clustering (cluster.c) and the voxel resampling (resample.c). */
#ifndef AG_POINTS_VOXEL_H
#define AG_POINTS_VOXEL_H

#include <stddef.h>
#include <stdint.h>

/* A 64-bit mix (the finalizer of MurmurHash3): cells of neighbouring coordinates spread
 * over the whole table. */
static inline uint64_t ag__voxel_mix(uint64_t k)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdull;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ull;
    return k ^ (k >> 33);
}

/* Cell (x, y, z) of 21 bits each (callers keep coordinates in 0 .. 2^21 - 1) as one key;
 * UINT64_MAX is never a key. */
static inline uint64_t ag__voxel_key(uint64_t x, uint64_t y, uint64_t z)
{
    return x << 42 | y << 21 | z;
}

#define AG__VOXEL_AXIS_MAX ((1u << 21) - 2)

/* The key of the cell of p in a grid of cell size h anchored at o (coordinates clamped into
 * the key's range). */
uint64_t ag__voxel_key_of(const double p[3], const double o[3], double h);

/* A set of cells by open addressing, sized once for at most n cells: each cell added gets
 * the next number from 0. */
typedef struct {
    uint64_t *keys; /* UINT64_MAX: empty */
    uint32_t *cell;
    size_t mask, used;
} ag__voxel_set;

/* 0, or -1 when out of memory (free it either way). */
int ag__voxel_set_init(ag__voxel_set *s, size_t n);
void ag__voxel_set_clear(ag__voxel_set *s);
void ag__voxel_set_free(ag__voxel_set *s);
/* The number of key's cell, added when new (at most n cells in all). */
uint32_t ag__voxel_set_add(ag__voxel_set *s, uint64_t key);
/* Its number, or UINT32_MAX when absent. */
uint32_t ag__voxel_set_find(const ag__voxel_set *s, uint64_t key);

#endif
