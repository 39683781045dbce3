#include "ply_mesh_positions.h"

#include <float.h>
#include <math.h>

#include "ply.h"

int ag_ply_mesh_restore_positions(ag_mesh *m, const uint8_t *data, size_t len)
{
    ag_cloud *c = NULL;
    ag_error err;
    if (ag_ply_read_buffer(data, len, &c, &err) != AG_OK)
        return 0;
    int same = c->n == m->nverts;
    /* assimp's value is the file's rounded to float (then widened): within one float step */
    for (size_t i = 0; same && i < 3 * m->nverts; i++) {
        double v = c->xyz[i] + c->offset[i % 3];
        same = fabs(m->pos[i] - v) <= 2 * FLT_EPSILON * fmax(fabs(v), FLT_MIN);
    }
    if (same)
        for (size_t i = 0; i < 3 * m->nverts; i++)
            m->pos[i] = c->xyz[i] + c->offset[i % 3];
    ag_cloud_free(c);
    return same;
}
