#include "voxel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"

uint64_t ag__voxel_key_of(const double p[3], const double o[3], double h)
{
    uint64_t q[3];
    for (int a = 0; a < 3; a++) {
        double v = floor((p[a] - o[a]) / h);
        q[a] = !(v > 0) ? 0 : v > AG__VOXEL_AXIS_MAX ? AG__VOXEL_AXIS_MAX : (uint64_t)v;
    }
    return ag__voxel_key(q[0], q[1], q[2]);
}

int ag__voxel_set_init(ag__voxel_set *s, size_t n)
{
    size_t cap;
    memset(s, 0, sizeof *s);
    if (ag_array_hash_size(n, &cap))
        return -1;
    s->keys = malloc(cap * sizeof *s->keys);
    s->cell = malloc(cap * sizeof *s->cell);
    if (!s->keys || !s->cell)
        return -1;
    s->mask = cap - 1;
    ag__voxel_set_clear(s);
    return 0;
}

void ag__voxel_set_clear(ag__voxel_set *s)
{
    memset(s->keys, 0xff, (s->mask + 1) * sizeof *s->keys);
    s->used = 0;
}

void ag__voxel_set_free(ag__voxel_set *s)
{
    free(s->keys);
    free(s->cell);
    memset(s, 0, sizeof *s);
}

uint32_t ag__voxel_set_add(ag__voxel_set *s, uint64_t key)
{
    size_t h = ag__voxel_mix(key) & s->mask;
    while (s->keys[h] != UINT64_MAX && s->keys[h] != key)
        h = (h + 1) & s->mask;
    if (s->keys[h] == UINT64_MAX) {
        s->keys[h] = key;
        s->cell[h] = (uint32_t)s->used++;
    }
    return s->cell[h];
}

uint32_t ag__voxel_set_find(const ag__voxel_set *s, uint64_t key)
{
    size_t h = ag__voxel_mix(key) & s->mask;
    while (s->keys[h] != UINT64_MAX) {
        if (s->keys[h] == key)
            return s->cell[h];
        h = (h + 1) & s->mask;
    }
    return UINT32_MAX;
}
