/* A small seeded random number generator (splitmix64) for the point pipeline: the same
 * seed gives the same segmentation on every machine; core never uses time-based
 * randomness. */
#ifndef AG_RNG_H
#define AG_RNG_H

#include <stdint.h>

typedef struct {
    uint64_t state;
} ag_rng;

static inline void ag_rng_seed(ag_rng *r, uint64_t seed)
{
    r->state = seed ? seed : 0x9E3779B97F4A7C15ull;
}

static inline uint64_t ag_rng_next(ag_rng *r)
{
    uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, n) for n > 0 (the bias of the modulo is below 2^-32 for n < 2^32). */
static inline uint64_t ag_rng_below(ag_rng *r, uint64_t n)
{
    return ag_rng_next(r) % n;
}

/* Uniform in [0, 1). */
static inline double ag_rng_unit(ag_rng *r)
{
    return (double)(ag_rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

/* Standard normal (Box-Muller). */
double ag_rng_gauss(ag_rng *r);

#endif
