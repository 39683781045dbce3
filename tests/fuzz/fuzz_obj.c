/* OBJ reader: any bytes give a mesh whose indices are in range, or a precise refusal. */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_check.h"
#include "io/obj.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_obj_read_options opt = {.max_vertices = 200000, .max_triangles = 200000};
    ag_mesh *m = NULL;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_obj_read_buffer((const char *)data, size, &opt, &m, &err);
    if (s != AG_OK) {
        fuzz_check_refusal(s, &err, "obj");
        return 0;
    }
    for (size_t i = 0; i < 3 * m->ntris; i++)
        FUZZ_CHECK(m->tri[i] < m->nverts, "index %u of %zu vertices", m->tri[i], m->nverts);
    for (size_t t = 0; t < m->ntris; t++)
        FUZZ_CHECK(m->tri_component[t] < m->ncomponents, "component %u of %zu",
                   m->tri_component[t], m->ncomponents);
    ag_mesh_free(m);
    return 0;
}
