/* Tolerances of the extrusion sweep, in one place (metres, z up).
 *
 * The base values are the ones the procedural-extrusion method was tuned with for
 * building-sized plans in double precision: height clustering delta1 = 1e-4 and plan
 * clustering delta2 = 1e-6. They are scaled by ag_extrude_scale(extent) so a 1 km
 * site plan or a 10 cm model part keeps the same relative precision; every plan is
 * also moved to a local origin before the sweep so coordinates stay small. */
#ifndef AG_EXTRUDE_TOLERANCE_H
#define AG_EXTRUDE_TOLERANCE_H

#define AG_EXTRUDE_DELTA1 1e-4 /* height window in which events are handled together */
#define AG_EXTRUDE_DELTA2 1e-6 /* plan radius in which intersection points are one point */
#define AG_EXTRUDE_DELTA3 1e-5 /* margin by which an edge is lengthened when testing a hit */
#define AG_EXTRUDE_PARALLEL 1e-9 /* |sin| below which two plan edges count as parallel */
#define AG_EXTRUDE_SAME_SLOPE 1e-9 /* slopes (tan of angle) closer than this are equal */

/* Scale factor for delta1..delta3: 1 for plans up to 100 m across, linear above. */
static inline double ag_extrude_scale(double extent)
{
    return extent > 100.0 ? extent / 100.0 : 1.0;
}

#endif
