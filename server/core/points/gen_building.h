/* Generated building point clouds whose planes are known, for tests and benchmarks.
 *
 * A block of width x depth x height with a gable roof (ridge along x), a grid of windows on
 * the front (y = 0) and back facades and a column of them on the sides. A window is an
 * opening in its wall with a glass plane set back (recessed), level with the wall (flush:
 * 2 cm behind it) or standing out (proud), and four reveals joining glass and wall. Points
 * are sampled area-uniformly with Gaussian noise along each surface's normal. The whole
 * building can be turned about z and moved to large (UTM-like) coordinates.
 *
 * Every point carries its ground truth: int32 `plane` (one id per planar patch: 0-3 the
 * walls front, right, back, left, 4-5 the roof planes, then per window its glass and four
 * reveals) and int32 `window` (the window, or -1). A flush window's glass counts as its
 * wall's plane: no geometric test can tell them apart. */
#ifndef AG_GEN_BUILDING_H
#define AG_GEN_BUILDING_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"

typedef enum {
    AG_GEN_WINDOW_RECESSED = 0,
    AG_GEN_WINDOW_FLUSH,
    AG_GEN_WINDOW_PROUD,
} ag_gen_window_kind;

typedef struct {
    size_t points;            /* 0 = 100000 */
    double width, depth;      /* 0 = 24 x 12 metres */
    double height;            /* eaves; 0 = 9 */
    double ridge;             /* ridge above the eaves; 0 = 4; < 0 a flat roof */
    unsigned cols, rows;      /* windows on the front and back; 0 = 6 x 3 */
    unsigned side_cols;       /* windows per row on the sides; 0 = 2 */
    double window_w, window_h;/* 0 = 1.2 x 1.5 */
    ag_gen_window_kind window;
    double window_depth;      /* how far glass is set back or stands out; 0 = 0.25 */
    double noise;             /* sigma along the normal in metres; 0 = 0.005; < 0 none */
    double jitter;            /* random shift of each window, metres (0: a regular grid) */
    double rotation;          /* degrees about the vertical axis through the centre */
    double origin[3];         /* absolute position of the block's corner (x = y = z = 0) */
    int absolute;             /* store origin + position in xyz (offset 0) instead of the
                               * cloud's offset: a cloud with large raw coordinates */
    uint64_t seed;
} ag_gen_building_options;

ag_status ag_gen_building(const ag_gen_building_options *opt, ag_cloud **out, ag_error *err);

/* Planes of a generated building (walls, roofs, and 5 per window), for sizing tests. */
size_t ag_gen_building_planes(const ag_gen_building_options *opt);

#endif
