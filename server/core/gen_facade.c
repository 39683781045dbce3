#include "gen_facade.h"

#include <stdio.h>
#include <stdlib.h>

typedef struct {
    ag_mesh *m;
    ag_status st;
    int no_groups;
    size_t comp;
    /* facade frame: world = origin + R_k(u, v) , z = w */
    double ox, oy;
    int k;
} gen;

static void to_world(const gen *g, double u, double v, double *x, double *y)
{
    switch (g->k & 3) {
    case 0: *x = g->ox + u; *y = g->oy + v; break;
    case 1: *x = g->ox - v; *y = g->oy + u; break;
    case 2: *x = g->ox - u; *y = g->oy - v; break;
    default: *x = g->ox + v; *y = g->oy - u; break;
    }
}

static void begin(gen *g, const char *name)
{
    if (g->st)
        return;
    size_t gi = 0;
    if (!g->no_groups)
        g->st = ag_mesh_add_group(g->m, name, &gi);
    if (!g->st)
        g->st = ag_mesh_add_component(g->m, g->no_groups ? -1 : (int32_t)gi, &g->comp);
}

/* Axis-aligned box in the facade frame: u0..u1 along, v0..v1 depth, w0..w1 up. */
static void box(gen *g, double u0, double u1, double v0, double v1, double w0, double w1)
{
    if (g->st)
        return;
    if (g->no_groups && (g->st = ag_mesh_add_component(g->m, -1, &g->comp)))
        return;
    uint32_t base = (uint32_t)g->m->nverts;
    for (int i = 0; i < 8; i++) {
        double x, y;
        to_world(g, i & 1 ? u1 : u0, i & 2 ? v1 : v0, &x, &y);
        if ((g->st = ag_mesh_add_vertex(g->m, x, y, i & 4 ? w1 : w0)))
            return;
    }
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12 && !g->st; i++)
        g->st = ag_mesh_add_triangle(g->m, base + f[i][0], base + f[i][1], base + f[i][2],
                                     (uint32_t)g->comp);
}

static void window(gen *g, double u, double w, unsigned bars)
{
    const double W = 1.2, H = 1.8, fr = 0.08;
    box(g, u, u + W, 0.05, 0.2, w, w + fr);                   /* bottom frame */
    box(g, u, u + W, 0.05, 0.2, w + H - fr, w + H);           /* top frame */
    box(g, u, u + fr, 0.05, 0.2, w + fr, w + H - fr);         /* left frame */
    box(g, u + W - fr, u + W, 0.05, 0.2, w + fr, w + H - fr); /* right frame */
    box(g, u + 0.4, u + 0.45, 0.1, 0.18, w + fr, w + H - fr); /* off-centre mullion */
    box(g, u + fr, u + W - fr, 0.15, 0.16, w + fr, w + H - fr); /* glass, set back */
    box(g, u - 0.05, u + W + 0.05, 0.0, 0.1, w - 0.06, w);    /* sill */
    for (unsigned b = 0; b < bars; b++) {
        double z = w + fr + (H - 2 * fr) * (b + 1) / (bars + 1);
        box(g, u + fr, u + W - fr, 0.12, 0.14, z - 0.01, z + 0.01);
    }
}

size_t ag_gen_facade_window_triangles(const ag_gen_facade_options *opt)
{
    return 12u * (7 + (opt ? opt->bars : 0));
}

static void facade(gen *g, const char *side, unsigned cols, unsigned rows, double len,
                   double height, double sx, double sz, unsigned bars)
{
    char name[64];
    snprintf(name, sizeof name, "wall_%s", side);
    begin(g, name);
    box(g, 0, len, 0, 0.3, 0, height);
    for (unsigned j = 0; j < rows; j++)
        for (unsigned i = 0; i < cols; i++) {
            snprintf(name, sizeof name, "window_%s_%u_%u", side, i, j);
            begin(g, name);
            window(g, 0.8 + i * sx, 0.9 + j * sz, bars);
        }
}

ag_status ag_gen_facade(const ag_gen_facade_options *opt, ag_mesh **out, ag_error *err)
{
    ag_gen_facade_options o = opt ? *opt : (ag_gen_facade_options){0};
    if (!o.cols || !o.rows) {
        o.cols = 6;
        o.rows = 4;
    }
    if (o.step_x <= 0)
        o.step_x = 2.5;
    if (o.step_z <= 0)
        o.step_z = 3.2;
    *out = NULL;
    gen g = {.m = ag_mesh_create(), .no_groups = o.no_groups};
    if (!g.m)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    double W = 0.8 * 2 + (o.cols - 1) * o.step_x + 1.2;
    unsigned sc = o.side_cols ? o.side_cols : 2;
    double D = 0.8 * 2 + (sc - 1) * o.step_x + 1.2;
    double H = 0.9 + o.rows * o.step_z;
    unsigned bars = o.bars;
    g.k = 0, g.ox = 0, g.oy = 0;
    facade(&g, "front", o.cols, o.rows, W, H, o.step_x, o.step_z, bars);
    g.k = 1, g.ox = W, g.oy = 0;
    facade(&g, "right", o.side_cols, o.rows, D, H, o.step_x, o.step_z, bars);
    g.k = 2, g.ox = W, g.oy = D;
    facade(&g, "back", o.back ? o.cols : 0, o.rows, W, H, o.step_x, o.step_z, bars);
    g.k = 3, g.ox = 0, g.oy = D;
    facade(&g, "left", o.left ? o.side_cols : 0, o.rows, D, H, o.step_x, o.step_z, bars);
    g.k = 0, g.ox = 0, g.oy = 0;
    begin(&g, "roof");
    box(&g, -0.2, W + 0.2, -0.2, D + 0.2, H, H + 0.35);
    if (o.annex) {
        begin(&g, "annex");
        box(&g, 1.0, 4.7, D, D + 2.9, 0, 2.6);
        box(&g, 1.9, 2.3, D + 0.6, D + 1.0, 2.6, 3.9); /* chimney */
    }
    if (g.st) {
        ag_mesh_free(g.m);
        return ag_error_set(err, g.st, 0, "could not generate the building");
    }
    *out = g.m;
    return AG_OK;
}
