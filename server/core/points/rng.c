#include "rng.h"

#include <math.h>

double ag_rng_gauss(ag_rng *r)
{
    double u = ag_rng_unit(r), v = ag_rng_unit(r);
    if (u < 1e-300)
        u = 1e-300;
    return sqrt(-2 * log(u)) * cos(2 * M_PI * v);
}
