#include "units.h"

#include <stdlib.h>
#include <string.h>

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The units a person may name: the metric ones and the two of US and UK building plans. */
static const struct {
    const char *name;
    double metres;
} named[] = {{"m", 1.0},     {"dm", 0.1},     {"cm", 0.01},
             {"mm", 0.001},  {"ft", 0.3048},  {"in", 0.0254}};

int ag_units_named(const char *name, double *metres_per_unit)
{
    for (size_t i = 0; name && i < sizeof named / sizeof *named; i++)
        if (strcmp(name, named[i].name) == 0) {
            *metres_per_unit = named[i].metres;
            return 0;
        }
    return -1;
}

ag_units ag_units_given(double metres_per_unit)
{
    ag_units u = {.metres_per_unit = 1.0, .name = "m", .given = 1};
    for (size_t i = 0; i < sizeof named / sizeof *named; i++)
        if (metres_per_unit == named[i].metres) {
            u.metres_per_unit = named[i].metres;
            u.name = named[i].name;
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
