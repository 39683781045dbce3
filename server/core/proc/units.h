/* The length unit of a z-up mesh whose file does not say it, decided from the content and
 * reported with the evidence, so tolerances meant in metres (the label tolerance's cap, the
 * turn a label allows) mean the same for a building exported in metres or in millimetres.
 *
 * Only metres and millimetres are told apart: the two conventions of GIS and game data on one
 * side and of BIM/CAD exports on the other, a factor of 1000 apart and so far apart in size
 * that a building's size tells them. A model is in millimetres when both
 *   height     it is taller than AG_UNITS_MAX_METRE_HEIGHT units (no building is 1 km tall,
 *              and a millimetre model of one storey already is), and
 *   parts      its typical component (the median of the components' largest extents) is
 *              longer than AG_UNITS_MAX_METRE_PART units (a metre model's parts are windows,
 *              walls and whole buildings, never 100 m as a rule),
 * else in metres. Feet, inches and centimetres are not told from their neighbours (a factor
 * of 3 or 10 is within the size of buildings): they are taken as metres or millimetres, and
 * the label tolerance, relative to the model's diagonal below its cap, is then unchanged by
 * the unit for every model smaller than the cap's diagonal; a person who knows the unit names
 * it (`--unit`, the proceduralize request's "unit"). Linear in the components plus
 * one sort of their extents. */
#ifndef AG_UNITS_H
#define AG_UNITS_H

#include <stddef.h>

#include "../base/box.h"

/* Units: a model taller than this is not in metres. */
#define AG_UNITS_MAX_METRE_HEIGHT 1000.0
/* Units: a model whose median component is longer than this is not in metres. */
#define AG_UNITS_MAX_METRE_PART 100.0

typedef struct {
    double metres_per_unit; /* decided: 1 or 0.001; given: any of ag_units_named's */
    const char *name;       /* "m", "mm", or the given unit's name */
    int given;              /* the caller named the unit (no evidence below) */
    double height;          /* the model's z extent, file units */
    double median_part;     /* the median of the components' largest extents, file units */
} ag_units;

/* Decides from the model's box and its components' boxes (empty boxes are skipped).
 * Returns 0, or -1 when out of memory (*u then says metres). */
int ag_units_decide(const ag_box *all, const ag_box *parts, size_t nparts, ag_units *u);

/* The units of a caller that names them: metres_per_unit one of the named units' (see
 * ag_units_named; any other value is taken as metres). */
ag_units ag_units_given(double metres_per_unit);

/* The metres per unit of a unit a person names: "m", "dm", "cm", "mm", "ft" or "in". Returns 0,
 * or -1 for any other name. */
int ag_units_named(const char *name, double *metres_per_unit);

/* The names ag_units_named takes, for messages: "m, dm, cm, mm, ft or in". */
#define AG_UNITS_NAMES "m, dm, cm, mm, ft or in"


#endif
