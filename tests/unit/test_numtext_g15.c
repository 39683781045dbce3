/* Reals as the served tree prints them: ag_numtext_double_g15 writes exactly what snprintf's
 * "%.15g" writes, byte for byte, for doubles from every region the fast path covers and its
 * edges: building coordinates, UTM/RD-sized offsets, values that are short decimals (0.1,
 * 2.4, 1e-3), neighbours of powers of ten (where the exponent changes under rounding), exact
 * rounding ties of 15 digits (x.5 at the 15th digit), random bit patterns, and the values that
 * leave the fast path (zeros, tiny, huge, subnormal, non-finite). The oracle is glibc's
 * printf, an independent implementation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "io/numtext.h"
#include "random_fixture.h"

static uint64_t seed = 0x243f6a8885a308d3ull;

static void check(double v)
{
    char want[64], got[AG_NUMTEXT_MAX + 8];
    int n = snprintf(want, sizeof want, "%.15g", v);
    memset(got, 'x', sizeof got);
    size_t m = ag_numtext_double_g15(got, v);
    if (m != (size_t)n || strcmp(got, want) != 0) {
        print_error("value %.17g (bits %016llx): printf \"%s\", got \"%s\"\n", v,
                    (unsigned long long)(union { double d; uint64_t u; }){v}.u, want, got);
        fail();
    }
}

static void both_signs(double v)
{
    check(v);
    check(-v);
}

static void test_special(void **state)
{
    (void)state;
    static const double vals[] = {0.0, 1e-4, 9.999999999999999e-5, 1e15, 999999999999999.0,
                                  999999999999999.5, 1e300, 5e-324, 2.2250738585072014e-308,
                                  1.0, 10.0, 0.1, 0.5, 2.4, 4.8, 0.3, 1e-3, 123456.789};
    for (size_t i = 0; i < sizeof vals / sizeof *vals; i++)
        both_signs(vals[i]);
    check(-0.0);
    check(INFINITY);
    check(-INFINITY);
    check(NAN);
}

/* Short decimals and their neighbours, powers of ten and theirs. */
static void test_decimals_and_decades(void **state)
{
    (void)state;
    for (int e = -5; e <= 16; e++) {
        double p = pow(10, e);
        double v = p;
        for (int k = 0; k < 40; k++) {
            both_signs(v);
            v = nextafter(v, 0);
        }
        v = p;
        for (int k = 0; k < 40; k++) {
            both_signs(v);
            v = nextafter(v, INFINITY);
        }
    }
    for (int i = 1; i < 200000; i++) {
        both_signs(i / 1000.0);
        both_signs(i * 0.1);
        both_signs(i * 1e-4);
    }
}

/* 15-digit ties: d.ddddddddddddd5 (16 significant digits ending in 5) at every scale. */
static void test_ties(void **state)
{
    (void)state;
    for (int i = 0; i < 200000; i++) {
        uint64_t m = 1000000000000000ull + next_random(&seed) % 9000000000000000ull;
        m = m / 10 * 10 + 5;
        int e = (int)(next_random(&seed) % 20) - 20;
        char text[64];
        snprintf(text, sizeof text, "%llue%d", (unsigned long long)m, e);
        double v = strtod(text, NULL);
        both_signs(v);
        both_signs(nextafter(v, 0));
        both_signs(nextafter(v, INFINITY));
    }
}

/* Coordinates: metres in a building, at UTM and RD offsets, and after arithmetic. */
static void test_coordinates(void **state)
{
    (void)state;
    static const double offsets[] = {0, 155000, 463000, 691234.5, 5331234.25, 4000000};
    for (int i = 0; i < 1000000; i++) {
        double o = offsets[i % 6];
        double v = o + uniform(&seed, -60, 60);
        both_signs(v);
        both_signs(uniform(&seed, 0, 1) * uniform(&seed, 0, 3));
        both_signs(v * 1.25 - o);
    }
}

/* Random bit patterns over the fast path's whole range of magnitudes. */
static void test_random_bits(void **state)
{
    (void)state;
    for (int i = 0; i < 2000000; i++) {
        double e = uniform(&seed, -4.5, 15.5);
        double v = pow(10, e);
        union { double d; uint64_t u; } b = {v};
        b.u ^= next_random(&seed) & 0xfffffffffull;
        check(b.d);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_special),
        cmocka_unit_test(test_decimals_and_decades),
        cmocka_unit_test(test_ties),
        cmocka_unit_test(test_coordinates),
        cmocka_unit_test(test_random_bits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
