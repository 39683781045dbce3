/* Generated buildings for the parts library tests (test_parts_*.c), header-only; include it
 * after <cmocka.h>.
 *
 * A block of four wall slabs and a roof; windows on the front (facing -y before the building's
 * turn) and optionally on the right facade (facing +x). A window is a casing box holding four
 * frame bars of width `frame` (flush with the casing's faces), a glass pane between them and
 * `mullions` vertical mullions 0.05 wide: the casing is the window's node, its members are
 * its children. Every piece is its own group, so components are pieces. Windows sit
 * recessed, flush or proud of the wall's outer face. The whole building may be turned by
 * quarter turns about z and moved by a large (UTM-sized) offset, its windows jittered and its
 * boxes triangulated along the other diagonals. slots[] receives every
 * window's world box (in generation order: front row by row, then right). */
#ifndef AG_TEST_PARTS_FIXTURE_H
#define AG_TEST_PARTS_FIXTURE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh.h"
#include "core/parts/part.h"
#include "core/proc/proceduralize.h"
#include "edit_fixture.h"
#include "mesh_measure_fixture.h"

enum { PF_RECESSED = 0, PF_FLUSH = 1, PF_PROUD = 2 };

typedef struct {
    unsigned cols, rows, side_cols; /* front grid; right facade columns (0: none) */
    double ww, wh, frame;           /* window width, height, frame bar width */
    unsigned mullions;
    int depth;                      /* PF_RECESSED / PF_FLUSH / PF_PROUD */
    int turn;                       /* quarter turns of the whole building about z */
    double ox, oy;                  /* offset */
    double sx, sz;                  /* window spacing */
    int balcony;                    /* a balcony in front of the front wall */
    double jitter;                  /* windows moved by up to this much (deterministic) */
    int flip;                       /* boxes triangulated along their other diagonals */
} pf_options;

typedef struct {
    ag_mesh *m;
    int turn;
    double ox, oy;
    unsigned piece;
    int flip;
    uint32_t seed;
    /* facade frame */
    double fx, fy;
    int fk;
} pf_gen;

static inline void pf_to_world(const pf_gen *g, double u, double v, double *x, double *y)
{
    double a, b; /* building frame */
    switch (g->fk & 3) {
    case 0: a = g->fx + u; b = g->fy + v; break;
    case 1: a = g->fx - v; b = g->fy + u; break;
    case 2: a = g->fx - u; b = g->fy - v; break;
    default: a = g->fx + v; b = g->fy - u; break;
    }
    double c, d;
    switch (g->turn & 3) {
    case 0: c = a; d = b; break;
    case 1: c = -b; d = a; break;
    case 2: c = -a; d = -b; break;
    default: c = b; d = -a; break;
    }
    *x = g->ox + c;
    *y = g->oy + d;
}

/* A box in the facade frame as its own group/component; returns its world box. */
static inline ag_box pf_box(pf_gen *g, const char *what, double u0, double u1, double v0, double v1,
                            double w0, double w1)
{
    char name[64];
    snprintf(name, sizeof name, "%s_%u", what, g->piece++);
    size_t gi, comp;
    ag_mesh_add_group(g->m, name, &gi);
    ag_mesh_add_component(g->m, (int32_t)gi, &comp);
    uint32_t base = (uint32_t)g->m->nverts;
    ag_box b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (int i = 0; i < 8; i++) {
        double x, y, z = i & 4 ? w1 : w0;
        pf_to_world(g, i & 1 ? u1 : u0, i & 2 ? v1 : v0, &x, &y);
        ag_mesh_add_vertex(g->m, x, y, z);
        double p[3] = {x, y, z};
        for (int a = 0; a < 3; a++) {
            b.min[a] = fmin(b.min[a], p[a]);
            b.max[a] = fmax(b.max[a], p[a]);
        }
    }
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    /* the same quads split along the other diagonal */
    static const int h[12][3] = {{0, 3, 1}, {0, 2, 3}, {4, 5, 7}, {4, 7, 6}, {0, 5, 4}, {0, 1, 5},
                                 {2, 7, 3}, {2, 6, 7}, {0, 6, 2}, {0, 4, 6}, {1, 7, 5}, {1, 3, 7}};
    for (int i = 0; i < 12; i++) {
        const int *q = g->flip ? h[i] : f[i];
        ag_mesh_add_triangle(g->m, base + q[0], base + q[1], base + q[2], (uint32_t)comp);
    }
    return b;
}

/* Deterministic offsets in [-1, 1]. */
static inline double pf_rand(pf_gen *g)
{
    g->seed = g->seed * 1664525u + 1013904223u;
    return (double)(g->seed >> 8) / (double)(1u << 23) - 1.0;
}

static inline ag_box pf_window(pf_gen *g, const pf_options *o, double u, double w)
{
    u += o->jitter * pf_rand(g);
    w += o->jitter * pf_rand(g);
    double v0 = o->depth == PF_RECESSED ? 0.1 : o->depth == PF_FLUSH ? 0.0 : -0.08;
    double v1 = v0 + 0.16, W = o->ww, H = o->wh, fr = o->frame;
    ag_box slot = pf_box(g, "casing", u, u + W, v0, v1, w, w + H);
    pf_box(g, "bar", u, u + W, v0, v1, w, w + fr);
    pf_box(g, "bar", u, u + W, v0, v1, w + H - fr, w + H);
    pf_box(g, "bar", u, u + fr, v0, v1, w + fr, w + H - fr);
    pf_box(g, "bar", u + W - fr, u + W, v0, v1, w + fr, w + H - fr);
    pf_box(g, "glass", u + fr, u + W - fr, v0 + 0.07, v0 + 0.08, w + fr, w + H - fr);
    for (unsigned k = 0; k < o->mullions; k++) {
        double c = u + fr + (W - 2 * fr) * (k + 1) / (o->mullions + 1);
        pf_box(g, "mullion", c - 0.025, c + 0.025, v0 + 0.03, v0 + 0.13, w + fr, w + H - fr);
    }
    return slot;
}

/* The building; *slots (malloc'd, may be NULL) gets the window boxes, *nslots their count. */
static inline ag_mesh *pf_building(const pf_options *o, ag_box **slots, size_t *nslots)
{
    pf_gen g = {.m = ag_mesh_create(), .turn = o->turn, .ox = o->ox, .oy = o->oy,
                .flip = o->flip, .seed = 12345};
    double sx = o->sx > 0 ? o->sx : o->ww + 1.0, sz = o->sz > 0 ? o->sz : o->wh + 1.2;
    double Wd = 2 * 0.9 + (o->cols - 1) * sx + o->ww;
    unsigned sc = o->side_cols ? o->side_cols : 2;
    double Dp = 2 * 0.9 + (sc - 1) * sx + o->ww;
    double Ht = 1.0 + o->rows * sz;
    size_t cap = (size_t)o->cols * o->rows + (size_t)o->side_cols * o->rows + 1, n = 0;
    ag_box *s = malloc(cap * sizeof *s);
    g.fk = 0, g.fx = 0, g.fy = 0;
    pf_box(&g, "wall_front", 0, Wd, 0, 0.3, 0, Ht);
    for (unsigned j = 0; j < o->rows; j++)
        for (unsigned i = 0; i < o->cols; i++)
            s[n++] = pf_window(&g, o, 0.9 + i * sx, 1.0 + j * sz);
    if (o->balcony) {
        /* the balcony's volume holds its slab, its front rail and five posts */
        double u = 0.9, L = 3.0, d = 1.0, h = 1.1;
        pf_box(&g, "balcony", u, u + L, -d, 0, 1.0, 1.0 + h);
        pf_box(&g, "slab", u, u + L, -d, 0, 1.0, 1.15);
        pf_box(&g, "rail", u, u + L, -d, -d + 0.05, 1.0 + h - 0.05, 1.0 + h);
        for (int k = 0; k < 5; k++)
            pf_box(&g, "post", u + 0.1 + k * 0.7, u + 0.15 + k * 0.7, -d, -d + 0.05, 1.15,
                   1.0 + h - 0.05);
    }
    g.fk = 1, g.fx = Wd, g.fy = 0;
    pf_box(&g, "wall_right", 0, Dp, 0, 0.3, 0, Ht);
    for (unsigned j = 0; j < o->rows; j++)
        for (unsigned i = 0; i < o->side_cols; i++)
            s[n++] = pf_window(&g, o, 0.9 + i * sx, 1.0 + j * sz);
    g.fk = 2, g.fx = Wd, g.fy = Dp;
    pf_box(&g, "wall_back", 0, Wd, 0, 0.3, 0, Ht);
    g.fk = 3, g.fx = 0, g.fy = Dp;
    pf_box(&g, "wall_left", 0, Dp, 0, 0.3, 0, Ht);
    g.fk = 0, g.fx = 0, g.fy = 0;
    pf_box(&g, "roof", -0.2, Wd + 0.2, -0.2, Dp + 0.2, Ht, Ht + 0.3);
    if (slots)
        *slots = s;
    else
        free(s);
    if (nslots)
        *nslots = n;
    return g.m;
}

/* Proceduralized as the edit pipeline does (edit_fixture.h): checked to derive back exactly. */
static inline ag_proceduralize_result *pf_proc(const ag_mesh *m) { return proc(m); }

/* The visible node whose box is b (within tol); -1 when none. */
static inline int32_t pf_node_with_box(const ag_proceduralize_result *r, const ag_box *b,
                                       double tol)
{
    const ag_splittree *t = r->tree;
    for (size_t i = 0; i < t->nnodes; i++) {
        if (t->nodes[i].kind != AG_NODE_COMPONENT)
            continue;
        int ok = 1;
        for (int a = 0; a < 3; a++)
            ok &= fabs(t->nodes[i].box.min[a] - b->min[a]) <= tol &&
                  fabs(t->nodes[i].box.max[a] - b->max[a]) <= tol;
        if (ok)
            return (int32_t)i;
    }
    return -1;
}

/* Per component of m: its box (malloc'd). */
static inline ag_box *pf_component_boxes(const ag_mesh *m)
{
    ag_box *b = malloc((m->ncomponents + 1) * sizeof *b);
    for (size_t c = 0; c < m->ncomponents; c++)
        b[c] = (ag_box){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t c = m->tri_component[t];
        for (int k = 0; k < 3; k++) {
            const double *p = m->pos + 3 * m->tri[3 * t + k];
            for (int a = 0; a < 3; a++) {
                b[c].min[a] = fmin(b[c].min[a], p[a]);
                b[c].max[a] = fmax(b[c].max[a], p[a]);
            }
        }
    }
    return b;
}

static inline int pf_inside(const ag_box *in, const ag_box *out, double tol)
{
    for (int a = 0; a < 3; a++)
        if (in->min[a] < out->min[a] - tol || in->max[a] > out->max[a] + tol)
            return 0;
    return 1;
}

static inline int pf_same_box(const ag_box *x, const ag_box *y, double tol)
{
    return pf_inside(x, y, tol) && pf_inside(y, x, tol);
}

/* The window `which` of building o saved as a part ("sash window" from "A"); *slot (may be
 * NULL) gets the window's slot. */
static inline ag_part *pf_window_part(const pf_options *o, int which, ag_box *slot)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(o, &slots, &ns);
    ag_proceduralize_result *r = pf_proc(m);
    int32_t node = pf_node_with_box(r, &slots[which], 1e-6);
    assert_true(node > 0);
    ag_part_meta meta = {.name = "sash window", .source = "A"};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(r, node, &meta, &p, &err))
        fail_msg("extract: %s", err.text);
    if (slot)
        *slot = slots[which];
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return p;
}

/* Window design A (the part): 1.2 x 1.8, frame 0.08, one mullion. Design B (the target's):
 * 1.6 x 2.0, frame 0.12, two mullions. */
static inline pf_options pf_design_a(int depth, int turn, double ox, double oy)
{
    return (pf_options){.cols = 3, .rows = 2, .ww = 1.2, .wh = 1.8, .frame = 0.08, .mullions = 1,
                        .depth = depth, .turn = turn, .ox = ox, .oy = oy};
}

static inline pf_options pf_design_b(int depth, int turn, double ox, double oy)
{
    return (pf_options){.cols = 4, .rows = 3, .side_cols = 2, .ww = 1.6, .wh = 2.0,
                        .frame = 0.12, .mullions = 2, .depth = depth, .turn = turn, .ox = ox,
                        .oy = oy};
}

/* The welded vertex set of the triangles' corners: positions rounded to 1e-5 m (relative to
 * origin), sorted, duplicates dropped. */
static inline mm_cell *pf_welded(const ag_mesh *m, const double origin[3], size_t *n)
{
    return mm_welded(m, origin, 1e-5, n);
}

static inline void pf_same_welded(const ag_mesh *a, const ag_mesh *b, const char *what)
{
    ag_box bb = ag_mesh_bounds(b);
    size_t na, nb;
    mm_cell *pa = pf_welded(a, bb.min, &na), *pb = pf_welded(b, bb.min, &nb);
    if (na != nb)
        fail_msg("%s: %zu welded vertices, the other %zu", what, na, nb);
    for (size_t i = 0; i < na; i++)
        if (mm_cmp_cell(&pa[i], &pb[i]))
            fail_msg("%s: welded vertex %zu differs", what, i);
    free(pa);
    free(pb);
}

static inline char *pf_print(const ag_grammar *g)
{
    char *text = NULL;
    size_t len = 0;
    ag_error err = {0};
    if (ag_grammar_text_print(g, &text, &len, &err))
        fail_msg("print: %s", err.text);
    return text;
}

/* fmt round trip: prints, parses and prints back to the same bytes. */
static inline void pf_check_roundtrip(const ag_grammar *g)
{
    char *a = pf_print(g);
    ag_grammar *back = NULL;
    ag_error err = {0};
    long col = 0;
    if (ag_grammar_text_parse(a, strlen(a), &back, &err, &col))
        fail_msg("the grammar does not parse: %ld:%ld: %s\n%s", err.element, col, err.text, a);
    char *b = pf_print(back);
    assert_string_equal(a, b);
    free(a);
    free(b);
    ag_grammar_free(back);
}

#endif
