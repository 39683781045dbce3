/* Numbers as text, fast, for writers of large text files (OBJ).
 *
 * ag_numtext_double writes the shortest decimal that reads back (strtod, or any correctly
 * rounding reader such as io/obj.c's) to exactly the same double: plain notation
 * ("12.5", "-0.001", "3", "-0") for magnitudes from 1e-5 to below 2^53, where the digits are
 * found with exact 128-bit integer arithmetic; other values (smaller, larger, subnormal,
 * non-finite) as printf's "%.17g", which is exact too. So a file written with it holds
 * every coordinate exactly, as "%.17g" did, in fewer bytes and a fraction of the time.
 *
 * Written here because no Debian C library does it: the shortest-round-trip formatters
 * Debian packages (double-conversion, dragonbox) are C++. */
#ifndef AG_NUMTEXT_H
#define AG_NUMTEXT_H

#include <stddef.h>
#include <stdint.h>

/* The most bytes either function writes, the terminating NUL included. */
#define AG_NUMTEXT_MAX 32

/* Writes v to out (AG_NUMTEXT_MAX bytes) with a terminating NUL; returns the length. */
size_t ag_numtext_double(char *out, double v);
/* Writes v to out (AG_NUMTEXT_MAX bytes) with a NUL exactly as printf's "%.15g" does, and
 * returns the length: for magnitudes from 1e-4 to below 1e15 (plain notation) the 15 digits
 * are found with exact integer arithmetic; the rest, and exact ties (printf rounds those
 * by the rounding mode), go to snprintf itself. For writers of large JSON files (jansson's
 * REAL_PRECISION(15) prints "%.15g"), where snprintf takes most of the time. */
size_t ag_numtext_double_g15(char *out, double v);
/* The same for prec digits, 1 to 15 ("%.*g"; the grammar text prints "%.12g"). */
size_t ag_numtext_double_g(char *out, double v, int prec);
/* Writes v in decimal to out (AG_NUMTEXT_MAX bytes) with a NUL; returns the length. */
size_t ag_numtext_u64(char *out, uint64_t v);

#endif
