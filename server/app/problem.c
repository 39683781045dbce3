#include "problem.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/utf8.h"

json_t *ag_problem_json(ag_status status, const ag_error *err)
{
    char type[96];
    snprintf(type, sizeof type, "urn:archgram:problem:%s", ag_status_slug(status));
    const char *text = err && err->text[0] ? err->text : ag_status_message(status);
    /* each bad byte may become the 3 bytes of U+FFFD */
    char detail[3 * AG_ERROR_TEXT + 1];
    ag_utf8_repair(text, strnlen(text, AG_ERROR_TEXT), detail, sizeof detail);
    json_t *p = json_pack("{s:s, s:s, s:i, s:s}", "type", type, "title",
                          ag_status_message(status), "status", ag_status_http(status), "detail",
                          detail);
    if (p && err && err->element > 0)
        json_object_set_new(p, status == AG_ERR_PARSE ? "line" : "element",
                            json_integer(err->element));
    return p;
}

char *ag_problem_text(ag_status status, const ag_error *err)
{
    json_t *p = ag_problem_json(status, err);
    char *text = p ? json_dumps(p, JSON_COMPACT) : NULL;
    json_decref(p);
    return text;
}

size_t ag_problem_fallback(ag_status status, char *buf, size_t cap)
{
    /* slugs and messages are short ASCII constants: nothing here needs escaping */
    int n = snprintf(buf, cap,
                     "{\"type\":\"urn:archgram:problem:%s\",\"title\":\"%s\",\"status\":%d,"
                     "\"detail\":\"%s\"}",
                     ag_status_slug(status), ag_status_message(status), ag_status_http(status),
                     ag_status_message(status));
    if (n < 0 || (size_t)n >= cap) {
        n = snprintf(buf, cap, "{\"type\":\"urn:archgram:problem:internal\",\"status\":500}");
        if (n < 0)
            n = 0;
    }
    return (size_t)n;
}
