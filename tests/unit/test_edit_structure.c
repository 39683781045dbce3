/* Resize keeps a building's structure (issue: a facade stretched 2x holds 2x the windows at the
 * original size and spacing, whether or not the windows are children of the wall; the root is
 * resized by the attachment equations like any node; thin elements keep their thickness; a
 * node attached at one end only keeps its size).
 *
 * Box buildings (edit_building_fixture.h) with a grid on the front and on one or both side facades
 * and a door, the windows recessed, flush and proud, with and without a roof overhang, turned a
 * quarter, at UTM coordinates and jittered, are proceduralized and then stretched 2x along the
 * front (the root and the front wall) and squeezed back. Every result is checked on its mesh
 * alone: windows and doors are counted by group and position, their sizes and the walls'
 * thicknesses measured, every element must still be closed, and the grammar must derive the
 * mesh exactly (fidelity). A global resize of one window (either hand) reaches every window:
 * both hands on every facade get its new size, the mirror images growing the other way. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_building_fixture.h"
#include "core/edit/edit.h"
#include "core/proc/proceduralize.h"

/* What a building's mesh holds, measured. */
typedef struct {
    size_t front, right, left;  /* windows on each facade */
    size_t front_cols, front_rows;
    size_t doors;
    size_t wall_parts;
    double win_size_err;        /* largest relative size error of a window (any axis) */
    double door_size_err;
    double wall_thick_err;      /* largest relative error of a wall's thickness */
    double min_gap;             /* smallest gap between two windows of one facade (< 0: overlap) */
    double period;              /* the front windows' column period (mean) */
    double period_err;          /* largest relative error of a column spacing to BB_PERIOD */
    double ext[3];              /* the whole building's extents (building frame) */
    size_t open_edges;
} bb_measure;

/* The elements' groups by name (an edit keeps the labels' names, not their group numbers). */
typedef struct {
    char window[64], door[64], wall_fb[64], wall_lr[64];
} bb_groups;

/* The group numbered as `name` in m, -2 when m has none of that name. */
static int32_t group_named(const ag_mesh *m, const char *name)
{
    for (size_t i = 0; i < m->ngroups; i++)
        if (!strcmp(m->group_names[i], name))
            return (int32_t)i;
    return -2;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Distinct values (within tol) of a sorted array. */
static size_t distinct(double *v, size_t n, double tol)
{
    qsort(v, n, sizeof *v, cmp_double);
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (!k || v[i] - v[k - 1] > tol)
            v[k++] = v[i];
    return k;
}

/* The groups of the elements, found by position in the mesh as proceduralized: the group of
 * the first front window, the door, the front wall and the left wall. */
static bb_groups find_groups(const ag_mesh *m, const bb_options *o)
{
    size_t n;
    bb_part *p = bb_parts(m, o, &n);
    double fr[2], gl[2], si[2];
    bb_depths(o->mount, fr, gl, si);
    int32_t w = bb_group_at(p, n, BB_MARGIN + 0.6, 0.5 * (gl[0] + gl[1]), BB_ROW0 + 0.7);
    int32_t d = bb_group_at(p, n, 0.5 * bb_length(o), 0.5 * (fr[0] + fr[1]), 1.0);
    int32_t fb = bb_group_at(p, n, 0.3, 0.5 * BB_WALL, 1.0);
    int32_t lr = bb_group_at(p, n, 0.5 * BB_WALL, 0.5 * bb_depth(o), 1.0);
    free(p);
    assert_true(w >= 0 && d >= 0 && fb >= 0 && lr >= 0);
    assert_true(w != d && w != fb && fb != d);
    bb_groups g;
    snprintf(g.window, sizeof g.window, "%s", m->group_names[w]);
    snprintf(g.door, sizeof g.door, "%s", m->group_names[d]);
    snprintf(g.wall_fb, sizeof g.wall_fb, "%s", m->group_names[fb]);
    snprintf(g.wall_lr, sizeof g.wall_lr, "%s", m->group_names[lr]);
    return g;
}

static bb_measure measure(const ag_mesh *m, const bb_options *o, const bb_groups *names)
{
    bb_measure r = {0};
    struct {
        int32_t window, door, wall_fb, wall_lr;
    } gi = {group_named(m, names->window), group_named(m, names->door),
            group_named(m, names->wall_fb), group_named(m, names->wall_lr)},
      *g = &gi;
    size_t n;
    bb_part *p = bb_parts(m, o, &n);
    double fr[2], gl[2], si[2];
    bb_depths(o->mount, fr, gl, si);
    /* the original window: u -0.05..1.25, v from the sill's or frame's front to the back,
     * w -0.08..1.5 */
    double win[3] = {BB_WIN_W + 0.1, fmax(fmax(fr[1], gl[1]), si[1]) - fmin(fmin(fr[0], gl[0]), si[0]),
                     BB_WIN_H + 0.08};
    double door[3] = {BB_DOOR_W, fmax(fr[1], gl[1]) - fmin(fr[0], gl[0]), BB_DOOR_H};
    double *xs = malloc((n + 1) * sizeof *xs), *zs = malloc((n + 1) * sizeof *zs);
    size_t nf = 0;
    double front_y = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (p[i].group == g->wall_fb || p[i].group == g->wall_lr)
            xmax = fmax(xmax, p[i].max[0]);
    r.min_gap = INFINITY;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], p[i].min[a]);
            hi[a] = fmax(hi[a], p[i].max[a]);
        }
    for (int a = 0; a < 3; a++)
        r.ext[a] = hi[a] - lo[a];
    for (size_t i = 0; i < n; i++) {
        const bb_part *x = &p[i];
        if (x->group == g->window) {
            /* which facade: the thin horizontal axis says where it faces */
            int along_x = bb_extent(x, 0) > bb_extent(x, 1);
            double e[3] = {bb_extent(x, along_x ? 0 : 1), bb_extent(x, along_x ? 1 : 0),
                           bb_extent(x, 2)};
            for (int a = 0; a < 3; a++)
                r.win_size_err = fmax(r.win_size_err, fabs(e[a] / win[a] - 1));
            if (along_x) {
                r.front++;
                xs[nf] = x->min[0];
                zs[nf++] = x->min[2];
                front_y = fmin(front_y, x->min[1]);
            } else if (x->min[0] > 0.5 * xmax) {
                r.right++;
            } else {
                r.left++;
            }
            for (size_t j = 0; j < i; j++) {
                const bb_part *y = &p[j];
                if (y->group != g->window)
                    continue;
                double gap = -INFINITY;
                for (int a = 0; a < 3; a++)
                    gap = fmax(gap, fmax(y->min[a] - x->max[a], x->min[a] - y->max[a]));
                r.min_gap = fmin(r.min_gap, gap);
            }
        } else if (x->group == g->door) {
            r.doors++;
            for (int a = 0; a < 3; a++)
                r.door_size_err = fmax(r.door_size_err, fabs(bb_extent(x, a) / door[a] - 1));
        } else if (x->group == g->wall_fb || x->group == g->wall_lr) {
            r.wall_parts++;
            double thin = fmin(bb_extent(x, 0), bb_extent(x, 1));
            r.wall_thick_err = fmax(r.wall_thick_err, fabs(thin / BB_WALL - 1));
        }
    }
    double *cols = malloc((nf + 1) * sizeof *cols);
    memcpy(cols, xs, nf * sizeof *xs);
    r.front_cols = distinct(cols, nf, 0.05);
    r.front_rows = distinct(zs, nf, 0.05);
    r.period = r.front_cols > 1 ? (cols[r.front_cols - 1] - cols[0]) / (r.front_cols - 1) : 0;
    for (size_t i = 1; i < r.front_cols; i++)
        r.period_err = fmax(r.period_err, fabs((cols[i] - cols[i - 1]) / BB_PERIOD - 1));
    (void)front_y;
    free(cols);
    free(xs);
    free(zs);
    free(p);
    double diag = 1;
    if (m->nverts) {
        ag_box b = ag_mesh_bounds(m);
        diag = ag_box_diagonal(&b);
    }
    r.open_edges = bb_open_edges(m, 1e-7 * diag + 1e-9 * fmax(fabs(o->dx), fabs(o->dy)));
    return r;
}

static void print_measure(const char *what, const bb_options *o, const bb_measure *r)
{
    print_message("  %-28s %-40s front %zu (%zu x %zu, period %.3f) right %zu left %zu doors %zu "
                  "walls %zu | window err %.4f door err %.4f wall err %.4f gap %.3f open %zu\n",
                  o->name, what, r->front, r->front_cols, r->front_rows, r->period, r->right,
                  r->left, r->doors, r->wall_parts, r->win_size_err, r->door_size_err,
                  r->wall_thick_err, r->min_gap, r->open_edges);
}

/* The grammar of the model derives its mesh: every triangle matched within the exact
 * tolerance, none left over. */
static void assert_grammar_derives_mesh(const ag_edit_model *em, const char *what)
{
    ag_mesh *d = NULL;
    ag_error err = {0};
    if (ag_grammar_derive(em->proc->grammar, NULL, &d, &err))
        fail_msg("%s: derive: %s", what, err.text);
    ag_fidelity f;
    ag_box b = ag_mesh_bounds(em->proc->mesh);
    double tol = 1e-6 * ag_box_diagonal(&b);
    assert_int_equal(ag_grammar_fidelity(em->proc->mesh, d, tol, &f, &err), AG_OK);
    if (f.unmatched || d->ntris != em->proc->mesh->ntris)
        fail_msg("%s: the grammar does not derive the mesh (%zu of %zu triangles unmatched, %zu "
                 "derived)",
                 what, f.unmatched, em->proc->mesh->ntris, d->ntris);
    ag_mesh_free(d);
}

/* The front's world axis (x, or y when the building is turned an odd number of times). */
static int front_axis(const bb_options *o)
{
    return o->turn & 1 ? 1 : 0;
}

static ag_edit_model *apply(ag_edit_model *em, const ag_edit_op *op, unsigned flags,
                            const char *what, const bb_options *o)
{
    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    if (ag_edit_apply_ex(em, op, flags, &out, &rep, &err))
        fail_msg("%s %s: %s", o->name, what, err.text);
    assert_true(rep.max_residual_rel <= 1e-6);
    ag_edit_report_clear(&rep);
    return out;
}

static ag_edit_model *scale_node(ag_edit_model *em, int32_t node, double f, unsigned flags,
                                 const char *what, const bb_options *o)
{
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = node, .has_scale = 1, .scale = {1, 1, 1},
                     .mode = AG_EDIT_GLOBAL};
    op.scale[front_axis(o)] = f;
    return apply(em, &op, flags, what, o);
}

/* The visible node whose box is the front wall's (building frame), -1 when none is. */
static int32_t front_wall(const ag_edit_model *em, const bb_options *o)
{
    const ag_splittree *t = em->proc->tree;
    double lo[3], hi[3];
    bb_to_world(o, 0, 0, 0, lo);
    bb_to_world(o, bb_length(o), BB_WALL, bb_height(o), hi);
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int ok = 1;
        for (int a = 0; a < 3 && ok; a++)
            ok = fabs(x->box.min[a] - fmin(lo[a], hi[a])) < 1e-3 &&
                 fabs(x->box.max[a] - fmax(lo[a], hi[a])) < 1e-3;
        if (ok)
            return (int32_t)n;
    }
    return -1;
}

static void expect_original(const bb_measure *r, const bb_options *o, const char *what)
{
    if (r->front != o->cols * o->rows || r->right != o->side_cols * o->rows ||
        r->left != o->left_cols * o->rows || r->doors != 1 || r->win_size_err > 0.01 ||
        r->door_size_err > 0.01 || r->wall_thick_err > 0.01 || r->open_edges ||
        !(r->min_gap > 0) || r->period_err > 0.01)
        fail_msg("%s %s: the original structure is not there", o->name, what);
}

/* Stretched 2x along the front: 12 (or 11) columns at the original size, the sides as they
 * were, one door, walls as thick as they were, nothing overlapping, every element closed. */
static void expect_stretched(const bb_measure *r, const bb_options *o, const char *what)
{
    size_t cols = r->front_cols;
    int ok = (cols == 2 * o->cols || cols == 2 * o->cols - 1) && r->front_rows == o->rows &&
             r->front == cols * o->rows && r->right == o->side_cols * o->rows &&
             r->left == o->left_cols * o->rows && r->doors == 1 && r->win_size_err <= 0.01 &&
             r->door_size_err <= 0.01 && r->wall_thick_err <= 0.01 && r->open_edges == 0 &&
             r->min_gap > 0 && r->period_err <= 0.01;
    if (!ok)
        fail_msg("%s %s: front %zu (%zu columns x %zu rows) want %u or %u columns x %u, right %zu "
                 "want %u, left %zu want %u, doors %zu, window size error %.4f, door %.4f, wall "
                 "thickness error %.4f, gap %.3f, open edges %zu, spacing error %.4f",
                 o->name, what, r->front, cols, r->front_rows, 2 * o->cols, 2 * o->cols - 1,
                 o->rows, r->right, o->side_cols * o->rows, r->left, o->left_cols * o->rows,
                 r->doors, r->win_size_err, r->door_size_err, r->wall_thick_err, r->min_gap,
                 r->open_edges, r->period_err);
}

static const bb_options variants[] = {
    {"recessed", 6, 3, 3, 0, BB_RECESSED, 0, 0, 0, 0, 0, 0, 0},
    {"flush", 6, 3, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 0, 0},
    {"proud", 6, 3, 3, 0, BB_PROUD, 0, 0, 0, 0, 0, 0, 0},
    {"proud, overhang", 6, 3, 3, 0, BB_PROUD, 0.3, 0, 0, 0, 0, 0, 0},
    {"recessed, overhang, both sides", 6, 3, 3, 2, BB_RECESSED, 0.3, 0, 0, 0, 0, 0, 0},
    {"flush, turned a quarter", 6, 3, 3, 0, BB_FLUSH, 0, 1, 0, 0, 0, 0, 0},
    {"proud, turned three quarters", 6, 3, 3, 3, BB_PROUD, 0.2, 3, 0, 0, 0, 0, 0},
    {"recessed, UTM", 6, 3, 3, 0, BB_RECESSED, 0, 0, 512345.0, 5812345.0, 31.0, 0, 0},
    {"proud, UTM, turned", 6, 3, 3, 0, BB_PROUD, 0.3, 2, 684321.0, 5403210.0, 412.0, 0, 0},
    {"flush, jittered", 6, 3, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 2e-7, 0},
    {"proud 5 x 2, jittered", 5, 2, 4, 0, BB_PROUD, 0.3, 0, 0, 0, 0, 2e-7, 0},
    /* windows and their mirror images alternating: two interleaved patterns per facade */
    {"recessed, handed", 6, 3, 3, 0, BB_RECESSED, 0, 0, 0, 0, 0, 0, 1},
    {"flush, handed", 6, 3, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 0, 1},
    {"proud, handed", 6, 3, 3, 0, BB_PROUD, 0, 0, 0, 0, 0, 0, 1},
    {"proud, handed, overhang, turned", 6, 2, 3, 2, BB_PROUD, 0.3, 1, 0, 0, 0, 0, 1},
    /* an odd count: 3 windows and 2 mirror images taking turns */
    {"flush, handed 5 x 2", 5, 2, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 0, 1},
    {"recessed, handed 5 x 2", 5, 2, 3, 0, BB_RECESSED, 0, 0, 0, 0, 0, 0, 1},
    {"proud, handed 5 x 2, overhang, turned", 5, 2, 3, 2, BB_PROUD, 0.3, 3, 0, 0, 0, 0, 1},

};

/* One variant through every edit, each on the service's path (the model kept, no read-back)
 * and, for the root, the command line's (read back through the grammar). */
static void run_variant(const bb_options *o)
{
    /* as the service keeps it: read back through its grammar, the mesh grouped by label */
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_edit_model *em = bb_service_model(o, &m, &err);
    if (!em)
        fail_msg("%s: proceduralize: %s", o->name, err.text);
    bb_groups g = find_groups(em->proc->mesh, o);
    bb_measure before = measure(em->proc->mesh, o, &g);
    print_measure("as proceduralized", o, &before);
    expect_original(&before, o, "as proceduralized");

    /* the whole building twice as long along the front, and back */
    ag_edit_model *wide = scale_node(em, AG_EDIT_ROOT, 2.0, 0, "root x2", o);
    bb_measure mw = measure(wide->proc->mesh, o, &g);
    print_measure("root stretched 2x", o, &mw);
    expect_stretched(&mw, o, "root stretched 2x");
    /* the building is what was asked: twice as long, nothing past its new ends */
    for (int a = 0; a < 3; a++)
        if (fabs(mw.ext[a] - (a ? 1 : 2) * before.ext[a]) > 1e-6 * before.ext[0])
            fail_msg("%s root stretched 2x: extent %d is %.9f, want %.9f", o->name, a, mw.ext[a],
                     (a ? 1 : 2) * before.ext[a]);
    assert_grammar_derives_mesh(wide, "root stretched 2x");
    ag_edit_model *back = scale_node(wide, AG_EDIT_ROOT, 0.5, 0, "root x0.5", o);
    bb_measure mb = measure(back->proc->mesh, o, &g);
    print_measure("and squeezed back", o, &mb);
    expect_original(&mb, o, "root squeezed back");
    for (int a = 0; a < 3; a++)
        if (fabs(mb.ext[a] - before.ext[a]) > 1e-6 * before.ext[0])
            fail_msg("%s root squeezed back: extent %d is %.9f, want %.9f", o->name, a, mb.ext[a],
                     before.ext[a]);
    assert_grammar_derives_mesh(back, "root squeezed back");
    ag_edit_model_free(back);
    ag_edit_model_free(wide);

    /* the front wall alone twice as long */
    int32_t wall = front_wall(em, o);
    assert_true(wall > 0);
    wide = scale_node(em, wall, 2.0, 0, "front wall x2", o);
    mw = measure(wide->proc->mesh, o, &g);
    print_measure("front wall stretched 2x", o, &mw);
    expect_stretched(&mw, o, "front wall stretched 2x");
    assert_grammar_derives_mesh(wide, "front wall stretched 2x");
    int32_t wall2 = front_wall(wide, &(bb_options){.cols = 2 * o->cols, .rows = o->rows,
                                                   .turn = o->turn, .dx = o->dx, .dy = o->dy,
                                                   .dz = o->dz});
    if (wall2 > 0) {
        back = scale_node(wide, wall2, 0.5, 0, "front wall x0.5", o);
        mb = measure(back->proc->mesh, o, &g);
        print_measure("and squeezed back", o, &mb);
        expect_original(&mb, o, "front wall squeezed back");
        ag_edit_model_free(back);
    }
    ag_edit_model_free(wide);

    /* the command line reads the result back through its grammar: the same building */
    wide = scale_node(em, AG_EDIT_ROOT, 2.0, 0, "root x2", o);
    ag_edit_model *reread = scale_node(em, AG_EDIT_ROOT, 2.0, AG_EDIT_READ_BACK,
                                       "root x2 read back", o);
    ag_fidelity f;
    ag_box b = ag_mesh_bounds(wide->proc->mesh);
    assert_int_equal(ag_grammar_fidelity(wide->proc->mesh, reread->proc->mesh,
                                         1e-6 * ag_box_diagonal(&b), &f, &err),
                     AG_OK);
    if (f.unmatched || reread->proc->mesh->ntris != wide->proc->mesh->ntris)
        fail_msg("%s: read back through the grammar, the stretched building differs", o->name);
    ag_edit_model_free(reread);
    ag_edit_model_free(wide);

    ag_edit_model_free(em);
    ag_mesh_free(m);
}

/* ---- a global resize of one window ------------------------------------------------------ */

/* The windows of a mesh as a window resize checks them: per window its box in the building
 * frame, its facade (0 front, 1 right, 2 left), its place along the facade (u, increasing
 * along the facade's own direction) and its hand: the sign of its triangles' mean centroid
 * along u from its box's centre (the handle is the only part off the centre: -1 on the left,
 * +1 on the right, 0 for a window without one). */
typedef struct {
    bb_part box;
    int facade;
    double u;  /* the box's min along the facade's direction */
    double along, depth, height; /* extents in the facade frame */
    double v0, v1;               /* the box's depth range along the facade's normal */
    int hand;
} window_measure;

/* A facade's direction (its u) in the building frame: front +x, right +y, left -y. */
static void facade_dir(int facade, double d[2])
{
    d[0] = facade == 0 ? 1 : 0;
    d[1] = facade == 0 ? 0 : facade == 1 ? 1 : -1;
}

/* A point's place along a facade (building frame). */
static double facade_u(int facade, double x, double y)
{
    double d[2];
    facade_dir(facade, d);
    return d[0] * x + d[1] * y;
}

static window_measure *measure_windows(const ag_mesh *m, const bb_options *o, const char *window,
                                  size_t *nw)
{
    int32_t gw = group_named(m, window);
    size_t nc = m->ncomponents;
    bb_part *b = calloc(nc + 1, sizeof *b);
    double *cx = calloc(nc + 1, sizeof *cx), *cy = calloc(nc + 1, sizeof *cy);
    size_t *nt = calloc(nc + 1, sizeof *nt);
    for (size_t c = 0; c < nc; c++)
        for (int a = 0; a < 3; a++) {
            b[c].min[a] = INFINITY;
            b[c].max[a] = -INFINITY;
        }
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t c = m->tri_component[t];
        for (int k = 0; k < 3; k++) {
            double q[3];
            bb_to_frame(o, &m->pos[3 * m->tri[3 * t + k]], q);
            for (int a = 0; a < 3; a++) {
                b[c].min[a] = fmin(b[c].min[a], q[a]);
                b[c].max[a] = fmax(b[c].max[a], q[a]);
            }
            cx[c] += q[0] / 3;
            cy[c] += q[1] / 3;
        }
        nt[c]++;
    }
    double xmid = 0.5 * bb_length(o);
    window_measure *w = calloc(nc + 1, sizeof *w);
    size_t k = 0;
    for (size_t c = 0; c < nc; c++) {
        if (!nt[c] || m->component_group[c] != gw)
            continue;
        window_measure *x = &w[k++];
        x->box = b[c];
        int along_x = bb_extent(&b[c], 0) > bb_extent(&b[c], 1);
        x->facade = along_x ? 0 : b[c].min[0] > xmid ? 1 : 2;
        double u0 = facade_u(x->facade, b[c].min[0], b[c].min[1]),
               u1 = facade_u(x->facade, b[c].max[0], b[c].max[1]);
        x->u = fmin(u0, u1);
        x->along = bb_extent(&b[c], along_x ? 0 : 1);
        x->depth = bb_extent(&b[c], along_x ? 1 : 0);
        x->height = bb_extent(&b[c], 2);
        x->v0 = b[c].min[along_x ? 1 : 0];
        x->v1 = b[c].max[along_x ? 1 : 0];
        double mu = facade_u(x->facade, cx[c] / nt[c], cy[c] / nt[c]);
        double off = mu - 0.5 * (u0 + u1);
        x->hand = fabs(off) < 1e-3 * x->along ? 0 : off < 0 ? -1 : 1;
    }
    free(b);
    free(cx);
    free(cy);
    free(nt);
    *nw = k;
    return w;
}

/* A window's row: the nearest of the rows its bottom (the sill's) started on. */
static long window_row(const window_measure *x)
{
    return lround((x->box.min[2] + 0.08 - BB_ROW0) / BB_FLOOR);
}

/* Windows ordered by facade, row, then place along the facade. */
static int cmp_window(const void *p, const void *q)
{
    const window_measure *x = p, *y = q;
    if (x->facade != y->facade)
        return x->facade - y->facade;
    if (window_row(x) != window_row(y))
        return window_row(x) < window_row(y) ? -1 : 1;
    return x->u < y->u ? -1 : x->u > y->u;
}

/* The visible node of the window of column col in the first row of a facade (0 front, 1
 * right): the smallest visible node whose box holds the window's glass centre (world). */
static int32_t window_node(const ag_edit_model *em, const bb_options *o, int facade,
                           unsigned col)
{
    double fr[2], gl[2], si[2], p[3];
    bb_depths(o->mount, fr, gl, si);
    double u = BB_MARGIN + col * BB_PERIOD + 0.5 * BB_WIN_W, v = 0.5 * (gl[0] + gl[1]);
    /* the right facade's frame: x = L - v, y = u (edit_building_fixture.h bb_to_building) */
    bb_to_world(o, facade ? bb_length(o) - v : u, facade ? u : v, BB_ROW0 + 0.5 * BB_WIN_H, p);
    const ag_splittree *t = em->proc->tree;
    int32_t best = -1;
    double bv = INFINITY;
    for (size_t n = 1; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int in = 1;
        for (int a = 0; a < 3 && in; a++)
            in = x->box.min[a] <= p[a] && p[a] <= x->box.max[a];
        double v = ag_box_extent(&x->box, 0) * ag_box_extent(&x->box, 1) *
                   ag_box_extent(&x->box, 2);
        if (in && v < bv) {
            bv = v;
            best = (int32_t)n;
        }
    }
    return best;
}

#define WINDOW_WIDER 1.2
#define WINDOW_TALLER 0.9

/* Resizes the window of column col in the first row of a facade (0 front, 1 right; a
 * left-handed window in an even column, its mirror image in an odd one) 1.2x wider and 0.9x
 * taller in global mode: every window, of both hands and on every facade, has the new size
 * within 1 % on the edited mesh, its hand where it was (the hands still alternate along every
 * row), the side it grew from kept (a mirror image grows the other way), its depth in the wall
 * as before, inside its facade's wall along it and clear of the other windows, and the count
 * is unchanged. */
static int resize_one_window(const bb_options *o, int facade, unsigned col)
{
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_edit_model *em = bb_service_model(o, &m, &err);
    if (!em)
        fail_msg("%s: proceduralize: %s", o->name, err.text);
    bb_groups g = find_groups(em->proc->mesh, o);
    size_t n0, n1;
    window_measure *w0 = measure_windows(em->proc->mesh, o, g.window, &n0);
    qsort(w0, n0, sizeof *w0, cmp_window);
    int32_t node = window_node(em, o, facade, col);
    assert_true(node > 0);
    /* the facade's direction in the world: the axis the window widens along, and whether the
     * scale, which holds the world min corner, holds the facade's min in its own frame */
    double d[2], w0o[3], w1o[3];
    facade_dir(facade, d);
    bb_to_world(o, 0, 0, 0, w0o);
    bb_to_world(o, d[0], d[1], 0, w1o);
    int axis = fabs(w1o[0] - w0o[0]) > fabs(w1o[1] - w0o[1]) ? 0 : 1;
    int grows_from_min = w1o[axis] > w0o[axis];
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = node, .has_scale = 1, .scale = {1, 1, 1},
                     .mode = AG_EDIT_GLOBAL};
    op.scale[axis] = WINDOW_WIDER;
    op.scale[2] = WINDOW_TALLER;
    char what[64];
    snprintf(what, sizeof what, "%s window %u resized", facade ? "right" : "front", col);
    ag_edit_model *ed = apply(em, &op, 0, what, o);
    window_measure *w1 = measure_windows(ed->proc->mesh, o, g.window, &n1);
    qsort(w1, n1, sizeof *w1, cmp_window);

    /* a window's box: the frame and the sill 5 cm past it on each side, 8 cm under it */
    double want[3] = {(BB_WIN_W + 0.1) * WINDOW_WIDER, w0[0].depth,
                      (BB_WIN_H + 0.08) * WINDOW_TALLER};
    /* the hand of the edited window: even columns left-handed (none when un-handed) */
    int edited_hand = o->handed ? (col & 1 ? 1 : -1) : 0;
    double size_err = 0, depth_moved = 0, anchor_moved = 0, min_gap = INFINITY, outside = 0;
    size_t hands_wrong = 0, row_start = 0, per_facade0[3] = {0}, per_facade1[3] = {0};
    for (size_t i = 0; i < n0; i++) {
        per_facade0[w0[i].facade]++;
        if (i == 0 || w0[i - 1].facade != w0[i].facade ||
            window_row(&w0[i - 1]) != window_row(&w0[i]))
            row_start = i;
        /* the measure itself: the original's hands alternate along every row */
        assert_int_equal(w0[i].hand, o->handed ? ((i - row_start) & 1 ? 1 : -1) : 0);
    }
    for (size_t i = 0; i < n1; i++) {
        const window_measure *x = &w1[i];
        per_facade1[x->facade]++;
        double e[3] = {x->along, x->depth, x->height};
        for (int a = 0; a < 3; a++)
            size_err = fmax(size_err, fabs(e[a] / want[a] - 1));
        /* its place in its row: even places left-handed, odd ones right (un-handed: 0) */
        if (i == 0 || w1[i - 1].facade != x->facade || window_row(&w1[i - 1]) != window_row(x))
            row_start = i;
        int hand = o->handed ? ((i - row_start) & 1 ? 1 : -1) : 0;
        hands_wrong += x->hand != hand;
        if (i < n0 && w0[i].facade == x->facade) {
            depth_moved = fmax(depth_moved, fmax(fabs(x->v0 - w0[i].v0), fabs(x->v1 - w0[i].v1)));
            /* the edited window grew from its world min: a window of its hand kept that side
             * in the facade's frame, a mirror image the other side (it grew the other way) */
            int keep_min = (x->hand == edited_hand) == grows_from_min;
            double a1 = keep_min ? x->u : x->u + x->along,
                   a0 = keep_min ? w0[i].u : w0[i].u + w0[i].along;
            anchor_moved = fmax(anchor_moved, fabs(a1 - a0));
        }
        /* inside its facade's wall along the facade (front 0..L, right 0..D, left -D..0)
         * and in height */
        double lo = x->facade == 2 ? -bb_depth(o) : 0,
               hi = lo + (x->facade ? bb_depth(o) : bb_length(o));
        outside = fmax(outside, fmax(fmax(lo - x->u, x->u + x->along - hi), 0));
        outside = fmax(outside, fmax(x->box.max[2] - bb_height(o), -x->box.min[2]));
        for (size_t j = 0; j < i; j++) {
            const bb_part *y = &w1[j].box;
            double gap = -INFINITY;
            for (int a = 0; a < 3; a++)
                gap = fmax(gap, fmax(y->min[a] - x->box.max[a], x->box.min[a] - y->max[a]));
            min_gap = fmin(min_gap, gap);
        }
    }
    print_message("  %-40s %s x%.1f wide x%.1f tall: %zu windows (were %zu), size error "
                  "%.4f, hands wrong %zu, anchor moved %.2g, depth moved %.2g, outside %.2g, gap "
                  "%.3f\n",
                  o->name, what, WINDOW_WIDER, WINDOW_TALLER, n1, n0, size_err, hands_wrong,
                  anchor_moved, depth_moved, outside, min_gap);
    int ok = n1 == n0 && !memcmp(per_facade0, per_facade1, sizeof per_facade0) &&
             size_err <= 0.01 && !hands_wrong && anchor_moved <= 1e-4 && depth_moved <= 1e-4 &&
             outside <= 1e-4 && min_gap > 0;
    if (!ok)
        print_error("%s %s: %zu windows (were %zu), size error %.4f, %zu with the "
                    "wrong hand, the fixed side moved %.3g, depth moved %.3g, outside its wall "
                    "%.3g, gap %.3f\n",
                    o->name, what, n1, n0, size_err, hands_wrong, anchor_moved, depth_moved,
                    outside, min_gap);
    assert_grammar_derives_mesh(ed, what);
    free(w0);
    free(w1);
    ag_edit_model_free(ed);
    ag_edit_model_free(em);
    ag_mesh_free(m);
    return ok;
}

/* Every variant measured (its figures printed) before the test fails on any. */
static void a_window_resize_reaches_every_window(void **state)
{
    (void)state;
    size_t failed = 0;
    for (size_t i = 0; i < sizeof variants / sizeof *variants; i++)
        for (int facade = 0; facade < (variants[i].side_cols ? 2 : 1); facade++)
            for (unsigned col = 0; col < 2; col++)
                failed += !resize_one_window(&variants[i], facade, col);
    if (failed)
        fail_msg("%zu window resizes did not reach every window", failed);
}

static void every_variant_keeps_its_structure(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof variants / sizeof *variants; i++)
        run_variant(&variants[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_variant_keeps_its_structure),
        cmocka_unit_test(a_window_resize_reaches_every_window),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
