/* Uploads through the importer the service runs on them: glTF, GLB and everything else
 * assimp reads, sniffed from the content, no external files, in the child process that a
 * loop or a crash of assimp cannot take the caller with (app/import_sandbox.h): a mesh with
 * indices in range or a precise refusal within the deadline, never a read of another file. */
#include <stddef.h>
#include <stdint.h>

#include "app/import_sandbox.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* the first byte picks the format the request names: glTF, GLB, or none (sniffed) */
    static const ag_format formats[] = {AG_FORMAT_GLTF, AG_FORMAT_GLB, AG_FORMAT_UNKNOWN};
    if (size < 1)
        return 0;
    ag_format fmt = formats[data[0] % 3];
    if (fmt == AG_FORMAT_UNKNOWN)
        fmt = ag_format_sniff(data + 1, size - 1, NULL);
    if (fmt == AG_FORMAT_UNKNOWN || fmt == AG_FORMAT_OBJ)
        return 0; /* refused before reading / the OBJ reader has a target of its own */
    ag_mesh *m = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_import_options opt = {0};
    ag_status s = ag_import_sandbox_read(data + 1, size - 1, fmt, &opt, 1.0, &m, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "import");
        return 0;
    }
    for (size_t i = 0; i < 3 * m->ntris; i++)
        FUZZ_CHECK(m->tri[i] < m->nverts, "index %u of %zu vertices", m->tri[i], m->nverts);
    ag_mesh_free(m);
    return 0;
}
