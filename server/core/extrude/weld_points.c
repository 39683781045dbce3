#include "weld_points.h"

static uint32_t root(uint32_t *par, uint32_t x)
{
    while (par[x] != x)
        x = par[x] = par[par[x]];
    return x;
}

ag_status ag_weld_points(const double *pos, ag_keyed *order, size_t n, double tol,
                         uint32_t *par)
{
    if (ag_keysort(order, n, NULL) != AG_OK)
        return AG_ERR_NOMEM;
    double t2 = tol * tol;
    for (size_t i = 0; i < n; i++) {
        const double *a = &pos[3 * order[i].val];
        for (size_t j = i + 1; j < n; j++) {
            const double *b = &pos[3 * order[j].val];
            if (b[0] - a[0] > tol)
                break;
            double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
            if (order[j].val != order[i].val && dx * dx + dy * dy + dz * dz <= t2) {
                uint32_t ra = root(par, order[i].val), rb = root(par, order[j].val);
                if (ra != rb)
                    par[ra > rb ? ra : rb] = ra < rb ? ra : rb;
            }
        }
    }
    for (size_t i = 0; i < n; i++)
        par[order[i].val] = root(par, order[i].val);
    return AG_OK;
}
