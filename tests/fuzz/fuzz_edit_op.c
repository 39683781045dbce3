/* Edit-op JSON: an op that parses writes the canonical JSON, which parses to an op that
 * writes the same JSON again. */
#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "core/edit/edit.h"
#include "fuzz_check.h"
#include "io/edit_op_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_edit_op op = {0}, again = {0};
    ag_edit_op_origin from = {0}, from2 = {0};
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_edit_op_json_parse_ex((const char *)data, size, &op, &from, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "edit op");
        ag_edit_op_origin_clear(&from);
        return 0;
    }
    json_t *a = ag_edit_op_json_to_ex(&op, &from);
    FUZZ_CHECK(a != NULL, "no JSON for a parsed op");
    s = ag_edit_op_json_from_ex(a, &again, &from2, &err);
    char *text = json_dumps(a, JSON_SORT_KEYS);
    FUZZ_CHECK(s == AG_OK, "the canonical JSON does not parse: %s\n%s", err.text, text);
    json_t *b = ag_edit_op_json_to_ex(&again, &from2);
    FUZZ_CHECK(json_equal(a, b), "not a fixed point: %s", text);
    free(text);
    json_decref(a);
    json_decref(b);
    ag_edit_op_clear(&op);
    ag_edit_op_clear(&again);
    ag_edit_op_origin_clear(&from);
    ag_edit_op_origin_clear(&from2);
    return 0;
}
