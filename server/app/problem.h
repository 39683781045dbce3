/* Problems (RFC 9457) as the REST and live layers send them: type
 * urn:archgram:problem:<slug>, title, status, detail (err->text or the status message) and,
 * when err->element > 0, "line" for parse errors or "element" otherwise. */
#ifndef AG_PROBLEM_H
#define AG_PROBLEM_H

#include <jansson.h>

#include "../core/status.h"

json_t *ag_problem_json(ag_status status, const ag_error *err);
/* A problem as compact JSON text (malloc'd). */
char *ag_problem_text(ag_status status, const ag_error *err);

#endif
