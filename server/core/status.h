/* Status codes and the caller-owned error record shared by every layer.
 *
 * The list is an X-macro so the enum, the name, the default message and the HTTP
 * status come from one place; the net layer maps a status to a problem+json body
 * with nothing more than ag_status_http() and ag_status_name(). */
#ifndef AG_STATUS_H
#define AG_STATUS_H

#include <stddef.h>

/*  name                           value http slug (problem type)      message */
#define AG_STATUS_LIST(X)                                                        \
    X(AG_OK,                         0,   200, "ok",                    "ok")                        \
    X(AG_ERR_NOMEM,                  -1,  503, "out-of-memory",         "out of memory")             \
    X(AG_ERR_IO,                     -2,  500, "io",                    "input/output error")        \
    X(AG_ERR_PARSE,                  -3,  422, "parse",                 "the input could not be parsed") \
    X(AG_ERR_INVALID,                -4,  400, "invalid",               "invalid argument")          \
    X(AG_ERR_NOT_FOUND,              -5,  404, "not-found",             "not found")                 \
    X(AG_ERR_CONFLICT,               -6,  409, "conflict",              "conflict")                  \
    X(AG_ERR_STALE,                  -7,  412, "stale",                 "the version is stale")      \
    X(AG_ERR_PRECONDITION_REQUIRED,  -8,  428, "precondition-required", "a precondition is required") \
    X(AG_ERR_TOO_LARGE,              -9,  413, "too-large",             "the input is too large")    \
    X(AG_ERR_UNSUPPORTED,            -10, 415, "unsupported",           "unsupported format")        \
    X(AG_ERR_CANCELLED,              -11, 409, "cancelled",             "the work was cancelled")    \
    X(AG_ERR_DB,                     -12, 500, "database",              "database error")            \
    X(AG_ERR_DB_TOO_NEW,             -13, 500, "database-too-new",      "the database is newer than this build") \
    X(AG_ERR_BUSY,                   -14, 503, "busy",                  "the server is busy")        \
    X(AG_ERR_EMPTY,                  -15, 422, "empty",                 "the input holds no geometry") \
    X(AG_ERR_INTERNAL,               -16, 500, "internal",              "internal error")            \
    X(AG_ERR_METHOD_NOT_ALLOWED,     -17, 405, "method-not-allowed",    "method not allowed")       \
    X(AG_ERR_NOT_PROCEDURALIZED,     -18, 409, "not-proceduralized",    "the model is not proceduralized") \
    X(AG_ERR_UNDO_CONFLICT,          -19, 409, "undo-conflict",         "nothing can be undone or redone here") \
    X(AG_ERR_EXTERNAL_REF,           -20, 422, "external-reference",    "the file refers to another file") \
    /* the work an op or job would do is past the server's limits (its input may be small) */ \
    X(AG_ERR_RESULT_TOO_LARGE,       -21, 422, "too-large",             "the result would be too large") \
    X(AG_ERR_DEADLINE,               -22, 503, "deadline",              "the work took longer than its time budget") \
    X(AG_ERR_RATE_LIMITED,           -23, 429, "rate-limited",          "too many requests")         \
    X(AG_ERR_STORAGE_FULL,           -24, 507, "storage-full",          "the database is full")      \
    X(AG_ERR_STORE_UNAVAILABLE,      -25, 503, "store-unavailable",     "the database cannot be read or written") \
    X(AG_ERR_URI_TOO_LONG,           -26, 414, "uri-too-long",          "the URL is too long")       \
    X(AG_ERR_HEADERS_TOO_LARGE,      -27, 431, "headers-too-large",     "the request headers are too large") \
    X(AG_ERR_NOT_AVAILABLE,          -30, 422, "not-available",         "this step is not available for the model") \
    X(AG_ERR_UNAUTHORIZED,           -40, 401, "unauthorized",          "sign in first")             \
    X(AG_ERR_FORBIDDEN,              -41, 403, "forbidden",             "not allowed for this account")

typedef enum {
#define AG__STATUS_ENUM(name, value, http, slug, msg) name = value,
    AG_STATUS_LIST(AG__STATUS_ENUM)
#undef AG__STATUS_ENUM
} ag_status;

/* Filled by a failing function when the caller passes one; never allocates.
 * `element` is a 1-based line, element or byte index where that makes sense, else 0. A text
 * longer than the buffer is cut between UTF-8 characters, never inside one. */
#define AG_ERROR_TEXT 256
typedef struct {
    ag_status code;
    long element;
    char text[AG_ERROR_TEXT];
} ag_error;

/* "AG_ERR_PARSE" → "parse" style stable slug used in problem type URIs. */
const char *ag_status_name(ag_status s);
const char *ag_status_message(ag_status s);
/* "not-found" for AG_ERR_NOT_FOUND: the stable part of a problem type URI. */
const char *ag_status_slug(ag_status s);
int ag_status_http(ag_status s);

/* Records code, element and a printf-formatted text into err (if non-NULL); returns code
 * so a function can `return ag_error_set(err, AG_ERR_PARSE, line, "...", ...)`. */
ag_status ag_error_set(ag_error *err, ag_status code, long element, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void ag_error_clear(ag_error *err);

#endif
