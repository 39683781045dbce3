/* Labels that do not depend on triangulation.
 *
 * A generator builds one window shape (an asymmetric, non-convex outline extruded into the
 * facade) many times: triangulated by ear clipping from every start vertex, by a fan from an
 * inner point, with its side quads cut along either diagonal or into four, with its triangle
 * list and each triangle's vertices in other orders, turned by 90 degrees onto a side facade
 * and re-triangulated, mirrored, and moved by up to a millimetre per vertex; and windows 1 to
 * 3 cm larger; each window has a sill in front. Every variant of the building is also turned about the up axis and moved to
 * UTM-sized coordinates. The test knows which component is which window and checks the
 * labels against that, and checks the derivation by its own point sampling (not the
 * proceduralizer's fidelity). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/proc/label.h"
#include "core/proc/proceduralize.h"

/* the outline in (u along the facade, v up), counter-clockwise; not symmetric, not convex */
static const double OUTLINE[][2] = {{0, 0},     {0.9, 0},    {0.9, 1.1}, {0.6, 1.1},
                                    {0.6, 1.4}, {0.15, 1.5}, {0, 1.2}};
#define NO (sizeof OUTLINE / sizeof OUTLINE[0])
#define DEPTH 0.25

typedef struct {
    double width_extra, height_extra; /* metres */
    int mirror;                       /* u -> width - u */
    int cap;          /* 0..NO-1: ear clipping from that vertex; NO: fan from an inner point */
    int side;         /* side quads: 0 one diagonal, 1 the other, 2 four triangles */
    int shuffle;      /* triangles in another order, each one's vertices shifted */
    double jitter;    /* metres, per vertex position */
    double turn;      /* radians about z: 0 front facade, pi/2 side facade */
    double at[3];     /* where the window's origin goes (before the building's transform) */
} window_spec;

typedef struct {
    double R[2][2], t[3]; /* the building's turn about z and offset */
} building_xf;

static double jitter_of(const double p[3], int axis, double amount)
{
    /* a function of the position, so a vertex repeated by several faces moves once */
    uint64_t h = 1469598103934665603ULL;
    for (int a = 0; a < 3; a++) {
        int64_t q = (int64_t)llround(p[a] * 1e6);
        h = (h ^ (uint64_t)q) * 1099511628211ULL;
    }
    h = (h ^ (uint64_t)axis) * 1099511628211ULL;
    h ^= h >> 29;
    return amount * ((double)(h % 20001) / 10000.0 - 1.0);
}

typedef struct {
    double *tri; /* 9 per triangle, world */
    size_t n, cap;
} soup;

static void soup_add(soup *s, const double a[3], const double b[3], const double c[3])
{
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 64;
        s->tri = realloc(s->tri, 9 * s->cap * sizeof *s->tri);
        assert_non_null(s->tri);
    }
    memcpy(s->tri + 9 * s->n, a, 3 * sizeof(double));
    memcpy(s->tri + 9 * s->n + 3, b, 3 * sizeof(double));
    memcpy(s->tri + 9 * s->n + 6, c, 3 * sizeof(double));
    s->n++;
}

/* (u, v, depth) of the window to its place before the building's transform. */
static void local_to_site(const window_spec *w, double u, double v, double d, double out[3])
{
    double x = u, y = d;
    double c = cos(w->turn), s = sin(w->turn);
    out[0] = w->at[0] + c * x - s * y;
    out[1] = w->at[1] + s * x + c * y;
    out[2] = w->at[2] + v;
}

/* Adds triangle (a, b, c) of the window's local frame so that its normal points along
 * `out` (local). */
static void add_oriented(soup *s, const window_spec *w, const double a[3], const double b[3],
                         const double c[3], const double out[3])
{
    double u[3], v[3], n[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    int flip = n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0;
    const double *p[3] = {a, flip ? c : b, flip ? b : c};
    double q[3][3];
    for (int k = 0; k < 3; k++)
        local_to_site(w, p[k][0], p[k][2], p[k][1], q[k]);
    soup_add(s, q[0], q[1], q[2]);
}

static double cross2(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

static int in_triangle(const double *p, const double *a, const double *b, const double *c)
{
    return cross2(a, b, p) > 0 && cross2(b, c, p) > 0 && cross2(c, a, p) > 0;
}

/* Ear clipping of the counter-clockwise polygon P (n points) from vertex `start`: the
 * triangles as index triples into P. Returns their count (n - 2). */
static size_t ear_clip(const double (*P)[2], size_t n, size_t start, size_t (*out)[3])
{
    size_t idx[16], m = n, k = 0;
    for (size_t i = 0; i < n; i++)
        idx[i] = (start + i) % n;
    size_t i = 0, guard = 0;
    while (m > 3 && guard++ < 1000) {
        size_t a = idx[(i + m - 1) % m], b = idx[i % m], c = idx[(i + 1) % m];
        int ear = cross2(P[a], P[b], P[c]) > 0;
        for (size_t j = 0; ear && j < m; j++) {
            size_t q = idx[j];
            if (q != a && q != b && q != c && in_triangle(P[q], P[a], P[b], P[c]))
                ear = 0;
        }
        if (ear) {
            out[k][0] = a;
            out[k][1] = b;
            out[k][2] = c;
            k++;
            memmove(idx + i % m, idx + i % m + 1, (m - i % m - 1) * sizeof *idx);
            m--;
        } else {
            i++;
        }
    }
    assert_int_equal(m, 3);
    out[k][0] = idx[0];
    out[k][1] = idx[1];
    out[k][2] = idx[2];
    return k + 1;
}

/* The window's triangles (site coordinates) into s. */
static void window(soup *s, const window_spec *w)
{
    double P[NO][2];
    double W = 0.9 + w->width_extra, H = 1.5 + w->height_extra;
    for (size_t i = 0; i < NO; i++) {
        size_t j = w->mirror ? (NO - i) % NO : i; /* mirrored: reversed, still CCW */
        double u = OUTLINE[j][0] * W / 0.9, v = OUTLINE[j][1] * H / 1.5;
        P[i][0] = w->mirror ? W - u : u;
        P[i][1] = v;
    }
    soup local = {0};
    double front[3] = {0, -1, 0}, back[3] = {0, 1, 0};
    /* caps: local (u, depth, v) */
    for (int side = 0; side < 2; side++) {
        double d = side ? DEPTH : 0;
        const double *dir = side ? back : front;
        if (w->cap < (int)NO) {
            size_t T[NO][3];
            size_t nt = ear_clip((const double(*)[2])P, NO, (size_t)w->cap, T);
            for (size_t t = 0; t < nt; t++) {
                double a[3] = {P[T[t][0]][0], d, P[T[t][0]][1]};
                double b[3] = {P[T[t][1]][0], d, P[T[t][1]][1]};
                double c[3] = {P[T[t][2]][0], d, P[T[t][2]][1]};
                add_oriented(&local, w, a, b, c, dir);
            }
        } else {
            /* a fan from an inner point the whole outline is visible from */
            double o[2] = {0.45 * W / 0.9, 0.6 * H / 1.5};
            for (size_t i = 0; i < NO; i++) {
                size_t j = (i + 1) % NO;
                assert_true(cross2(o, P[i], P[j]) > 0);
                double a[3] = {o[0], d, o[1]}, b[3] = {P[i][0], d, P[i][1]},
                       c[3] = {P[j][0], d, P[j][1]};
                add_oriented(&local, w, a, b, c, dir);
            }
        }
    }
    /* sides: one quad per outline edge */
    for (size_t i = 0; i < NO; i++) {
        size_t j = (i + 1) % NO;
        double out[3] = {P[j][1] - P[i][1], 0, -(P[j][0] - P[i][0])};
        double a[3] = {P[i][0], 0, P[i][1]}, b[3] = {P[j][0], 0, P[j][1]};
        double c[3] = {P[j][0], DEPTH, P[j][1]}, e[3] = {P[i][0], DEPTH, P[i][1]};
        if (w->side == 0) {
            add_oriented(&local, w, a, b, c, out);
            add_oriented(&local, w, a, c, e, out);
        } else if (w->side == 1) {
            add_oriented(&local, w, a, b, e, out);
            add_oriented(&local, w, b, c, e, out);
        } else {
            double m[3];
            for (int k = 0; k < 3; k++)
                m[k] = (a[k] + b[k] + c[k] + e[k]) / 4;
            add_oriented(&local, w, a, b, m, out);
            add_oriented(&local, w, b, c, m, out);
            add_oriented(&local, w, c, e, m, out);
            add_oriented(&local, w, e, a, m, out);
        }
    }
    /* a sill in front (the window is not the same seen from behind, so its mirror image
     * is not a turned copy) */
    {
        double lo[3] = {-0.05, -0.08, -0.05}, hi[3] = {W + 0.05, 0, 0};
        for (int a = 0; a < 3; a++)
            for (int sgn = 0; sgn < 2; sgn++) {
                int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
                double dir[3] = {0, 0, 0};
                dir[a] = sgn ? 1 : -1;
                double q[4][3];
                for (int k = 0; k < 4; k++) {
                    q[k][a] = sgn ? hi[a] : lo[a];
                    q[k][b1] = (k == 1 || k == 2) ? hi[b1] : lo[b1];
                    q[k][b2] = k >= 2 ? hi[b2] : lo[b2];
                }
                add_oriented(&local, w, q[0], q[1], q[2], dir);
                add_oriented(&local, w, q[0], q[2], q[3], dir);
            }
    }
    /* the triangle list reversed and each triangle's vertices shifted */
    for (size_t t0 = 0; t0 < local.n; t0++) {
        size_t t = w->shuffle ? local.n - 1 - t0 : t0;
        const double *p = local.tri + 9 * t;
        int sh = w->shuffle ? (int)(t % 3) : 0;
        double q[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                q[k][a] = p[3 * ((k + sh) % 3) + a] + jitter_of(p + 3 * ((k + sh) % 3), a, w->jitter);
        soup_add(s, q[0], q[1], q[2]);
    }
    free(local.tri);
}

enum { SAME, MIRRORED, WIDER1, WIDER2, WIDER3, TALLER2, NKINDS };

typedef struct {
    ag_mesh *m;
    int kind[128]; /* per component */
    size_t n;
} site;

static void add_window(site *S, const building_xf *X, const window_spec *w, int kind)
{
    soup s = {0};
    window(&s, w);
    char name[32];
    snprintf(name, sizeof name, "Window_%zu", S->n);
    size_t g, c;
    assert_int_equal(ag_mesh_add_group(S->m, name, &g), AG_OK);
    assert_int_equal(ag_mesh_add_component(S->m, (int32_t)g, &c), AG_OK);
    for (size_t t = 0; t < s.n; t++) {
        uint32_t v0 = (uint32_t)S->m->nverts;
        for (int k = 0; k < 3; k++) {
            const double *p = s.tri + 9 * t + 3 * k;
            double x = X->R[0][0] * p[0] + X->R[0][1] * p[1] + X->t[0];
            double y = X->R[1][0] * p[0] + X->R[1][1] * p[1] + X->t[1];
            assert_int_equal(ag_mesh_add_vertex(S->m, x, y, p[2] + X->t[2]), AG_OK);
        }
        assert_int_equal(ag_mesh_add_triangle(S->m, v0, v0 + 1, v0 + 2, (uint32_t)c), AG_OK);
    }
    free(s.tri);
    S->kind[c] = kind;
    S->n++;
}

/* A front facade of windows along x (each triangulated otherwise), a side facade of turned
 * copies along y, mirrored and jittered copies, and larger windows. */
static void make_site(site *S, double building_turn, const double offset[3])
{
    memset(S, 0, sizeof *S);
    S->m = ag_mesh_create();
    assert_non_null(S->m);
    building_xf X = {{{cos(building_turn), -sin(building_turn)},
                      {sin(building_turn), cos(building_turn)}},
                     {offset[0], offset[1], offset[2]}};
    double x = 0;
    /* every ear-clipping start and the fan, each with each way of cutting the sides */
    for (int cap = 0; cap <= (int)NO; cap++) {
        window_spec w = {.cap = cap, .side = cap % 3, .shuffle = cap & 1, .at = {x, 0, 1}};
        add_window(S, &X, &w, SAME);
        x += 2;
    }
    /* turned by 90 degrees onto the side facade, re-triangulated */
    for (int k = 0; k < 4; k++) {
        window_spec w = {.cap = (3 * k + 1) % (int)(NO + 1), .side = (k + 1) % 3,
                         .shuffle = !(k & 1), .turn = M_PI / 2, .at = {x + 2, 2.0 * k, 1}};
        add_window(S, &X, &w, SAME);
    }
    /* hand-modelled: every vertex up to a millimetre off */
    for (int k = 0; k < 2; k++) {
        window_spec w = {.cap = k + 2, .side = k, .jitter = 0.001, .at = {x, 0, 4}};
        add_window(S, &X, &w, SAME);
        x -= 2;
    }
    for (int k = 0; k < 2; k++) {
        window_spec w = {.cap = k, .side = 2 - k, .mirror = 1, .at = {x, 0, 4}};
        add_window(S, &X, &w, MIRRORED);
        x -= 2;
    }
    window_spec d = {.at = {x, 0, 4}};
    d.width_extra = 0.01;
    add_window(S, &X, &d, WIDER1);
    d.width_extra = 0.02;
    d.at[0] -= 2;
    add_window(S, &X, &d, WIDER2);
    d.width_extra = 0.03;
    d.at[0] -= 2;
    add_window(S, &X, &d, WIDER3);
    d.width_extra = 0;
    d.height_extra = 0.02;
    d.at[0] -= 2;
    add_window(S, &X, &d, TALLER2);
}

/* ---- an independent check of a derivation: sampled points, brute-force distances ---- */

static double point_segment(const double *p, const double *a, const double *b)
{
    double ab[3], ap[3], l = 0, t = 0;
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ap[k] = p[k] - a[k];
        l += ab[k] * ab[k];
        t += ab[k] * ap[k];
    }
    t = l > 0 ? fmin(1, fmax(0, t / l)) : 0;
    double d = 0;
    for (int k = 0; k < 3; k++)
        d += (ap[k] - t * ab[k]) * (ap[k] - t * ab[k]);
    return sqrt(d);
}

/* distance from p to triangle abc: the plane where p projects inside, else the edges */
static double point_triangle(const double *p, const double *a, const double *b, const double *c)
{
    double u[3], v[3], n[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = p[k] - a[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    if (nn > 0) {
        double uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2], vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        double uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        double wu = w[0] * u[0] + w[1] * u[1] + w[2] * u[2], wv = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
        double den = uu * vv - uv * uv;
        double s = (vv * wu - uv * wv) / den, t = (uu * wv - uv * wu) / den;
        if (s >= 0 && t >= 0 && s + t <= 1)
            return fabs(w[0] * n[0] + w[1] * n[1] + w[2] * n[2]) / sqrt(nn);
    }
    return fmin(point_segment(p, a, b), fmin(point_segment(p, b, c), point_segment(p, c, a)));
}

/* The largest distance from sampled points of mesh a (corners, edge midpoints, centroid and
 * a few inner points of each triangle) to mesh b. */
static double sampled_distance(const ag_mesh *a, const ag_mesh *b)
{
    static const double W[][3] = {{1, 0, 0},       {0, 1, 0},       {0, 0, 1},
                                  {.5, .5, 0},     {0, .5, .5},     {.5, 0, .5},
                                  {1. / 3, 1. / 3, 1. / 3}, {.7, .2, .1}, {.1, .7, .2},
                                  {.2, .1, .7}};
    double worst = 0;
    for (size_t t = 0; t < a->ntris; t++) {
        const double *p0 = a->pos + 3 * a->tri[3 * t], *p1 = a->pos + 3 * a->tri[3 * t + 1],
                     *p2 = a->pos + 3 * a->tri[3 * t + 2];
        for (size_t s = 0; s < sizeof W / sizeof W[0]; s++) {
            double p[3];
            for (int k = 0; k < 3; k++)
                p[k] = W[s][0] * p0[k] + W[s][1] * p1[k] + W[s][2] * p2[k];
            double best = INFINITY;
            for (size_t q = 0; q < b->ntris && best > 0; q++)
                best = fmin(best, point_triangle(p, b->pos + 3 * b->tri[3 * q],
                                                 b->pos + 3 * b->tri[3 * q + 1],
                                                 b->pos + 3 * b->tri[3 * q + 2]));
            worst = fmax(worst, best);
        }
    }
    return worst;
}

static void check_site(double turn, const double offset[3])
{
    site S;
    make_site(&S, turn, offset);
    ag_labels *L;
    assert_int_equal(ag_label_components(S.m, NULL, &L, NULL), AG_OK);
    int32_t first[NKINDS];
    uint32_t first_c[NKINDS];
    for (int k = 0; k < NKINDS; k++)
        first[k] = -1;
    for (size_t c = 0; c < S.m->ncomponents; c++) {
        int k = S.kind[c] == MIRRORED ? SAME : S.kind[c];
        if (first[k] < 0) {
            first[k] = L->label[c];
            first_c[k] = (uint32_t)c;
        }
        if (L->label[c] != first[k])
            fail_msg("turn %g offset %g: window %zu (kind %d) has label %d, its copies %d", turn,
                     offset[0], c, S.kind[c], L->label[c], first[k]);
        /* a mirror image is a variant of the same label, marked as mirrored */
        if (k == SAME && (S.kind[c] == MIRRORED) != (L->mirror[c] != L->mirror[first_c[SAME]]))
            fail_msg("window %zu: mirror %d, kind %d", c, L->mirror[c], S.kind[c]);
    }
    /* windows 1-3 cm larger are labels of their own */
    for (int a = SAME; a < NKINDS; a++)
        for (int b = a + 1; b < NKINDS; b++)
            if (a != MIRRORED && b != MIRRORED && first[a] == first[b])
                fail_msg("turn %g: kinds %d and %d share label %d", turn, a, b, first[a]);
    assert_true(L->tol > 0.001 && L->tol <= 0.005);
    ag_labels_free(L);

    /* derivation: shared terminals move no point by more than the fidelity says (and never
     * more than a centimetre); --exact gives the input back */
    for (int exact = 0; exact < 2; exact++) {
        ag_proceduralize_options o = {.verify = 1};
        o.label.exact_copies = exact;
        ag_proceduralize_result *r;
        ag_error err = {0};
        if (ag_proceduralize_run(S.m, &o, &r, &err))
            fail_msg("proceduralize: %s", err.text);
        assert_int_equal(r->fidelity.unmatched, 0);
        ag_mesh *d;
        assert_int_equal(ag_grammar_derive(r->grammar, NULL, &d, NULL), AG_OK);
        double there = sampled_distance(S.m, d), back = sampled_distance(d, S.m);
        double worst = fmax(there, back);
        if (!(worst <= r->fidelity.max_error + 1e-9))
            fail_msg("exact %d: sampled %g m beyond the reported fidelity %g m", exact, worst,
                     r->fidelity.max_error);
        assert_true(r->fidelity.max_error <= 0.01);
        if (exact && !(worst <= 1e-6))
            fail_msg("exact: sampled %g m", worst);
        /* sharing: fewer terminals than windows by default */
        if (!exact)
            assert_true(r->grammar->nterminals < S.m->ncomponents);
        ag_mesh_free(d);
        ag_proceduralize_result_free(r);
    }
    ag_mesh_free(S.m);
}

static void test_triangulations_share_a_label(void **state)
{
    (void)state;
    const double none[3] = {0, 0, 0}, utm[3] = {448123.25, 5402456.75, 374.5};
    check_site(0, none);
    check_site(0, utm);
    check_site(23 * M_PI / 180, none);
    check_site(23 * M_PI / 180, utm);
    check_site(M_PI / 2, utm);
}

static void test_same_surface(void **state)
{
    (void)state;
    /* a unit square as two triangles, cut along either diagonal, and as four */
    double a[18] = {0, 0, 0, 1, 0, 0, 1, 1, 0, /**/ 0, 0, 0, 1, 1, 0, 0, 1, 0};
    double b[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /**/ 1, 0, 0, 1, 1, 0, 0, 1, 0};
    double c[36] = {0, 0, 0, 1, 0, 0, .5, .5, 0, /**/ 1, 0, 0, 1, 1, 0, .5, .5, 0,
                    1, 1, 0, 0, 1, 0, .5, .5, 0, /**/ 0, 1, 0, 0, 0, 0, .5, .5, 0};
    double dev = -1;
    assert_int_equal(ag_label_same_surface(a, 2, b, 2, 1e-3, &dev), 1);
    assert_true(dev >= 0 && dev <= 1e-3);
    assert_int_equal(ag_label_same_surface(a, 2, c, 4, 1e-3, &dev), 1);
    /* the centre raised by 2 mm: the same within 5 mm, not within 1 mm */
    c[8] = c[17] = c[26] = c[35] = 0.002;
    assert_int_equal(ag_label_same_surface(a, 2, c, 4, 5e-3, &dev), 1);
    assert_true(dev >= 0.0019 && dev <= 5e-3);
    assert_int_equal(ag_label_same_surface(a, 2, c, 4, 1e-3, &dev), 0);
    /* a square 1 cm wider is not the same at 5 mm */
    double w[18];
    memcpy(w, b, sizeof w);
    w[3] = w[9] = w[12] = 1.01;
    assert_int_equal(ag_label_same_surface(a, 2, w, 2, 5e-3, &dev), 0);
}

/* Hundreds of different pyramids on one square base (the apex moved by 1.2 cm steps, on one
 * side of the diagonal so that no turn or mirror image maps one onto another): each is a label
 * of its own, and the surface comparisons stay within their budget per component, not one per
 * pair. */
static void test_many_shapes_on_one_box(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create();
    size_t n = 0;
    for (int i = 0; i < 34; i++)
        for (int j = i + 1; j < 34; j++) {
            double ax = 0.05 + 0.012 * i, ay = 0.05 + 0.012 * j, x0 = 2.0 * (double)(n % 30),
                   y0 = 2.0 * (double)(n / 30);
            size_t c;
            assert_int_equal(ag_mesh_add_component(m, -1, &c), AG_OK);
            uint32_t b = (uint32_t)m->nverts;
            ag_mesh_add_vertex(m, x0, y0, 0);
            ag_mesh_add_vertex(m, x0 + 1, y0, 0);
            ag_mesh_add_vertex(m, x0 + 1, y0 + 1, 0);
            ag_mesh_add_vertex(m, x0, y0 + 1, 0);
            ag_mesh_add_vertex(m, x0 + ax, y0 + ay, 1);
            /* the base cut along the diagonal the apex's side does not show */
            ag_mesh_add_triangle(m, b, b + 2, b + 1, (uint32_t)c);
            ag_mesh_add_triangle(m, b, b + 3, b + 2, (uint32_t)c);
            for (uint32_t k = 0; k < 4; k++)
                ag_mesh_add_triangle(m, b + k, b + (k + 1) % 4, b + 4, (uint32_t)c);
            n++;
        }
    ag_labels *L;
    assert_int_equal(ag_label_components(m, NULL, &L, NULL), AG_OK);
    assert_int_equal(L->nlabels, n);
    /* 64 comparisons per component and pass at most */
    if (L->surface_checks > 2 * 64 * n)
        fail_msg("%zu surface checks for %zu components", L->surface_checks, n);
    ag_labels_free(L);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_surface),
        cmocka_unit_test(test_triangulations_share_a_label),
        cmocka_unit_test(test_many_shapes_on_one_box),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
