/* A read-only JSON document for large inputs (GeoJSON footprints): parsed by yajl's event
 * parser into one array of nodes and one pool of text, so a megabyte of coordinates costs a
 * few allocations instead of one per value (a DOM of jansson values spent most of reading a
 * city in malloc and free).
 *
 * Nodes are indices; AG_JSONDOC_NONE is "no such node". Objects keep their members in order
 * (a member is a node with a key); arrays their elements. Numbers keep their value, and
 * whether they were written as integers (no fraction, no exponent, within int64). */
#ifndef AG_JSONDOC_H
#define AG_JSONDOC_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"

#define AG_JSONDOC_NONE UINT32_MAX

typedef enum {
    AG_JSON_NULL,
    AG_JSON_FALSE,
    AG_JSON_TRUE,
    AG_JSON_NUMBER,
    AG_JSON_STRING,
    AG_JSON_ARRAY,
    AG_JSON_OBJECT,
} ag_json_type;

typedef struct ag_jsondoc ag_jsondoc;

/* Parses data (len bytes, need not be NUL-terminated). A syntax error is AG_ERR_PARSE with
 * "<yajl's message> (line L, column C)" and the line in err->element. */
ag_status ag_jsondoc_parse(const char *data, size_t len, ag_jsondoc **out, ag_error *err);
void ag_jsondoc_free(ag_jsondoc *d);

uint32_t ag_jsondoc_root(const ag_jsondoc *d);
ag_json_type ag_jsondoc_type(const ag_jsondoc *d, uint32_t node);
/* Elements of an array or members of an object: the first child and the next sibling. */
uint32_t ag_jsondoc_first(const ag_jsondoc *d, uint32_t node);
uint32_t ag_jsondoc_next(const ag_jsondoc *d, uint32_t node);
/* How many elements or members; 0 for other types. */
size_t ag_jsondoc_size(const ag_jsondoc *d, uint32_t node);
/* The member of an object with this key (the first), else AG_JSONDOC_NONE. */
uint32_t ag_jsondoc_get(const ag_jsondoc *d, uint32_t object, const char *key);
/* Element i of an array, else AG_JSONDOC_NONE (O(i)). */
uint32_t ag_jsondoc_at(const ag_jsondoc *d, uint32_t array, size_t i);
/* A number's value (0 for other types), a string's text (NULL for other types). */
double ag_jsondoc_number(const ag_jsondoc *d, uint32_t node);
const char *ag_jsondoc_string(const ag_jsondoc *d, uint32_t node);
/* Non-zero when a number was written as an integer; *value gets it. */
int ag_jsondoc_integer(const ag_jsondoc *d, uint32_t node, int64_t *value);

#endif
