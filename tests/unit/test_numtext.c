/* Numbers as text: every double written reads back to the same bits (through strtod and
 * through the OBJ reader), and is never longer than the shortest "%.{15,16,17}g" that reads
 * back; integers as printf writes them. Doubles from every region: building coordinates,
 * UTM/RD-sized offsets, tiny and huge magnitudes, powers of two (asymmetric rounding
 * intervals), neighbours of powers of ten, random bit patterns, subnormals, zeros,
 * non-finite values. */
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
#include "io/obj.h"
#include "random_fixture.h"

static uint64_t seed = 0x9e3779b97f4a7c15ull;
static uint64_t next(void)
{
    return next_random(&seed);
}
static double unit(void)
{
    return uniform(&seed, 0, 1);
}

static size_t shortest_printf(double v, char *buf)
{
    for (int prec = 1; prec <= 17; prec++) {
        int n = snprintf(buf, 64, "%.*g", prec, v);
        if (strtod(buf, NULL) == v || (isnan(v) && isnan(strtod(buf, NULL))))
            return (size_t)n;
    }
    return (size_t)snprintf(buf, 64, "%.17g", v);
}

/* Significant digits of a decimal text: no sign, leading zeros, point, trailing zeros or
 * exponent. */
static size_t significant_digits(const char *text)
{
    size_t n = 0, zeros = 0;
    int seen = 0;
    for (const char *c = text; *c && *c != 'e'; c++) {
        if (*c < '0' || *c > '9' || (*c == '0' && !seen))
            continue;
        seen = 1;
        if (*c == '0') {
            zeros++;
        } else {
            n += zeros + 1;
            zeros = 0;
        }
    }
    return n;
}

static size_t checked, plain;

static void check(double v)
{
    char out[AG_NUMTEXT_MAX + 8];
    memset(out, 'x', sizeof out);
    size_t n = ag_numtext_double(out, v);
    assert_true(n < AG_NUMTEXT_MAX);
    assert_int_equal(strlen(out), n);
    double back = strtod(out, NULL);
    if (isnan(v)) {
        assert_true(isnan(back));
        return;
    }
    if (memcmp(&back, &v, sizeof v) != 0)
        fail_msg("%.17g written as \"%s\" reads back as %.17g", v, out, back);
    char ref[64];
    size_t best = shortest_printf(v, ref);
    /* printf's shortest may use an exponent ("1e+20") where ours is plain; compare the
     * significant digits in the plain range */
    if (fabs(v) >= 1e-5 && fabs(v) < 9007199254740992.0) {
        plain++;
        assert_null(strchr(out, 'e'));
        size_t ours = significant_digits(out), ref_digits = significant_digits(ref);
        if (ours > ref_digits)
            fail_msg("%.17g: \"%s\" has %zu significant digits, \"%s\" only %zu", v, out,
                     ours, ref, ref_digits);
        (void)best;
    }
    /* the OBJ reader reads it back exactly too (one value in 16: it builds a mesh each) */
    if (checked++ % 16)
        return;
    char obj[160];
    char x2[AG_NUMTEXT_MAX];
    ag_numtext_double(x2, v);
    snprintf(obj, sizeof obj, "v %s 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", x2);
    if (isfinite(v)) {
        ag_mesh *m = NULL;
        ag_obj_read_options o = {.up = AG_UP_Z};
        assert_int_equal(ag_obj_read_buffer(obj, strlen(obj), &o, &m, NULL), AG_OK);
        if (memcmp(&m->pos[0], &v, sizeof v) != 0)
            fail_msg("%.17g written as \"%s\" reads back through the OBJ reader as %.17g", v,
                     x2, m->pos[0]);
        ag_mesh_free(m);
    }
}

static void test_special(void **state_)
{
    (void)state_;
    char out[AG_NUMTEXT_MAX];
    ag_numtext_double(out, 0.0);
    assert_string_equal(out, "0");
    ag_numtext_double(out, -0.0);
    assert_string_equal(out, "-0");
    ag_numtext_double(out, 12.5);
    assert_string_equal(out, "12.5");
    ag_numtext_double(out, -0.001);
    assert_string_equal(out, "-0.001");
    ag_numtext_double(out, 3);
    assert_string_equal(out, "3");
    ag_numtext_double(out, 0.1);
    assert_string_equal(out, "0.1");
    ag_numtext_double(out, 1e15);
    assert_string_equal(out, "1000000000000000");
    ag_numtext_double(out, 85000.123);
    assert_string_equal(out, "85000.123");
    ag_numtext_double(out, 0.1 + 0.2);
    assert_string_equal(out, "0.30000000000000004");
    ag_numtext_double(out, INFINITY);
    assert_string_equal(out, "inf");
    ag_numtext_double(out, -INFINITY);
    assert_string_equal(out, "-inf");
    check(NAN);
    check(5e-324);
    check(2.2250738585072014e-308);
}

static void test_integers(void **state_)
{
    (void)state_;
    uint64_t vals[] = {0, 1, 9, 10, 99, 100, 4294967295ull, 18446744073709551615ull};
    for (size_t i = 0; i < sizeof vals / sizeof *vals; i++) {
        char a[AG_NUMTEXT_MAX], b[32];
        size_t n = ag_numtext_u64(a, vals[i]);
        snprintf(b, sizeof b, "%llu", (unsigned long long)vals[i]);
        assert_string_equal(a, b);
        assert_int_equal(n, strlen(b));
    }
    for (int i = 0; i < 100000; i++) {
        uint64_t v = next() >> (next() % 64);
        char a[AG_NUMTEXT_MAX], b[32];
        ag_numtext_u64(a, v);
        snprintf(b, sizeof b, "%llu", (unsigned long long)v);
        assert_string_equal(a, b);
    }
}

static void test_round_trip(void **state_)
{
    (void)state_;
    checked = plain = 0;
    /* building coordinates: a few metres to kilometres, mm steps and full noise */
    for (int i = 0; i < 100000; i++) {
        double v = (unit() - 0.5) * 2000;
        check(v);
        check(round(v * 1000) / 1000);
        check(round(v * 100) / 100);
    }
    /* RD New / UTM-sized coordinates, with and without noise */
    for (int i = 0; i < 100000; i++) {
        check(85000 + unit() * 1000);
        check(5.4e6 + unit() * 1e4);
        check(446000.0 + round(unit() * 1e6) / 1e3);
    }
    /* powers of two and their neighbours (asymmetric intervals), powers of ten */
    for (int e = -60; e <= 60; e++) {
        double p = ldexp(1.0, e);
        check(p);
        check(nextafter(p, 0));
        check(nextafter(p, INFINITY));
        check(-p);
    }
    for (int e = -30; e <= 30; e++) {
        double p = pow(10.0, e);
        check(p);
        check(nextafter(p, 0));
        check(nextafter(p, INFINITY));
    }
    /* every magnitude */
    for (int i = 0; i < 100000; i++) {
        double v = ldexp(1 + unit(), (int)(next() % 200) - 100);
        check(next() & 1 ? v : -v);
    }
    /* random bit patterns */
    for (int i = 0; i < 100000; i++) {
        uint64_t b = next();
        double v;
        memcpy(&v, &b, sizeof v);
        check(v);
    }
    /* the region's borders */
    check(1e-5);
    check(nextafter(1e-5, 0));
    check(9007199254740991.0);
    check(9007199254740992.0);
    check(4503599627370496.5);
    printf("numtext: %zu doubles read back exactly, %zu of them in plain notation, none "
           "longer than printf's shortest\n", checked, plain);
}

/* ag_numtext_double_g15 prints what "%.15g" prints, byte for byte; ag_numtext_double_g
 * what "%.*g" prints at every precision from 1 to 15 (the grammar text's is 12) */
static size_t g15_checked;
static void check_g15(double v)
{
    char a[AG_NUMTEXT_MAX], b[64];
    size_t n = ag_numtext_double_g15(a, v);
    snprintf(b, sizeof b, "%.15g", v);
    if (strcmp(a, b) || n != strlen(b))
        fail_msg("%.17g: \"%s\" instead of printf's \"%s\"", v, a, b);
    for (int prec = 1; prec <= 15; prec++) {
        n = ag_numtext_double_g(a, v, prec);
        snprintf(b, sizeof b, "%.*g", prec, v);
        if (strcmp(a, b) || n != strlen(b))
            fail_msg("%.17g at %d digits: \"%s\" instead of printf's \"%s\"", v, prec, a, b);
    }
    g15_checked++;
}

static void test_g15_is_printf(void **state)
{
    (void)state;
    const double fixed[] = {0.0, -0.0, 1e-4, 1e-5, 0.5, 1.0, 85.5, 64.9, -0.200000000000003,
                            0.1, 0.3, 2.675, 1e15, 999999999999999.0, 999999999999999.5,
                            123456789012345.5, 100000000000000.5, 1e14, 0.000099999999999999,
                            9.99999999999999e-5, 512345.25, 5812345.123456789, INFINITY,
                            -INFINITY, NAN, 1e300, 5e-324};
    for (size_t i = 0; i < sizeof fixed / sizeof *fixed; i++) {
        check_g15(fixed[i]);
        check_g15(-fixed[i]);
    }
    for (int e = -6; e <= 16; e++) {
        double p = pow(10.0, e);
        for (int k = 0; k < 40; k++) {
            check_g15(p);
            check_g15(-p);
            p = nextafter(p, INFINITY);
        }
        p = pow(10.0, e);
        for (int k = 0; k < 40; k++) {
            p = nextafter(p, 0);
            check_g15(p);
        }
    }
    /* building and UTM coordinates: short decimals and their neighbours */
    for (int i = 0; i < 200000; i++) {
        double base = (double)(next() % 20000000) / (double)pow(10.0, (double)(next() % 7));
        if (i % 3 == 0)
            base += 5400000;
        check_g15(base);
        check_g15(nextafter(base, 0));
        check_g15(-nextafter(base, INFINITY));
    }
    /* halves at 15 digits: exact ties between two 15-digit decimals */
    for (int i = 0; i < 20000; i++) {
        double t = (double)(100000000000000ull + next() % 900000000000000ull) + 0.5;
        check_g15(t);
        check_g15(t * 0.001);
    }
    /* every magnitude, random bits */
    for (int i = 0; i < 200000; i++) {
        double v = ldexp(1 + unit(), (int)(next() % 80) - 30);
        check_g15(next() & 1 ? v : -v);
        uint64_t b = next();
        memcpy(&v, &b, sizeof v);
        check_g15(v);
    }
    printf("numtext: %zu doubles printed as %%.15g prints them\n", g15_checked);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_g15_is_printf),
        cmocka_unit_test(test_special),
        cmocka_unit_test(test_integers),
        cmocka_unit_test(test_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
