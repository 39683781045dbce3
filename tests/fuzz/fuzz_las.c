/* LAS and LAZ point clouds (the first byte picks which the input is named as): a cloud
 * whose points are all there, or a precise refusal, never a read past the buffer or an
 * allocation the file's counts alone ask for. */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/cloud_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    ag_cloud_format fmt = data[0] & 1 ? AG_CLOUD_FORMAT_LAZ : AG_CLOUD_FORMAT_LAS;
    ag_cloud *c = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_cloud_import_buffer(data + 1, size - 1, fmt, &c, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, fmt == AG_CLOUD_FORMAT_LAZ ? "laz" : "las");
        return 0;
    }
    volatile double sum = 0;
    for (size_t i = 0; i < 3 * c->n; i++)
        sum += c->xyz[i];
    (void)sum;
    ag_cloud_free(c);
    return 0;
}
