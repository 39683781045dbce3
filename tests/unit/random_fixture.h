/* A small deterministic generator for unit tests (xorshift64*): a failing case is
 * reproducible from its seed, on every machine. */
#ifndef AG_TEST_RANDOM_FIXTURE_H
#define AG_TEST_RANDOM_FIXTURE_H

#include <stdint.h>

static inline uint64_t next_random(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return *s * 0x2545F4914F6CDD1DULL;
}

/* Uniform in [lo, hi). */
static inline double uniform(uint64_t *s, double lo, double hi)
{
    return lo + (hi - lo) * (double)(next_random(s) >> 11) / 9007199254740992.0;
}

#endif
