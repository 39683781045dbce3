#include "demo_building.h"

#include <math.h>
#include <stdio.h>

typedef struct {
    ag_mesh *m;
    int failed;
} builder;

/* Starts a component in a new group of that name; returns the component. */
static uint32_t part(builder *b, const char *name)
{
    size_t g, c = 0;
    if (ag_mesh_add_group(b->m, name, &g) != AG_OK ||
        ag_mesh_add_component(b->m, (int32_t)g, &c) != AG_OK)
        b->failed = 1;
    return (uint32_t)c;
}

static void tri(builder *b, uint32_t a, uint32_t c, uint32_t d, uint32_t comp)
{
    if (ag_mesh_add_triangle(b->m, a, c, d, comp) != AG_OK)
        b->failed = 1;
}

/* A closed prism: the convex polygon base[n] (any plane) swept by dir. The base is
 * reoriented so every face comes out counter-clockwise seen from outside. */
static void prism(builder *b, uint32_t comp, const double (*base)[3], int n, const double dir[3])
{
    double nx = 0, ny = 0, nz = 0; /* Newell normal of the base as given */
    for (int i = 0; i < n; i++) {
        const double *p = base[i], *q = base[(i + 1) % n];
        nx += (p[1] - q[1]) * (p[2] + q[2]);
        ny += (p[2] - q[2]) * (p[0] + q[0]);
        nz += (p[0] - q[0]) * (p[1] + q[1]);
    }
    int flip = nx * dir[0] + ny * dir[1] + nz * dir[2] < 0;
    uint32_t v0 = (uint32_t)b->m->nverts;
    for (int i = 0; i < n; i++) {
        const double *p = base[flip ? n - 1 - i : i];
        if (ag_mesh_add_vertex(b->m, p[0], p[1], p[2]) != AG_OK)
            b->failed = 1;
    }
    for (int i = 0; i < n; i++) {
        const double *p = base[flip ? n - 1 - i : i];
        if (ag_mesh_add_vertex(b->m, p[0] + dir[0], p[1] + dir[1], p[2] + dir[2]) != AG_OK)
            b->failed = 1;
    }
    if (b->failed)
        return;
    uint32_t bot = v0, top = v0 + (uint32_t)n;
    for (int i = 1; i + 1 < n; i++) {
        tri(b, bot, bot + (uint32_t)i + 1, bot + (uint32_t)i, comp);
        tri(b, top, top + (uint32_t)i, top + (uint32_t)i + 1, comp);
    }
    for (int i = 0; i < n; i++) {
        uint32_t j = (uint32_t)((i + 1) % n);
        tri(b, bot + (uint32_t)i, bot + j, top + j, comp);
        tri(b, bot + (uint32_t)i, top + j, top + (uint32_t)i, comp);
    }
}

/* An axis-aligned box: 8 vertices, 12 triangles. */
static void box(builder *b, uint32_t comp, double x0, double y0, double z0, double x1, double y1,
                double z1)
{
    const double base[4][3] = {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}};
    const double dir[3] = {0, 0, z1 - z0};
    prism(b, comp, base, 4, dir);
}

/* A window frame in the plane y ∈ [y0, y1]: four bars around a (w × h) opening at
 * (x, z), and a recessed pane. */
static void window_frame(builder *b, uint32_t comp, double x, double z, double w, double h,
                         double y0, double y1)
{
    const double t = 0.08; /* bar width */
    box(b, comp, x - t, y0, z - t, x + w + t, y1, z);         /* sill */
    box(b, comp, x - t, y0, z + h, x + w + t, y1, z + h + t); /* head */
    box(b, comp, x - t, y0, z, x, y1, z + h);                 /* left jamb */
    box(b, comp, x + w, y0, z, x + w + t, y1, z + h);         /* right jamb */
    box(b, comp, x, y1 - 0.03, z, x + w, y1 - 0.01, z + h);   /* pane */
}

static void row_house(builder *b)
{
    const double W = 12, D = 8, H = 6, T = 0.3;
    box(b, part(b, "floor"), 0, 0, -0.2, W, D, 0);
    box(b, part(b, "wall_front"), 0, 0, 0, W, T, H);
    box(b, part(b, "wall_back"), 0, D - T, 0, W, D, H);
    box(b, part(b, "wall_left"), 0, T, 0, T, D - T, H);
    box(b, part(b, "wall_right"), W - T, T, 0, W, D - T, H);

    /* Gables close the ends under the roof; the ridge runs along x at y = D/2. */
    const double rise = 3, ridge = H + rise;
    for (int side = 0; side < 2; side++) {
        double x = side ? W - T : 0;
        const double base[3][3] = {{x, 0, H}, {x, D, H}, {x, D / 2, ridge}};
        const double dir[3] = {T, 0, 0};
        prism(b, part(b, side ? "gable_right" : "gable_left"), base, 3, dir);
    }
    /* Roof slabs: sloped quads from the eave (0.3 m overhang) to the ridge, 0.2 m thick. */
    const double over = 0.3, slope = rise / (D / 2), thick = 0.2;
    const double ze = H - over * slope;
    const double front[4][3] = {{-over, -over, ze}, {W + over, -over, ze},
                                {W + over, D / 2, ridge}, {-over, D / 2, ridge}};
    const double back[4][3] = {{-over, D / 2, ridge}, {W + over, D / 2, ridge},
                               {W + over, D + over, ze}, {-over, D + over, ze}};
    const double up[3] = {0, 0, thick};
    prism(b, part(b, "roof_front"), front, 4, up);
    prism(b, part(b, "roof_back"), back, 4, up);

    /* 6 × 2 identical windows, symmetric about the door in the middle. */
    const double ww = 0.9, wh = 1.2, pitch = 2.0, x0 = W / 2 - 2.5 * pitch - ww / 2;
    const double rows[2] = {1.0, 3.6};
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 6; c++) {
            char name[32];
            snprintf(name, sizeof name, "window_%d_%d", r + 1, c + 1);
            window_frame(b, part(b, name), x0 + c * pitch, rows[r], ww, wh, -0.1, 0.02);
        }
    uint32_t door = part(b, "door");
    window_frame(b, door, W / 2 - 0.35, 0.08, 0.7, 2.1, -0.1, 0.02);
    box(b, door, W / 2 - 0.35, -0.04, 0.08, W / 2 + 0.35, -0.02, 2.18); /* leaf */
}

static void octagon(double r, double z, double (*out)[3])
{
    for (int i = 0; i < 8; i++) {
        double a = (i + 0.5) * M_PI / 4;
        out[i][0] = r * cos(a);
        out[i][1] = r * sin(a);
        out[i][2] = z;
    }
}

static void tower(builder *b)
{
    const double R = 5, storey = 3.5, slab = 0.3, col = 0.5, rc = 4.2;
    double ring[8][3];
    char name[32];
    octagon(R + 0.4, -0.5, ring);
    const double plinth[3] = {0, 0, 0.5};
    prism(b, part(b, "plinth"), (const double (*)[3])ring, 8, plinth);
    for (int s = 0; s < 3; s++) {
        double z = s * storey;
        snprintf(name, sizeof name, "slab_%d", s + 1);
        octagon(R, z, ring);
        const double up[3] = {0, 0, slab};
        prism(b, part(b, name), (const double (*)[3])ring, 8, up);
        for (int i = 0; i < 8; i++) {
            double a = i * M_PI / 4, cx = rc * cos(a), cy = rc * sin(a);
            /* Rounded to the millimetre so every column is the same shape. */
            cx = round(cx * 1000) / 1000;
            cy = round(cy * 1000) / 1000;
            snprintf(name, sizeof name, "column_%d_%d", s + 1, i + 1);
            box(b, part(b, name), cx - col / 2, cy - col / 2, z + slab, cx + col / 2,
                cy + col / 2, z + storey);
        }
    }
    octagon(1.5, 0, ring);
    const double core[3] = {0, 0, 3 * storey};
    prism(b, part(b, "core"), (const double (*)[3])ring, 8, core);
    octagon(R + 0.2, 3 * storey, ring);
    const double roof[3] = {0, 0, 0.4};
    prism(b, part(b, "roof"), (const double (*)[3])ring, 8, roof);
    /* Parapet: eight wall segments on the roof's edge. */
    octagon(R + 0.2, 3 * storey + 0.4, ring);
    for (int i = 0; i < 8; i++) {
        const double *p = ring[i], *q = ring[(i + 1) % 8];
        double ox = -0.25 * (p[0] + q[0]) / (2 * R), oy = -0.25 * (p[1] + q[1]) / (2 * R);
        const double seg[4][3] = {{p[0], p[1], p[2]},
                                  {q[0], q[1], q[2]},
                                  {q[0] + ox, q[1] + oy, q[2]},
                                  {p[0] + ox, p[1] + oy, p[2]}};
        const double up[3] = {0, 0, 1.0};
        snprintf(name, sizeof name, "parapet_%d", i + 1);
        prism(b, part(b, name), seg, 4, up);
    }
}

ag_mesh *ag_demo_building(int which)
{
    if (which < 0 || which >= AG_DEMO_BUILDING_COUNT)
        return NULL;
    builder b = {ag_mesh_create(), 0};
    if (!b.m)
        return NULL;
    if (which == 0)
        row_house(&b);
    else
        tower(&b);
    if (b.failed) {
        ag_mesh_free(b.m);
        return NULL;
    }
    return b.m;
}

const char *ag_demo_building_name(int which)
{
    static const char *const names[AG_DEMO_BUILDING_COUNT] = {"Row house", "Tower"};
    return which >= 0 && which < AG_DEMO_BUILDING_COUNT ? names[which] : NULL;
}
