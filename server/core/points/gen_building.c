#include "gen_building.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "rng.h"

#define MAX_HOLES_PER_WALL 4096

typedef struct {
    double s0, s1, t0, t1; /* unit parameters of an opening */
} hole;

typedef struct {
    double o[3], u[3], v[3], n[3];
    int triangle;
    int32_t plane, window;
    size_t first_hole, nholes;
    double area;
    size_t count;
} patch;

typedef struct {
    patch *p;
    size_t n, cap;
    hole *h;
    size_t nh, caph;
} patches;

static double len3(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static int add_patch(patches *ps, const double o[3], const double u[3], const double v[3],
                     int triangle, int32_t plane, int32_t window)
{
    if (AG_ARRAY_RESERVE(ps->p, ps->cap, ps->n + 1))
        return -1;
    patch *p = &ps->p[ps->n++];
    memset(p, 0, sizeof *p);
    memcpy(p->o, o, sizeof p->o);
    memcpy(p->u, u, sizeof p->u);
    memcpy(p->v, v, sizeof p->v);
    p->triangle = triangle;
    p->plane = plane;
    p->window = window;
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double l = len3(c);
    for (int a = 0; a < 3; a++)
        p->n[a] = l > 0 ? c[a] / l : 0;
    p->area = triangle ? l / 2 : l;
    p->first_hole = ps->nh;
    return 0;
}

size_t ag_gen_building_planes(const ag_gen_building_options *o)
{
    unsigned cols = o->cols ? o->cols : 6, rows = o->rows ? o->rows : 3;
    unsigned side = o->side_cols ? o->side_cols : 2;
    size_t windows = 2 * (size_t)cols * rows + 2 * (size_t)side * rows;
    return 4 + (o->ridge < 0 ? 1 : 2) + (o->window == AG_GEN_WINDOW_FLUSH ? 0 : 5 * windows);
}

/* Windows set into the wall just added (the last patch): glass and reveals as patches of
 * their own, the openings as holes of the wall. */
static int add_windows(patches *ps, unsigned cols, unsigned rows, const ag_gen_building_options *o,
                       double w, double h, double depth, int32_t *next_plane, int32_t *next_window,
                       ag_rng *rng)
{
    patch wall = ps->p[ps->n - 1];
    size_t wall_index = ps->n - 1;
    double lu = len3(wall.u), lv = len3(wall.v);
    double uh[3], vh[3], dv[3];
    for (int a = 0; a < 3; a++) {
        uh[a] = wall.u[a] / lu;
        vh[a] = wall.v[a] / lv;
        /* glass set back (recessed, flush) or standing out (proud) */
        dv[a] = (o->window == AG_GEN_WINDOW_PROUD ? 1 : -1) * depth * wall.n[a];
    }
    for (unsigned r = 0; r < rows; r++)
        for (unsigned c = 0; c < cols; c++) {
            double cs = (c + 0.5) / cols * lu, ct = (r + 0.5) / rows * lv;
            if (o->jitter > 0) {
                cs += (ag_rng_unit(rng) - 0.5) * 2 * o->jitter;
                ct += (ag_rng_unit(rng) - 0.5) * 2 * o->jitter;
            }
            double s0 = cs - w / 2, t0 = ct - h / 2;
            hole hl = {s0 / lu, (s0 + w) / lu, t0 / lv, (t0 + h) / lv};
            if (hl.s0 < 0 || hl.s1 > 1 || hl.t0 < 0 || hl.t1 > 1)
                continue; /* does not fit this wall */
            /* the opening is a hole of the wall (patches added below do not move it) */
            if (AG_ARRAY_RESERVE(ps->h, ps->caph, ps->nh + 1))
                return -1;
            ps->h[ps->nh++] = hl;
            ps->p[wall_index].nholes++;
            int32_t win = (*next_window)++;
            double corner[3], glass_o[3], a[3], b[3];
            for (int k = 0; k < 3; k++) {
                corner[k] = wall.o[k] + s0 * uh[k] + t0 * vh[k];
                glass_o[k] = corner[k] + dv[k];
                a[k] = w * uh[k];
                b[k] = h * vh[k];
            }
            if (o->window == AG_GEN_WINDOW_FLUSH) {
                if (add_patch(ps, glass_o, a, b, 0, wall.plane, win))
                    return -1;
                continue;
            }
            int32_t base = *next_plane;
            *next_plane += 5;
            double tp[3], rp[3];
            for (int k = 0; k < 3; k++) {
                tp[k] = corner[k] + b[k];
                rp[k] = corner[k] + a[k];
            }
            if (add_patch(ps, glass_o, a, b, 0, base, win) ||
                add_patch(ps, corner, a, dv, 0, base + 1, win) ||  /* bottom */
                add_patch(ps, tp, a, dv, 0, base + 2, win) ||      /* top */
                add_patch(ps, corner, b, dv, 0, base + 3, win) ||  /* left */
                add_patch(ps, rp, b, dv, 0, base + 4, win))        /* right */
                return -1;
        }
    return 0;
}

ag_status ag_gen_building(const ag_gen_building_options *opt, ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_gen_building_options o = opt ? *opt : (ag_gen_building_options){0};
    size_t npoints = o.points ? o.points : 100000;
    double W = o.width > 0 ? o.width : 24, D = o.depth > 0 ? o.depth : 12;
    double H = o.height > 0 ? o.height : 9;
    double R = o.ridge ? o.ridge : 4;
    unsigned cols = o.cols ? o.cols : 6, rows = o.rows ? o.rows : 3;
    unsigned side = o.side_cols ? o.side_cols : 2;
    double ww = o.window_w > 0 ? o.window_w : 1.2, wh = o.window_h > 0 ? o.window_h : 1.5;
    double depth = o.window == AG_GEN_WINDOW_FLUSH ? 0.02 : o.window_depth > 0 ? o.window_depth : 0.25;
    double sigma = o.noise < 0 ? 0 : o.noise > 0 ? o.noise : 0.005;
    if ((size_t)cols * rows > MAX_HOLES_PER_WALL || (size_t)side * rows > MAX_HOLES_PER_WALL)
        return ag_error_set(err, AG_ERR_INVALID, 0, "too many windows per wall");
    ag_rng rng;
    ag_rng_seed(&rng, o.seed ? o.seed : 12345);
    patches ps = {0};
    int32_t next_plane = R < 0 ? 5 : 6, next_window = 0;
    int fail = 0;
    /* walls: front (y = 0), right (x = W), back (y = D), left (x = 0), outward normals */
    const double walls[4][3][3] = {
        {{0, 0, 0}, {W, 0, 0}, {0, 0, H}},
        {{W, 0, 0}, {0, D, 0}, {0, 0, H}},
        {{W, D, 0}, {-W, 0, 0}, {0, 0, H}},
        {{0, D, 0}, {0, -D, 0}, {0, 0, H}},
    };
    for (int k = 0; k < 4 && !fail; k++) {
        fail |= add_patch(&ps, walls[k][0], walls[k][1], walls[k][2], 0, k, -1);
        unsigned c = k % 2 == 0 ? cols : side;
        if (!fail)
            fail |= add_windows(&ps, c, rows, &o, ww, wh, depth, &next_plane, &next_window, &rng);
    }
    if (!fail && R > 0) {
        const double gr[3][3] = {{W, 0, H}, {0, D, 0}, {0, D / 2, R}};
        const double gl[3][3] = {{0, D, H}, {0, -D, 0}, {0, -D / 2, R}};
        const double rf[3][3] = {{0, 0, H}, {W, 0, 0}, {0, D / 2, R}};
        const double rb[3][3] = {{W, D, H}, {-W, 0, 0}, {0, -D / 2, R}};
        fail |= add_patch(&ps, gr[0], gr[1], gr[2], 1, 1, -1) ||
                add_patch(&ps, gl[0], gl[1], gl[2], 1, 3, -1) ||
                add_patch(&ps, rf[0], rf[1], rf[2], 0, 4, -1) ||
                add_patch(&ps, rb[0], rb[1], rb[2], 0, 5, -1);
    } else if (!fail) {
        const double fl[3][3] = {{0, 0, H}, {W, 0, 0}, {0, D, 0}};
        fail |= add_patch(&ps, fl[0], fl[1], fl[2], 0, 4, -1);
    }
    if (fail) {
        free(ps.p);
        free(ps.h);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* net areas, then points per patch in proportion (largest remainders first) */
    double total = 0;
    for (size_t i = 0; i < ps.n; i++) {
        patch *p = &ps.p[i];
        double lu = len3(p->u), lv = len3(p->v);
        for (size_t k = 0; k < p->nholes; k++) {
            const hole *hl = &ps.h[p->first_hole + k];
            p->area -= (hl->s1 - hl->s0) * lu * (hl->t1 - hl->t0) * lv;
        }
        total += p->area;
    }
    size_t assigned = 0;
    for (size_t i = 0; i < ps.n; i++) {
        ps.p[i].count = (size_t)floor((double)npoints * ps.p[i].area / total);
        assigned += ps.p[i].count;
    }
    for (size_t i = 0; assigned < npoints; i = (i + 1) % ps.n, assigned++)
        ps.p[i].count++;

    ag_cloud *c = ag_cloud_create();
    size_t iplane, iwin;
    ag_status st = c ? ag_cloud_resize(c, npoints, err) : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK)
        st = ag_cloud_add_property(c, "plane", AG_SCALAR_INT32, &iplane, err);
    if (st == AG_OK)
        st = ag_cloud_add_property(c, "window", AG_SCALAR_INT32, &iwin, err);
    if (st != AG_OK) {
        ag_cloud_free(c);
        free(ps.p);
        free(ps.h);
        return st;
    }
    int32_t *plane = c->props[iplane].values, *window = c->props[iwin].values;
    double th = o.rotation * M_PI / 180, cs = cos(th), sn = sin(th);
    double base[3] = {0, 0, 0};
    if (o.absolute)
        memcpy(base, o.origin, sizeof base);
    else
        memcpy(c->offset, o.origin, sizeof c->offset);
    size_t at = 0;
    for (size_t i = 0; i < ps.n; i++) {
        const patch *p = &ps.p[i];
        for (size_t k = 0; k < p->count; k++) {
            double s, t;
            for (;;) {
                s = ag_rng_unit(&rng);
                t = ag_rng_unit(&rng);
                if (p->triangle && s + t > 1) {
                    s = 1 - s;
                    t = 1 - t;
                }
                int inside = 0;
                for (size_t q = 0; q < p->nholes && !inside; q++) {
                    const hole *hl = &ps.h[p->first_hole + q];
                    inside = s > hl->s0 && s < hl->s1 && t > hl->t0 && t < hl->t1;
                }
                if (!inside)
                    break;
            }
            double e = sigma > 0 ? sigma * ag_rng_gauss(&rng) : 0;
            double q[3];
            for (int a = 0; a < 3; a++)
                q[a] = p->o[a] + s * p->u[a] + t * p->v[a] + e * p->n[a];
            double x = q[0] - W / 2, y = q[1] - D / 2;
            c->xyz[3 * at + 0] = base[0] + W / 2 + cs * x - sn * y;
            c->xyz[3 * at + 1] = base[1] + D / 2 + sn * x + cs * y;
            c->xyz[3 * at + 2] = base[2] + q[2];
            plane[at] = p->plane;
            window[at] = p->window;
            at++;
        }
    }
    free(ps.p);
    free(ps.h);
    *out = c;
    return AG_OK;
}
