/* PLY point clouds (ASCII and binary): a cloud whose coordinates are all there, or a precise
 * refusal, never a read past the buffer. */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/ply.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_cloud *c = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_ply_read_buffer(data, size, &c, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "ply");
        return 0;
    }
    volatile double sum = 0;
    for (size_t i = 0; i < 3 * c->n; i++)
        sum += c->xyz[i]; /* every coordinate is there to read */
    (void)sum;
    ag_cloud_free(c);
    return 0;
}
