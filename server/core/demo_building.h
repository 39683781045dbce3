/* Two small generated buildings (z-up metres, outward counter-clockwise triangles) that
 * give a fresh server, the viewer and the tests something recognisable to work on.
 * Every component is a closed solid in its own named group. */
#ifndef AG_DEMO_BUILDING_H
#define AG_DEMO_BUILDING_H

#include "mesh.h"

#define AG_DEMO_BUILDING_COUNT 2

/* which = 0: "Row house" — 12 × 8 m, 6 m walls as four slabs and a floor slab, a 6 × 2
 *            grid of identical framed windows and a door on the front (y = 0, facing −y),
 *            a gabled roof of two slabs with gable walls.
 * which = 1: "Tower" — an octagonal three-storey tower: floor slabs, a ring of eight
 *            identical columns per storey, a core, a flat roof with a parapet.
 * Returns a new mesh (free with ag_mesh_free), or NULL for another `which` or no memory. */
ag_mesh *ag_demo_building(int which);
/* The building's display name, or NULL. */
const char *ag_demo_building_name(int which);

#endif
