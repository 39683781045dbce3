#include "units.h"

#include <stdlib.h>

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

ag_units ag_units_given(double metres_per_unit)
{
    ag_units u = {.metres_per_unit = 1.0, .name = "m", .given = 1};
    if (metres_per_unit == 0.001) {
        u.metres_per_unit = 0.001;
        u.name = "mm";
    }
    return u;
}

int ag_units_decide(const ag_box *all, const ag_box *parts, size_t nparts, ag_units *u)
{
    *u = (ag_units){.metres_per_unit = 1.0, .name = "m"};
    if (ag_box_is_empty(all))
        return 0;
    u->height = all->max[2] - all->min[2];
    double *ext = malloc((nparts + 1) * sizeof *ext);
    if (!ext)
        return -1;
    size_t n = 0;
    for (size_t c = 0; c < nparts; c++) {
        if (ag_box_is_empty(&parts[c]))
            continue;
        double e = 0;
        for (int a = 0; a < 3; a++)
            if (parts[c].max[a] - parts[c].min[a] > e)
                e = parts[c].max[a] - parts[c].min[a];
        ext[n++] = e;
    }
    if (n) {
        qsort(ext, n, sizeof *ext, by_value);
        u->median_part = ext[n / 2];
    }
    free(ext);
    if (u->height > AG_UNITS_MAX_METRE_HEIGHT && u->median_part > AG_UNITS_MAX_METRE_PART) {
        u->metres_per_unit = 0.001;
        u->name = "mm";
    }
    return 0;
}
