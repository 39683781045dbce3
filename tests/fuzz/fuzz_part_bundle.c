/* Part bundles (.agpart): a bundle that reads writes a bundle that reads again to the same
 * text; anything else is refused precisely. */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/part_bundle.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_part **parts = NULL, **back = NULL;
    size_t n = 0, nback = 0;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_part_bundle_read((const char *)data, size, &parts, &n, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "part bundle");
        return 0;
    }
    char *a = NULL, *b = NULL;
    size_t alen = 0, blen = 0;
    FUZZ_CHECK(ag_part_bundle_write((const ag_part *const *)parts, n, &a, &alen, &err) == AG_OK,
               "write: %s", err.text);
    s = ag_part_bundle_read(a, alen, &back, &nback, &err);
    FUZZ_CHECK(s == AG_OK && nback == n, "the written bundle does not read back: %s", err.text);
    FUZZ_CHECK(ag_part_bundle_write((const ag_part *const *)back, nback, &b, &blen, &err) ==
                   AG_OK,
               "write again: %s", err.text);
    FUZZ_CHECK(alen == blen && memcmp(a, b, alen) == 0, "write is not a fixed point");
    free(a);
    free(b);
    ag_part_bundle_free(parts, n);
    ag_part_bundle_free(back, nback);
    return 0;
}
