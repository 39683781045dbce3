/* A real printed as printf's "%.15g" prints it, byte for byte, in a fraction of the time: the
 * served split tree prints six of them per node with every edit.
 *
 * Magnitudes from 1e-4 to below 1e15 (every box coordinate in metres, also at UTM offsets)
 * take the fast path: the value scaled to 15 digits with an exact power of ten, the
 * product's rounding error recovered exactly with fma, rounded to an integer as printf rounds
 * the exact value; a product within a hair of a rounding tie, and every other value, goes to
 * snprintf. Written here because the C formatters Debian packages print the shortest
 * round-trip form (io/numtext.h), not 15 digits. */
#ifndef AG_REAL_TEXT_H
#define AG_REAL_TEXT_H

#include <stddef.h>

/* The most bytes ag_real_text_g15 writes, the terminating NUL included. */
#define AG_REAL_TEXT_MAX 32

/* Writes snprintf(out, AG_REAL_TEXT_MAX, "%.15g", v) into out; returns its length. */
size_t ag_real_text_g15(char *out, double v);

#endif
