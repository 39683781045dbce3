/* The integer-grid stress profiles, shared by bench/extrude.c and the extrusion tests:
 * horizontal segments inwards and outwards at whole heights, so parts of a building touch
 * exactly along edges. */
#ifndef AG_EXTRUDE_GRID_PROFILES_H
#define AG_EXTRUDE_GRID_PROFILES_H

#include "core/extrude/extrude.h"

/* Indices of grid_profiles(). */
enum { GP_HIP, GP_STEEP, GP_WALL, GP_R2, GP_OVER, GP_SOFFIT, GP_R45, GP_TERRACE };

static void grid_profiles(ag_plan *p, double h)
{
    ag_profile_point hip[] = {{0, 0}, {0, h}, {1, h + 1}};
    ag_profile_point steep[] = {{0, 0}, {0, h}, {0.5, h + 1}};
    ag_profile_point wall[] = {{0, 0}, {0, h + 1}};
    ag_profile_point r2[] = {{0, 0}, {0, h}, {2, h + 1}};
    ag_profile_point over[] = {{0, 0}, {0, h}, {-1, h + 1}, {1, h + 2}};
    ag_profile_point soffit[] = {{0, 0}, {0, h}, {-1, h}, {1, h + 2}};
    ag_profile_point r45[] = {{0, 0}, {1, 1}};
    ag_profile_point terrace[] = {{0, 0}, {0, h}, {1, h}, {1, h + 1}, {2, h + 2}};
    ag_plan_add_profile(p, "hip", hip, 3, NULL, NULL, NULL);
    ag_plan_add_profile(p, "steep", steep, 3, NULL, NULL, NULL);
    ag_plan_add_profile(p, "wall", wall, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "r2", r2, 3, NULL, NULL, NULL);
    ag_plan_add_profile(p, "over", over, 4, NULL, NULL, NULL);
    ag_plan_add_profile(p, "soffit", soffit, 4, NULL, NULL, NULL);
    ag_plan_add_profile(p, "r45", r45, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "terrace", terrace, 5, NULL, NULL, NULL);
}

#endif
