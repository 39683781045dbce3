#include "status.h"

#include "utf8.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *ag_status_name(ag_status s)
{
    switch (s) {
#define AG__STATUS_NAME(name, value, http, slug, msg) case name: return #name;
        AG_STATUS_LIST(AG__STATUS_NAME)
#undef AG__STATUS_NAME
    }
    return "AG_ERR_INTERNAL";
}

const char *ag_status_slug(ag_status s)
{
    switch (s) {
#define AG__STATUS_SLUG(name, value, http, slug, msg) case name: return slug;
        AG_STATUS_LIST(AG__STATUS_SLUG)
#undef AG__STATUS_SLUG
    }
    return "internal";
}

const char *ag_status_message(ag_status s)
{
    switch (s) {
#define AG__STATUS_MSG(name, value, http, slug, msg) case name: return msg;
        AG_STATUS_LIST(AG__STATUS_MSG)
#undef AG__STATUS_MSG
    }
    return "internal error";
}

int ag_status_http(ag_status s)
{
    switch (s) {
#define AG__STATUS_HTTP(name, value, http, slug, msg) case name: return http;
        AG_STATUS_LIST(AG__STATUS_HTTP)
#undef AG__STATUS_HTTP
    }
    return 500;
}

ag_status ag_error_set(ag_error *err, ag_status code, long element, const char *fmt, ...)
{
    if (err) {
        err->code = code;
        err->element = element;
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(err->text, sizeof err->text, fmt, ap);
        va_end(ap);
        if (n < 0)
            err->text[0] = '\0';
        else if ((size_t)n >= sizeof err->text)
            ag_utf8_trim_partial(err->text); /* cut mid-character, it would not be UTF-8 */
    }
    return code;
}

void ag_error_clear(ag_error *err)
{
    if (err) {
        err->code = AG_OK;
        err->element = 0;
        err->text[0] = '\0';
    }
}
