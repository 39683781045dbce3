/* Shared by the fuzz targets: a property that fails aborts with a message (libFuzzer keeps
 * the input that did it), and every problem a parser returns must be a precise one. */
#ifndef AG_FUZZ_CHECK_H
#define AG_FUZZ_CHECK_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/status.h"

#define FUZZ_CHECK(cond, ...)                                                                  \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "fuzz property failed: %s: ", #cond);                              \
            fprintf(stderr, __VA_ARGS__);                                                      \
            fputc('\n', stderr);                                                               \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

/* A refusal carries its status and a message (never an empty one, never an internal error
 * for bad input). */
static inline void fuzz_check_refusal(ag_status s, const ag_error *err, const char *what)
{
    FUZZ_CHECK(s != AG_ERR_INTERNAL, "%s: internal error for bad input: %s", what, err->text);
    FUZZ_CHECK(err->code == s, "%s: status %d but err->code %d", what, (int)s, (int)err->code);
    FUZZ_CHECK(err->text[0] != '\0', "%s: a refusal without a message (status %d)", what, (int)s);
}

#endif
