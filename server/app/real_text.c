#include "real_text.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static const double pow10_exact[19] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,
                                       1e7,  1e8,  1e9,  1e10, 1e11, 1e12, 1e13,
                                       1e14, 1e15, 1e16, 1e17, 1e18};

static size_t slow(char *out, double v)
{
    int n = snprintf(out, AG_REAL_TEXT_MAX, "%.15g", v);
    return n > 0 ? (size_t)n : 0;
}

size_t ag_real_text_g15(char *out, double v)
{
    double a = fabs(v);
    if (!(a >= 1e-4 && a < 1e15)) /* also zero, NaN and the infinities */
        return slow(out, v);
    /* the decimal exponent: 10^e <= a < 10^(e + 1), estimated from the binary one (off by
     * one at most) and checked exactly below */
    int bexp;
    frexp(a, &bexp);
    int e = (int)floor((bexp - 1) * 0.30102999566398120);
    if (e < -4)
        e = -4;
    if (e > 14)
        e = 14;
    uint64_t digits = 0;
    for (int tries = 0;; tries++) {
        if (tries == 3)
            return slow(out, v);
        int k = 14 - e; /* 0 ..18: an exact power of ten */
        double p = a * pow10_exact[k];
        double residual = fma(a, pow10_exact[k], -p); /* a * 10^k = p + residual exactly */
        double r = nearbyint(p);
        double d = (p - r) + residual; /* p - r is exact: both near 1e14 .. 1e15 */
        if (fabs(fabs(d) - 0.5) < 1e-6)
            return slow(out, v); /* a tie or nearly: printf decides */
        if (d > 0.5)
            r += 1;
        else if (d < -0.5)
            r -= 1;
        int below = p < 1e14 || (p == 1e14 && residual < 0); /* a * 10^k < 10^14 */
        int above = p > 1e15 || (p == 1e15 && residual >= 0); /* a * 10^k >= 10^15 */
        if (below || above) { /* e was off by one */
            if (tries == 2 || (below && e == -4) || (above && e == 14))
                return slow(out, v);
            e += below ? -1 : 1;
            continue;
        }
        if (r >= 1e15) { /* rounds up to the next decade: 1.00000000000000 times 10^(e + 1) */
            if (e == 14)
                return slow(out, v);
            digits = 100000000000000ULL;
            e++;
            break;
        }
        digits = (uint64_t)r;
        break;
    }
    char d15[16];
    for (int i = 14; i >= 0; i--) {
        d15[i] = (char)('0' + digits % 10);
        digits /= 10;
    }
    /* %g with 15 digits and an exponent from -4 to 14: plain notation, trailing zeros and a
     * bare point dropped */
    int last = 14;
    while (last > 0 && d15[last] == '0' && last > e)
        last--;
    size_t n = 0;
    if (v < 0)
        out[n++] = '-';
    if (e >= 0) {
        for (int i = 0; i <= e; i++)
            out[n++] = d15[i];
        if (last > e) {
            out[n++] = '.';
            for (int i = e + 1; i <= last; i++)
                out[n++] = d15[i];
        }
    } else {
        out[n++] = '0';
        out[n++] = '.';
        for (int i = 0; i < -e - 1; i++)
            out[n++] = '0';
        for (int i = 0; i <= last; i++)
            out[n++] = d15[i];
    }
    out[n] = '\0';
    return n;
}
