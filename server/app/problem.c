#include "problem.h"

#include <stdio.h>
#include <stdlib.h>

json_t *ag_problem_json(ag_status status, const ag_error *err)
{
    char type[96];
    snprintf(type, sizeof type, "urn:archgram:problem:%s", ag_status_slug(status));
    const char *detail = err && err->text[0] ? err->text : ag_status_message(status);
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
