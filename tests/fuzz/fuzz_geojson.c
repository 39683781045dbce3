/* GeoJSON footprints: every footprint read has loops of finite corners, or a precise
 * refusal. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/footprints.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_footprints *f = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_footprints_options opt = {0};
    ag_status s = ag_footprints_read_buffer((const char *)data, size, &opt, &f, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "geojson");
        return 0;
    }
    for (size_t i = 0; i < f->n; i++) {
        const ag_footprint *fp = &f->items[i];
        FUZZ_CHECK(fp->id != NULL, "footprint %zu has no id", i);
        for (size_t l = 0; l < fp->nloops; l++)
            for (size_t k = 0; k < 2 * fp->sizes[l]; k++)
                FUZZ_CHECK(isfinite(fp->loops[l][k]), "footprint %zu loop %zu", i, l);
    }
    ag_footprints_free(f);
    return 0;
}
