#include "numtext.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef unsigned __int128 u128;

static const uint64_t pow10_u64[20] = {1ull,
                                       10ull,
                                       100ull,
                                       1000ull,
                                       10000ull,
                                       100000ull,
                                       1000000ull,
                                       10000000ull,
                                       100000000ull,
                                       1000000000ull,
                                       10000000000ull,
                                       100000000000ull,
                                       1000000000000ull,
                                       10000000000000ull,
                                       100000000000000ull,
                                       1000000000000000ull,
                                       10000000000000000ull,
                                       100000000000000000ull,
                                       1000000000000000000ull,
                                       10000000000000000000ull};

/* "00" .. "99" */
static const char digit_pairs[201] = "00010203040506070809101112131415161718192021222324"
                                     "25262728293031323334353637383940414243444546474849"
                                     "50515253545556575859606162636465666768697071727374"
                                     "75767778798081828384858687888990919293949596979899";

size_t ag_numtext_u64(char *out, uint64_t v)
{
    char tmp[24];
    size_t n = sizeof tmp;
    while (v >= 100) {
        unsigned r = (unsigned)(v % 100);
        v /= 100;
        n -= 2;
        memcpy(tmp + n, digit_pairs + 2 * r, 2);
    }
    if (v >= 10) {
        n -= 2;
        memcpy(tmp + n, digit_pairs + 2 * v, 2);
    } else {
        tmp[--n] = (char)('0' + v);
    }
    size_t len = sizeof tmp - n;
    memcpy(out, tmp + n, len);
    out[len] = '\0';
    return len;
}

/* Powers of ten from 1e-6 to 1e16, as doubles (exact from 1e0 up). */
static const double pow10_double[23] = {1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1e0,  1e1,
                                        1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,
                                        1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16};

static size_t fallback(char *out, double v)
{
    int n = snprintf(out, AG_NUMTEXT_MAX, "%.17g", v);
    return n > 0 ? (size_t)n : 0;
}

size_t ag_numtext_double(char *out, double v)
{
    if (v == 0)
        return signbit(v) ? (memcpy(out, "-0", 3), 2) : (memcpy(out, "0", 2), 1);
    double a = fabs(v);
    if (!(a >= 1e-5 && a < 9007199254740992.0)) /* 2^53; also NaN and inf */
        return fallback(out, v);
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    int be = (int)(bits >> 52); /* a >= 1e-5: normal */
    uint64_t m = (bits & ((1ull << 52) - 1)) | (1ull << 52);
    int sh = 1075 - be; /* a = m / 2^sh, sh >= 1 here */
    /* k = floor(log10(a)), so that a * 10^s lies in [1e16, 1e17): estimated from the binary
     * exponent (log10(2) slightly low, so never above), then raised against the powers of
     * ten. Below 1 those are not exact and k may be one off next to a power of ten; that
     * costs nothing: one more digit is searched away below, one fewer finds no candidate
     * and falls back. */
    int k = (int)floor((be - 1023) * 0.30102999566398114);
    while (k < 16 && k >= -6 && a >= pow10_double[k + 1 + 6])
        k++;
    int s = 16 - k;
    if (s < 0 || s > 21)
        return fallback(out, v);
    /* The doubles next to a lie 2^-sh away, below only half that when m is a power of two:
     * a's rounding interval is (4m - lo, 4m + 2) / 2^(sh + 2) with lo 1 or 2. In units of
     * 10^-s it is (L, H) / 2^D. Products below 2^55 * 10^21 < 2^125 fit. */
    u128 p10 = (u128)pow10_u64[s > 19 ? 19 : s] * (s > 19 ? pow10_u64[s - 19] : 1);
    int D = sh + 2;
    if (D >= 127)
        return fallback(out, v);
    int pow2 = m == (1ull << 52) && be > 1;
    u128 L = (u128)(4 * m - (pow2 ? 1 : 2)) * p10, H = (u128)(4 * m + 2) * p10,
         X = (u128)(4 * m) * p10;
    u128 mask = ((u128)1 << D) - 1;
    uint64_t lf = (uint64_t)(L >> D), hf = (uint64_t)(H >> D), xf = (uint64_t)(X >> D);
    int h_exact = (H & mask) == 0;
    int x_half_up = ((X & mask) << 1) >= ((u128)1 << D); /* frac(x) >= 1/2 */
    uint64_t cmin = lf + 1, cmax = h_exact ? hf - 1 : hf;
    if (cmin > cmax)
        return fallback(out, v); /* cannot happen: the interval is wider than 1 */
    /* the most trailing zeros a candidate inside the interval can have */
    int t = 0;
    while (t < 18) {
        uint64_t p = pow10_u64[t + 1];
        if (cmax - cmax % p < cmin)
            break;
        t++;
    }
    uint64_t p = pow10_u64[t];
    /* of the multiples of 10^t inside, the one nearest to a */
    uint64_t xr = xf + (uint64_t)x_half_up;
    uint64_t c = (xr + p / 2) / p * p;
    if (c < cmin)
        c += p;
    if (c > cmax)
        c -= p;
    if (c < cmin || c > cmax)
        c = cmax - cmax % p;
    uint64_t digits = c / p;
    int e10 = t - s; /* a ~ digits * 10^e10 */
    char d[24];
    size_t nd = ag_numtext_u64(d, digits);
    size_t n = 0;
    if (v < 0)
        out[n++] = '-';
    if (e10 >= 0) {
        memcpy(out + n, d, nd);
        n += nd;
        for (int i = 0; i < e10; i++)
            out[n++] = '0';
    } else if ((int)nd + e10 > 0) {
        size_t ip = (size_t)((int)nd + e10);
        memcpy(out + n, d, ip);
        n += ip;
        out[n++] = '.';
        memcpy(out + n, d + ip, nd - ip);
        n += nd - ip;
    } else {
        out[n++] = '0';
        out[n++] = '.';
        for (int i = 0; i < -((int)nd + e10); i++)
            out[n++] = '0';
        memcpy(out + n, d, nd);
        n += nd;
    }
    out[n] = '\0';
    return n;
}

/* What snprintf "%.*g" writes with prec (1 to 15) digits: plain notation, printf's own
 * decision, for decimal exponents from -4 to below prec. */
static size_t printf_g(char *out, double v, int prec)
{
    int n = snprintf(out, AG_NUMTEXT_MAX, "%.*g", prec, v);
    return n > 0 ? (size_t)n : 0;
}

size_t ag_numtext_double_g(char *out, double v, int prec)
{
    if (prec < 1 || prec > 15)
        return printf_g(out, v, prec < 1 ? 1 : 17);
    double a = fabs(v);
    if (!(a >= 1e-4 && a < pow10_double[prec + 6])) /* exponent notation, zero, NaN, inf */
        return printf_g(out, v, prec);
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    int be = (int)(bits >> 52); /* a >= 1e-4: normal */
    uint64_t m = (bits & ((1ull << 52) - 1)) | (1ull << 52);
    int sh = 1075 - be; /* a = m / 2^sh, 3 <= sh <= 66 here */
    /* x = floor(log10(a)), estimated; a wrong estimate gives digits out of [1e14, 1e15)
     * below and goes to printf */
    int x = (int)floor(log10(a));
    int s = prec - 1 - x; /* a * 10^s has prec digits before the point */
    if (s < 0 || s > 18)
        return printf_g(out, v, prec);
    u128 q = (u128)m * pow10_u64[s]; /* < 2^53 * 10^18 < 2^113 */
    u128 rem = q & (((u128)1 << sh) - 1), half = (u128)1 << (sh - 1);
    uint64_t d = (uint64_t)(q >> sh);
    int below = d < pow10_u64[prec - 1]; /* the estimate was one too high */
    if (rem > half)
        d++;
    if (rem == half || below || d >= pow10_u64[prec])
        /* a tie (the rounding mode decides), the estimate off next to a power of ten, or
         * rounding up to the next power of ten */
        return printf_g(out, v, prec);
    char dg[24];
    ag_numtext_u64(dg, d); /* prec digits */
    int nd = prec;
    while (nd > 1 && dg[nd - 1] == '0')
        nd--;
    size_t n = 0;
    if (v < 0)
        out[n++] = '-';
    if (x >= 0) {
        int ip = x + 1; /* digits before the point */
        memcpy(out + n, dg, (size_t)ip);
        n += (size_t)ip;
        if (nd > ip) {
            out[n++] = '.';
            memcpy(out + n, dg + ip, (size_t)(nd - ip));
            n += (size_t)(nd - ip);
        }
    } else {
        out[n++] = '0';
        out[n++] = '.';
        for (int i = 0; i < -x - 1; i++)
            out[n++] = '0';
        memcpy(out + n, dg, (size_t)nd);
        n += (size_t)nd;
    }
    out[n] = '\0';
    return n;
}

size_t ag_numtext_double_g15(char *out, double v)
{
    return ag_numtext_double_g(out, v, 15);
}
