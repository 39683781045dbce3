/* Problems (RFC 9457) as the REST and live layers send them: type
 * urn:archgram:problem:<slug>, title, status, detail (err->text or the status message) and,
 * when err->element > 0, "line" for parse errors or "element" otherwise.
 *
 * Every message gets an answer: a detail that is not valid UTF-8 (it quotes input) is
 * repaired (U+FFFD for each bad byte) rather than failing the JSON, and when even that cannot
 * be built (out of memory) ag_problem_fallback writes a problem without allocating. */
#ifndef AG_PROBLEM_H
#define AG_PROBLEM_H

#include <jansson.h>
#include <stddef.h>

#include "../core/status.h"

/* NULL only when out of memory. */
json_t *ag_problem_json(ag_status status, const ag_error *err);
/* A problem as compact JSON text (malloc'd); NULL only when out of memory. */
char *ag_problem_text(ag_status status, const ag_error *err);
/* The problem without its detail into buf (cap >= AG_PROBLEM_FALLBACK_MAX), allocating
 * nothing; returns its length. */
#define AG_PROBLEM_FALLBACK_MAX 256
size_t ag_problem_fallback(ag_status status, char *buf, size_t cap);

#endif
