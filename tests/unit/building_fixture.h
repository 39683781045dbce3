/* Generated buildings for the proceduralization tests: walls, windows set into every facade
 * (proud, flush or recessed), a door, a flat, gable or hip roof, an optional ground plane,
 * built z up and then turned in plan, moved to a local frame, to UTM-sized coordinates or to
 * a frame centred on the plan, and written z up or y up. Header-only (every test is its own
 * binary); include it after <cmocka.h>. */
#ifndef AG_TEST_BUILDING_FIXTURE_H
#define AG_TEST_BUILDING_FIXTURE_H

#include <math.h>
#include <stdio.h>

#include "core/mesh.h"

typedef enum { ROOF_FLAT, ROOF_GABLE, ROOF_HIP } roof_kind;
typedef enum { FRAME_LOCAL, FRAME_UTM, FRAME_CENTRED } frame_kind;

typedef struct {
    double w, d, h;     /* plan (x, y) and wall height, metres */
    roof_kind roof;
    int ground;         /* a ground plane reaching 8 m around the plan */
    double turn;        /* plan rotation about up, degrees */
    frame_kind frame;
    int yup;            /* written y up: raw (x, y, z) = (x, up, -y) */
    double window_depth; /* windows' front relative to the wall face: > 0 proud, < 0 recessed */
} building_spec;

typedef struct {
    ag_mesh *m;
    const building_spec *s;
    double c, sn;       /* the plan turn */
    double off[3];      /* the frame's offset (z up) */
    int one_group;      /* everything in one group (as an exported game asset) */
    size_t comp;
} building_gen;

/* World (z up) to the raw coordinates the file holds. */
static inline void building_put(building_gen *g, double x, double y, double z)
{
    double X = g->c * x - g->sn * y + g->off[0], Y = g->sn * x + g->c * y + g->off[1];
    double Z = z + g->off[2];
    ag_status st = g->s->yup ? ag_mesh_add_vertex(g->m, X, Z, -Y)
                             : ag_mesh_add_vertex(g->m, X, Y, Z);
    assert_int_equal(st, AG_OK);
}

static inline void building_begin(building_gen *g, const char *name)
{
    if (g->one_group && g->m->ncomponents)
        return;
    size_t gi;
    assert_int_equal(ag_mesh_add_group(g->m, g->one_group ? "building" : name, &gi), AG_OK);
    assert_int_equal(ag_mesh_add_component(g->m, (int32_t)gi, &g->comp), AG_OK);
}

static inline void building_tri(building_gen *g, uint32_t a, uint32_t b, uint32_t c)
{
    /* a y-up file mirrors nothing: (x, z, -y) is a rotation, so the winding stays */
    assert_int_equal(ag_mesh_add_triangle(g->m, a, b, c, (uint32_t)g->comp), AG_OK);
}

/* An axis-aligned box (before the plan turn) as 12 outward triangles. */
static inline void building_box(building_gen *g, double x0, double x1, double y0, double y1,
                                double z0, double z1)
{
    uint32_t b = (uint32_t)g->m->nverts;
    for (int i = 0; i < 8; i++)
        building_put(g, i & 1 ? x1 : x0, i & 2 ? y1 : y0, i & 4 ? z1 : z0);
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12; i++)
        building_tri(g, b + f[i][0], b + f[i][1], b + f[i][2]);
}

/* Windows of one facade: u runs along it from (ox, oy) in direction (dx, dy), the facade's
 * outward normal is (dy, -dx). */
static inline void building_facade(building_gen *g, double ox, double oy, double dx, double dy,
                                   double len, const char *side)
{
    const double W = 1.2, H = 1.6, T = 0.12;
    double front = g->s->window_depth; /* the window box's outer face, from the wall face */
    int cols = (int)((len - 1.0) / 2.6), rows = (int)((g->s->h - 1.0) / 3.0);
    if (cols < 1)
        cols = 1;
    if (rows < 1)
        rows = 1;
    double u0 = (len - (cols - 1) * 2.6 - W) / 2;
    char name[64];
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < cols; i++) {
            snprintf(name, sizeof name, "window_%s_%d_%d", side, i, j);
            building_begin(g, name);
            double u = u0 + i * 2.6, z = 0.9 + j * 3.0;
            /* the box spans u..u+W along, [front - T, front] outwards of the wall face */
            double nx = dy, ny = -dx;
            double a[2] = {ox + dx * u + nx * (front - T), oy + dy * u + ny * (front - T)};
            double b[2] = {ox + dx * (u + W) + nx * front, oy + dy * (u + W) + ny * front};
            building_box(g, fmin(a[0], b[0]), fmax(a[0], b[0]), fmin(a[1], b[1]),
                         fmax(a[1], b[1]), z, z + H);
            /* the sill, proud of the window */
            double c[2] = {ox + dx * (u - 0.05) + nx * (front - T),
                           oy + dy * (u - 0.05) + ny * (front - T)};
            double e[2] = {ox + dx * (u + W + 0.05) + nx * (front + 0.06),
                           oy + dy * (u + W + 0.05) + ny * (front + 0.06)};
            building_box(g, fmin(c[0], e[0]), fmax(c[0], e[0]), fmin(c[1], e[1]),
                         fmax(c[1], e[1]), z - 0.08, z);
        }
}

/* The building of s in a new mesh; one_group puts everything in one group. */
static inline ag_mesh *building_make(const building_spec *s, int one_group)
{
    building_gen g = {.m = ag_mesh_create(), .s = s, .one_group = one_group};
    assert_non_null(g.m);
    double t = s->turn * M_PI / 180;
    g.c = cos(t);
    g.sn = sin(t);
    if (s->frame == FRAME_CENTRED) {
        /* the plan's centre (after the turn) on the origin, the ground at 0 */
        double cx = s->w / 2, cy = s->d / 2;
        g.off[0] = -(g.c * cx - g.sn * cy);
        g.off[1] = -(g.sn * cx + g.c * cy);
    } else if (s->frame == FRAME_UTM) {
        g.off[0] = 691234.5;
        g.off[1] = 5335678.25;
        g.off[2] = 374.0;
    } else {
        g.off[0] = 12.5; /* a local frame near the origin, as files with an offset removed */
        g.off[1] = 3.25;
        g.off[2] = 0.4;
    }
    const double th = 0.3, W = s->w, D = s->d, H = s->h;
    building_begin(&g, "wall_front");
    building_box(&g, 0, W, 0, th, 0, H);
    building_begin(&g, "wall_back");
    building_box(&g, 0, W, D - th, D, 0, H);
    building_begin(&g, "wall_left");
    building_box(&g, 0, th, th, D - th, 0, H);
    building_begin(&g, "wall_right");
    building_box(&g, W - th, W, th, D - th, 0, H);
    building_begin(&g, "door");
    building_box(&g, W / 2 - 0.6, W / 2 + 0.6, -0.08, 0.04, 0, 2.2);
    building_facade(&g, 0, 0, 1, 0, W, "front");
    building_facade(&g, W, D, -1, 0, W, "back");
    building_facade(&g, W, 0, 0, 1, D, "right");
    building_facade(&g, 0, D, 0, -1, D, "left");
    building_begin(&g, "roof");
    const double o = 0.4; /* eaves */
    if (s->roof == ROOF_FLAT) {
        building_box(&g, -o, W + o, -o, D + o, H, H + 0.3);
        building_box(&g, -o, W + o, -o, 0.2 - o, H + 0.3, H + 1.0); /* parapet */
        building_box(&g, -o, W + o, D + o - 0.2, D + o, H + 0.3, H + 1.0);
        building_box(&g, -o, 0.2 - o, 0.2 - o, D + o - 0.2, H + 0.3, H + 1.0);
        building_box(&g, W + o - 0.2, W + o, 0.2 - o, D + o - 0.2, H + 0.3, H + 1.0);
    } else {
        /* a gable roof has its ridge along x over the whole length, a hip roof a ridge
         * shortened by the depth's half at both ends; both are closed solids */
        double rise = 0.5 * (D + 2 * o), inset = s->roof == ROOF_HIP ? (D + 2 * o) / 2 : 0;
        if (inset > (W + 2 * o) / 2 - 0.5)
            inset = (W + 2 * o) / 2 - 0.5;
        uint32_t b = (uint32_t)g.m->nverts;
        building_put(&g, -o, -o, H);           /* 0 */
        building_put(&g, W + o, -o, H);        /* 1 */
        building_put(&g, W + o, D + o, H);     /* 2 */
        building_put(&g, -o, D + o, H);        /* 3 */
        building_put(&g, -o + inset, D / 2, H + rise);     /* 4 ridge west */
        building_put(&g, W + o - inset, D / 2, H + rise);  /* 5 ridge east */
        building_tri(&g, b + 0, b + 2, b + 1); /* eaves plane, facing down */
        building_tri(&g, b + 0, b + 3, b + 2);
        building_tri(&g, b + 0, b + 1, b + 5); /* south slope */
        building_tri(&g, b + 0, b + 5, b + 4);
        building_tri(&g, b + 2, b + 3, b + 4); /* north slope */
        building_tri(&g, b + 2, b + 4, b + 5);
        building_tri(&g, b + 1, b + 2, b + 5); /* east end */
        building_tri(&g, b + 3, b + 0, b + 4); /* west end */
    }
    if (s->ground) {
        building_begin(&g, "ground");
        uint32_t b = (uint32_t)g.m->nverts;
        building_put(&g, -8, -8, -0.02);
        building_put(&g, W + 8, -8, -0.02);
        building_put(&g, W + 8, D + 8, -0.02);
        building_put(&g, -8, D + 8, -0.02);
        building_tri(&g, b, b + 1, b + 2);
        building_tri(&g, b, b + 2, b + 3);
    }
    return g.m;
}

#endif
