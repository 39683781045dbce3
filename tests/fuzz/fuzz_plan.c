/* Building descriptions (plan JSON): read and validated, or refused precisely. */
#include <stddef.h>
#include <stdint.h>

#include "core/extrude/plan.h"
#include "fuzz_check.h"
#include "io/plan_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_plan *p = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_plan_json_read_buffer((const char *)data, size, &p, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "plan");
        return 0;
    }
    ag_plan_free(p);
    return 0;
}
