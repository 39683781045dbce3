/* Status codes and the caller-owned error record shared by every layer.
 *
 * The list is an X-macro so the enum, the name, the default message and the HTTP
 * status come from one place; the net layer maps a status to a problem+json body
 * with nothing more than ag_status_http() and ag_status_name(). */
#ifndef AG_STATUS_H
#define AG_STATUS_H

#include <stddef.h>

/*        name               value  http  message */
#define AG_STATUS_LIST(X)                                                        \
    X(AG_OK,                   0,   200, "ok")                                   \
    X(AG_ERR_NOMEM,           -1,   503, "out of memory")                        \
    X(AG_ERR_IO,              -2,   500, "input/output error")                   \
    X(AG_ERR_PARSE,           -3,   422, "the input could not be parsed")        \
    X(AG_ERR_INVALID,         -4,   400, "invalid argument")                     \
    X(AG_ERR_NOT_FOUND,       -5,   404, "not found")                            \
    X(AG_ERR_CONFLICT,        -6,   409, "conflict")                             \
    X(AG_ERR_STALE,           -7,   412, "the version is stale")                 \
    X(AG_ERR_PRECONDITION,    -8,   428, "a precondition is required")          \
    X(AG_ERR_TOO_LARGE,       -9,   413, "the input is too large")               \
    X(AG_ERR_UNSUPPORTED,    -10,   415, "unsupported format")                   \
    X(AG_ERR_CANCELLED,      -11,   409, "the work was cancelled")               \
    X(AG_ERR_DB,             -12,   500, "database error")                       \
    X(AG_ERR_DB_TOO_NEW,     -13,   500, "the database is newer than this build") \
    X(AG_ERR_BUSY,           -14,   503, "the server is busy")                   \
    X(AG_ERR_EMPTY,          -15,   422, "the input holds no geometry")          \
    X(AG_ERR_INTERNAL,       -16,   500, "internal error")

typedef enum {
#define AG__STATUS_ENUM(name, value, http, msg) name = value,
    AG_STATUS_LIST(AG__STATUS_ENUM)
#undef AG__STATUS_ENUM
} ag_status;

/* Filled by a failing function when the caller passes one; never allocates.
 * `element` is a 1-based line, element or byte index where that makes sense, else 0. */
#define AG_ERROR_TEXT 256
typedef struct {
    ag_status code;
    long element;
    char text[AG_ERROR_TEXT];
} ag_error;

/* "AG_ERR_PARSE" → "parse" style stable slug used in problem type URIs. */
const char *ag_status_name(ag_status s);
const char *ag_status_message(ag_status s);
int ag_status_http(ag_status s);

/* Records code, element and a printf-formatted text into err (if non-NULL); returns code
 * so a function can `return ag_error_set(err, AG_ERR_PARSE, line, "...", ...)`. */
ag_status ag_error_set(ag_error *err, ag_status code, long element, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void ag_error_clear(ag_error *err);

#endif
