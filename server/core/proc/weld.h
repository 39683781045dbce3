/* Internal: position welding by a hashed grid, shared by the proceduralization stages. */
#ifndef AG_WELD_H
#define AG_WELD_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

/* ids[v] = the welded id of vertex v (vertices whose positions quantize to the same cell of
 * size `cell` share an id); *count = number of ids. */
ag_status ag__weld(const double *pos, size_t n, double cell, uint32_t *ids, size_t *count);

static inline uint64_t ag__mix64(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return x;
}

static inline uint64_t ag__cell_hash(int64_t x, int64_t y, int64_t z)
{
    return ag__mix64((uint64_t)x * 0x9E3779B97F4A7C15ULL ^ ag__mix64((uint64_t)y + 0x632BE59BD9B4E019ULL) ^
                     ag__mix64((uint64_t)z * 0x85EBCA77C2B2AE63ULL + 1));
}

#endif
