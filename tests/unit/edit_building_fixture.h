/* Generated box buildings for the resize tests (test_edit_structure.c, test_edit_ids.c):
 * four walls, a roof slab, a grid of identical windows on the front and on the right facade,
 * one door on the front, with the windows and the door recessed into the wall, flush with its
 * face or proud of it (sill and frame in front of the wall, so they are not inside the wall's
 * box), optionally a roof overhang, a quarter turn of the whole building, a UTM-sized offset and
 * a jitter of every vertex. Every element is a closed solid (boxes) in a group of its own.
 *
 * The measurements work on a mesh alone (an edited model's mesh or a grammar's derivation):
 * components by group, their bounding boxes, in the building's own frame (the turn and offset
 * undone), so a test checks what an edit made without asking the edit. Header-only because every
 * test file is its own binary; include it after <cmocka.h>. */
#ifndef AG_TEST_EDIT_BUILDING_FIXTURE_H
#define AG_TEST_EDIT_BUILDING_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/edit/edit.h"
#include "core/mesh.h"
#include "core/proc/proceduralize.h"

typedef enum { BB_RECESSED = 0, BB_FLUSH = 1, BB_PROUD = 2 } bb_mount;

typedef struct {
    const char *name;
    unsigned cols, rows;  /* front grid */
    unsigned side_cols;   /* right facade grid (same rows); 0: none */
    unsigned left_cols;   /* left facade grid; 0: none */
    int mount;            /* bb_mount */
    double overhang;      /* roof overhang, metres */
    int turn;             /* quarter turns of the whole building about z */
    double dx, dy, dz;    /* offset after the turn */
    double jitter;        /* amplitude of a deterministic per-vertex jitter, metres */
    int handed;           /* windows with a handle, on the left in even columns and on the
                             right in odd ones: mirror images of each other */
} bb_options;

/* Dimensions (metres) in the building's frame: the front faces -y along x from 0 to
 * bb_length(), the right facade faces +x at x = bb_length() along y from 0 to bb_depth(). */
#define BB_PERIOD 2.4  /* window period along a facade */
#define BB_FLOOR 3.0   /* row period */
#define BB_MARGIN 1.2  /* from a corner to the first window */
#define BB_WALL 0.3    /* wall thickness */
#define BB_WIN_W 1.2   /* frame width */
#define BB_WIN_H 1.5   /* frame height */
#define BB_ROW0 3.6    /* first row's frame bottom */
#define BB_DOOR_W 1.1
#define BB_DOOR_H 2.2

static inline double bb_run(unsigned n)
{
    return 2 * BB_MARGIN + (n ? (n - 1) * BB_PERIOD + BB_WIN_W : BB_WIN_W);
}
static inline double bb_length(const bb_options *o) { return bb_run(o->cols); }
static inline double bb_depth(const bb_options *o)
{
    unsigned n = o->side_cols > o->left_cols ? o->side_cols : o->left_cols;
    return bb_run(n ? n : 2);
}
static inline double bb_height(const bb_options *o) { return BB_ROW0 + BB_FLOOR * o->rows; }

typedef struct {
    ag_mesh *m;
    const bb_options *o;
    double ox, oy; /* facade frame: world = origin + R_k(u, v) */
    int k;
    size_t comp;
    int hand; /* the next window's handle: 0 none, 1 left, 2 right */
    int fail;
} bb_gen;

/* Facade frame to the building frame (u along the facade, v into the wall from its outer
 * face, w up). */
static inline void bb_to_building(const bb_gen *g, double u, double v, double *x, double *y)
{
    switch (g->k & 3) {
    case 0: *x = g->ox + u; *y = g->oy + v; break;   /* front: outer face y = 0 */
    case 1: *x = g->ox - v; *y = g->oy + u; break;   /* right: outer face x = L */
    case 2: *x = g->ox - u; *y = g->oy - v; break;   /* back */
    default: *x = g->ox + v; *y = g->oy - u; break;  /* left: outer face x = 0 */
    }
}

/* The building frame to the world: the turn, then the offset. */
static inline void bb_to_world(const bb_options *o, double x, double y, double z, double out[3])
{
    double p[2] = {x, y};
    for (int i = 0; i < (o->turn & 3); i++) {
        double t = p[0];
        p[0] = -p[1];
        p[1] = t;
    }
    out[0] = p[0] + o->dx;
    out[1] = p[1] + o->dy;
    out[2] = z + o->dz;
}

/* The world to the building frame. */
static inline void bb_to_frame(const bb_options *o, const double w[3], double out[3])
{
    double p[2] = {w[0] - o->dx, w[1] - o->dy};
    for (int i = 0; i < (o->turn & 3); i++) {
        double t = p[0];
        p[0] = p[1];
        p[1] = -t;
    }
    out[0] = p[0];
    out[1] = p[1];
    out[2] = w[2] - o->dz;
}

static inline void bb_begin(bb_gen *g, const char *name)
{
    size_t gi;
    if (ag_mesh_add_group(g->m, name, &gi) || ag_mesh_add_component(g->m, (int32_t)gi, &g->comp))
        g->fail = 1;
}

/* A box in the facade frame (or the building frame with k = 0 and origin 0). */
static inline void bb_box(bb_gen *g, double u0, double u1, double v0, double v1, double w0,
                          double w1)
{
    uint32_t base = (uint32_t)g->m->nverts;
    for (int i = 0; i < 8; i++) {
        double x, y, p[3];
        bb_to_building(g, i & 1 ? u1 : u0, i & 2 ? v1 : v0, &x, &y);
        bb_to_world(g->o, x, y, i & 4 ? w1 : w0, p);
        if (g->o->jitter > 0) {
            /* deterministic, per vertex and axis */
            for (int a = 0; a < 3; a++) {
                uint32_t h = (uint32_t)(g->m->nverts * 2654435761u + (uint32_t)a * 40503u);
                p[a] += g->o->jitter * ((double)(h % 2001) / 1000.0 - 1.0);
            }
        }
        if (ag_mesh_add_vertex(g->m, p[0], p[1], p[2]))
            g->fail = 1;
    }
    /* outward, counter-clockwise: every facade frame is a turn of the building frame */
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12; i++)
        if (ag_mesh_add_triangle(g->m, base + f[i][0], base + f[i][1], base + f[i][2],
                                 (uint32_t)g->comp))
            g->fail = 1;
}

/* Depth ranges (v) of the frame, the glass and the sill for a mount. */
static inline void bb_depths(int mount, double fr[2], double gl[2], double si[2])
{
    switch (mount) {
    case BB_PROUD:
        fr[0] = -0.06, fr[1] = 0.10, gl[0] = 0.02, gl[1] = 0.04, si[0] = -0.12, si[1] = 0.04;
        break;
    case BB_FLUSH:
        fr[0] = 0.0, fr[1] = 0.12, gl[0] = 0.05, gl[1] = 0.07, si[0] = 0.0, si[1] = 0.06;
        break;
    default:
        fr[0] = 0.08, fr[1] = 0.22, gl[0] = 0.13, gl[1] = 0.15, si[0] = 0.04, si[1] = 0.12;
        break;
    }
}

/* A window whose frame's lower left corner is at (u, w): frame, glass set into it, sill. */
static inline void bb_window(bb_gen *g, double u, double w)
{
    double fr[2], gl[2], si[2];
    bb_depths(g->o->mount, fr, gl, si);
    bb_box(g, u, u + BB_WIN_W, fr[0], fr[1], w, w + BB_WIN_H);
    bb_box(g, u + 0.1, u + BB_WIN_W - 0.1, gl[0], gl[1], w + 0.1, w + BB_WIN_H - 0.1);
    bb_box(g, u - 0.05, u + BB_WIN_W + 0.05, si[0], si[1], w - 0.08, w);
    if (g->hand) { /* in front of the glass, off the window's centre */
        double h0 = g->hand == 1 ? u + 0.15 : u + BB_WIN_W - 0.3;
        bb_box(g, h0, h0 + 0.15, gl[0] - 0.04, gl[0], w + 0.6, w + 0.75);
    }
}

static inline void bb_door(bb_gen *g, double u)
{
    double fr[2], gl[2], si[2];
    bb_depths(g->o->mount, fr, gl, si);
    bb_box(g, u, u + BB_DOOR_W, fr[0], fr[1], 0, BB_DOOR_H);
    bb_box(g, u + 0.15, u + BB_DOOR_W - 0.15, gl[0], gl[1], 0.15, BB_DOOR_H - 0.15);
}

static inline void bb_grid(bb_gen *g, const char *side, unsigned cols, unsigned rows)
{
    for (unsigned j = 0; j < rows; j++)
        for (unsigned i = 0; i < cols; i++) {
            char name[64];
            snprintf(name, sizeof name, "window_%s_%u_%u", side, i, j);
            bb_begin(g, name);
            g->hand = g->o->handed ? 1 + (int)(i & 1) : 0;
            bb_window(g, BB_MARGIN + i * BB_PERIOD, BB_ROW0 + j * BB_FLOOR);
        }
}

/* The building as a new mesh (NULL when out of memory). */
static inline ag_mesh *bb_generate(const bb_options *o)
{
    bb_gen g = {.m = ag_mesh_create(), .o = o};
    if (!g.m)
        return NULL;
    double L = bb_length(o), D = bb_depth(o), H = bb_height(o), T = BB_WALL, oh = o->overhang;
    /* walls in the building frame: front and back run the whole length, the sides between */
    bb_begin(&g, "wall_front");
    bb_box(&g, 0, L, 0, T, 0, H);
    bb_begin(&g, "wall_back");
    bb_box(&g, 0, L, D - T, D, 0, H);
    bb_begin(&g, "wall_left");
    bb_box(&g, 0, T, T, D - T, 0, H);
    bb_begin(&g, "wall_right");
    bb_box(&g, L - T, L, T, D - T, 0, H);
    bb_begin(&g, "roof");
    bb_box(&g, -oh, L + oh, -oh, D + oh, H, H + 0.3);
    g.k = 0, g.ox = 0, g.oy = 0;
    bb_grid(&g, "front", o->cols, o->rows);
    bb_begin(&g, "door");
    bb_door(&g, 0.5 * L - 0.5 * BB_DOOR_W);
    g.k = 1, g.ox = L, g.oy = 0;
    bb_grid(&g, "right", o->side_cols, o->rows);
    g.k = 3, g.ox = 0, g.oy = D;
    bb_grid(&g, "left", o->left_cols, o->rows);
    if (g.fail) {
        ag_mesh_free(g.m);
        return NULL;
    }
    return g.m;
}

/* The buildings the id tests (test_edit_ids.c, test_edit_keep_ids.c) run on: windows recessed,
 * flush and proud, a turned building with a roof overhang, UTM coordinates, jitter. *n gets
 * their count. */
static inline const bb_options *bb_id_variants(size_t *n)
{
    static const bb_options v[] = {
        {"recessed", 6, 3, 3, 0, BB_RECESSED, 0, 0, 0, 0, 0, 0, 0},
        {"flush", 6, 3, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 0, 0},
        {"proud", 6, 3, 3, 0, BB_PROUD, 0, 0, 0, 0, 0, 0, 0},
        {"proud, overhang, turned a quarter", 6, 3, 3, 2, BB_PROUD, 0.3, 1, 0, 0, 0, 0, 0},
        {"recessed, UTM", 6, 3, 3, 0, BB_RECESSED, 0, 0, 512345.0, 5812345.0, 31.0, 0, 0},
        {"flush, jittered", 5, 2, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 2e-7, 0},
    };
    *n = sizeof v / sizeof *v;
    return v;
}

/* Buildings whose windows are mirror images of each other (handles left and right): for the
 * tests of edits that copy or turn terminals. *n gets their count. */
static inline const bb_options *bb_handed_variants(size_t *n)
{
    static const bb_options v[] = {
        {"proud, handed", 6, 3, 3, 0, BB_PROUD, 0, 0, 0, 0, 0, 0, 1},
        {"recessed, handed, turned a quarter", 4, 2, 3, 2, BB_RECESSED, 0.3, 1, 0, 0, 0, 0, 1},
        {"flush, handed, UTM", 5, 2, 3, 0, BB_FLUSH, 0, 0, 512345.0, 5812345.0, 31.0, 0, 1},
    };
    *n = sizeof v / sizeof *v;
    return v;
}

/* ---- measuring a mesh --------------------------------------------------------------------- */

/* A component's bounding box in the building frame (turn and offset undone). */
typedef struct {
    double min[3], max[3];
    int32_t group;
} bb_part;

/* Every component with triangles: its box in the building frame and its group. *n gets the
 * count; the array is malloc'd. */
static inline bb_part *bb_parts(const ag_mesh *m, const bb_options *o, size_t *n)
{
    bb_part *p = calloc(m->ncomponents + 1, sizeof *p);
    uint8_t *seen = calloc(m->ncomponents + 1, 1);
    for (size_t c = 0; c < m->ncomponents; c++)
        for (int a = 0; a < 3; a++) {
            p[c].min[a] = INFINITY;
            p[c].max[a] = -INFINITY;
        }
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t c = m->tri_component[t];
        seen[c] = 1;
        for (int k = 0; k < 3; k++) {
            double q[3];
            bb_to_frame(o, &m->pos[3 * m->tri[3 * t + k]], q);
            for (int a = 0; a < 3; a++) {
                p[c].min[a] = fmin(p[c].min[a], q[a]);
                p[c].max[a] = fmax(p[c].max[a], q[a]);
            }
        }
    }
    size_t k = 0;
    for (size_t c = 0; c < m->ncomponents; c++)
        if (seen[c]) {
            p[k] = p[c];
            p[k++].group = m->component_group[c];
        }
    free(seen);
    *n = k;
    return p;
}

/* The group of the component whose box holds the point (building frame) most tightly, -1 when
 * none does. */
static inline int32_t bb_group_at(const bb_part *p, size_t n, double x, double y, double z)
{
    int32_t g = -1;
    double best = INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (x < p[i].min[0] || x > p[i].max[0] || y < p[i].min[1] || y > p[i].max[1] ||
            z < p[i].min[2] || z > p[i].max[2])
            continue;
        double v = (p[i].max[0] - p[i].min[0]) * (p[i].max[1] - p[i].min[1]) *
                   (p[i].max[2] - p[i].min[2]);
        if (v < best) {
            best = v;
            g = p[i].group;
        }
    }
    return g;
}

static inline double bb_extent(const bb_part *p, int a) { return p->max[a] - p->min[a]; }

typedef struct {
    int64_t a[3], b[3];
    uint32_t c;
} bb_edge;

static inline int bb_cmp_edge(const void *u, const void *v)
{
    const bb_edge *x = u, *y = v;
    if (x->c != y->c)
        return x->c < y->c ? -1 : 1;
    for (int k = 0; k < 3; k++) {
        if (x->a[k] != y->a[k])
            return x->a[k] < y->a[k] ? -1 : 1;
        if (x->b[k] != y->b[k])
            return x->b[k] < y->b[k] ? -1 : 1;
    }
    return 0;
}

/* Every edge of every component's triangles (vertices welded by position on a grid of eps
 * metres) is used by exactly two triangles of that component: each element is still a set of
 * closed solids. Returns the number of edges that are not. */
static inline size_t bb_open_edges(const ag_mesh *m, double eps)
{
    size_t ne = 3 * m->ntris;
    bb_edge *e = malloc((ne + 1) * sizeof *e);
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++) {
            const double *p = &m->pos[3 * m->tri[3 * t + k]];
            const double *q = &m->pos[3 * m->tri[3 * t + (k + 1) % 3]];
            bb_edge *x = &e[3 * t + k];
            int64_t pa[3], qa[3];
            for (int a = 0; a < 3; a++) {
                pa[a] = llround(p[a] / eps);
                qa[a] = llround(q[a] / eps);
            }
            int swap = 0;
            for (int a = 0; a < 3 && !swap; a++) {
                if (pa[a] != qa[a]) {
                    swap = pa[a] > qa[a];
                    break;
                }
            }
            memcpy(x->a, swap ? qa : pa, sizeof pa);
            memcpy(x->b, swap ? pa : qa, sizeof qa);
            x->c = m->tri_component[t];
        }
    qsort(e, ne, sizeof *e, bb_cmp_edge);
    size_t bad = 0;
    for (size_t i = 0, j; i < ne; i = j) {
        for (j = i + 1; j < ne && !bb_cmp_edge(&e[i], &e[j]); j++)
            ;
        if (j - i != 2)
            bad++;
    }
    free(e);
    return bad;
}

/* The building proceduralized and read back through its grammar, as the service keeps a
 * proceduralized model (NULL when anything fails; *mesh gets the generated mesh). */
static inline ag_edit_model *bb_service_model(const bb_options *o, ag_mesh **mesh, ag_error *err)
{
    *mesh = bb_generate(o);
    ag_proceduralize_result *r = NULL;
    ag_edit_model *em = NULL;
    if (*mesh && !ag_proceduralize_run(*mesh, NULL, &r, err))
        ag_edit_model_from_grammar(r->grammar, NULL, &em, err);
    ag_proceduralize_result_free(r);
    return em;
}

#endif
