#include "meshjson.h"

#include <math.h>

static json_t *vec3_or_null(const double *v)
{
    if (!isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2]))
        return json_null();
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

json_t *ag_meshjson_summary(const ag_mesh *m)
{
    ag_box b = ag_mesh_bounds(m);
    json_t *names = json_array();
    for (size_t g = 0; names && g < m->ngroups; g++) {
        json_t *s = json_string(m->group_names[g]);
        /* Names that are not UTF-8 are shown with invalid bytes replaced. */
        if (!s) {
            char buf[256];
            size_t k = 0;
            for (const char *c = m->group_names[g]; *c && k + 1 < sizeof buf; c++)
                buf[k++] = (unsigned char)*c < 0x80 ? *c : '?';
            buf[k] = '\0';
            s = json_string(buf);
        }
        json_array_append_new(names, s ? s : json_null());
    }
    /* Bounds of an empty mesh are infinite, which JSON cannot hold: null instead. */
    return json_pack("{s:I,s:I,s:I,s:I,s:o*,s:{s:o,s:o},s:f}", "vertices", (json_int_t)m->nverts,
                     "triangles", (json_int_t)m->ntris, "components", (json_int_t)m->ncomponents,
                     "groups", (json_int_t)m->ngroups, "group_names", names, "bounds", "min",
                     vec3_or_null(b.min), "max", vec3_or_null(b.max), "diagonal",
                     ag_box_diagonal(&b));
}
