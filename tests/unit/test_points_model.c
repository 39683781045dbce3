/* Point models (§4.2-§5): a generated building proceduralized (segments, repetition,
 * consensus, split tree, rules, patterns, grammar), its grammar text and PLY terminals read
 * back and derived into the cloud again, and edits: a resize that doubles the front facade
 * doubles its windows at the input's density (windows counted and densities measured on the
 * derived points alone, by a geometric slab test), a paste turned to its destination (the
 * derived points' spread in the destination), bad ops
 * refused, hard clouds refused precisely. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/model_kept.h"
#include "app/points_state.h"
#include "core/base/uf.h"
#include "core/points/gen_building.h"
#include "core/points/pointedit.h"
#include "core/points/proceduralize_cloud.h"
#include "io/cloud_import.h"

#define SHARED AG_REPO_DIR "/../shared/data"

static ag_cloud *building(const ag_gen_building_options *o)
{
    ag_cloud *c;
    ag_error e;
    if (ag_gen_building(o, &c, &e) != AG_OK)
        fail_msg("gen_building: %s", e.text);
    return c;
}

static ag_proceduralize_cloud_result *proceduralize(ag_cloud *c)
{
    ag_proceduralize_cloud_result *r;
    ag_error e;
    if (ag_proceduralize_cloud_run(c, NULL, &r, &e) != AG_OK)
        fail_msg("proceduralize: %s", e.text);
    return r;
}

static ag_cloud *derive(const ag_pointmodel *pm)
{
    ag_cloud *d;
    ag_pointmodel_derive_info info;
    ag_error e;
    if (ag_pointmodel_derive(pm, 0, &d, &info, &e) != AG_OK)
        fail_msg("derive: %s", e.text);
    return d;
}

/* What the front (y = 0 in the building's frame, not turned) shows in a cloud with absolute
 * coordinates xyz + offset - origin: the windows, counted as connected blobs of glass points
 * (a slab 0.15..0.35 m behind the wall) on a 0.2 m grid in x and z, and the points per m² of
 * the glass and of the wall (|y| < 0.04 m, over x in [x0, x1], z in [z0, z1] minus the
 * glass). Independent of the model: only positions are read. */
typedef struct {
    size_t windows;
    double glass_density, wall_density;
    double x_extent;
} front_view;

static front_view look_at_front(const ag_cloud *c, const double origin[3], double z_max)
{
    front_view v = {0};
    const double cell = 0.2;
    double xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < c->n; i++) {
        double y = c->xyz[3 * i + 1] + c->offset[1] - origin[1];
        double z = c->xyz[3 * i + 2] + c->offset[2] - origin[2];
        if (fabs(y) < 0.04 && z > 0.3 && z < z_max) {
            double x = c->xyz[3 * i] + c->offset[0] - origin[0];
            xmin = fmin(xmin, x);
            xmax = fmax(xmax, x);
        }
    }
    v.x_extent = xmax - xmin;
    size_t nx = (size_t)ceil((xmax - xmin) / cell) + 1, nz = (size_t)ceil(z_max / cell) + 1;
    size_t *count = calloc(nx * nz, sizeof *count);
    size_t wall = 0, glass = 0;
    for (size_t i = 0; i < c->n; i++) {
        double x = c->xyz[3 * i] + c->offset[0] - origin[0];
        double y = c->xyz[3 * i + 1] + c->offset[1] - origin[1];
        double z = c->xyz[3 * i + 2] + c->offset[2] - origin[2];
        if (x < xmin + 0.3 || x > xmax - 0.3 || z < 0.3 || z > z_max)
            continue; /* off the side walls */
        if (y > 0.15 && y < 0.35) {
            count[(size_t)((x - xmin) / cell) * nz + (size_t)(z / cell)]++;
            glass++;
        } else if (fabs(y) < 0.04) {
            wall++;
        }
    }
    /* blobs: 4-connected occupied cells (at least 2 points) */
    ag_uf ufs, *uf = &ufs;
    assert_int_equal(ag_uf_init(uf, nx * nz, 0), AG_OK);
    size_t occupied = 0;
    for (size_t a = 0; a < nx; a++)
        for (size_t b = 0; b < nz; b++) {
            if (count[a * nz + b] < 2)
                continue;
            occupied++;
            if (a + 1 < nx && count[(a + 1) * nz + b] >= 2)
                ag_uf_union(uf, (uint32_t)(a * nz + b), (uint32_t)((a + 1) * nz + b));
            if (b + 1 < nz && count[a * nz + b + 1] >= 2)
                ag_uf_union(uf, (uint32_t)(a * nz + b), (uint32_t)(a * nz + b + 1));
        }
    size_t *blob = calloc(nx * nz, sizeof *blob);
    for (size_t k = 0; k < nx * nz; k++)
        if (count[k] >= 2)
            blob[ag_uf_find(uf, (uint32_t)k)] += 1;
    for (size_t k = 0; k < nx * nz; k++)
        v.windows += blob[k] >= 10; /* a 1.2 x 1.5 m pane covers about 40 cells */
    /* areas: the glass as its occupied cells, the wall the rest of the band */
    double glass_area = (double)occupied * cell * cell;
    double band = (xmax - xmin - 0.6) * (z_max - 0.3);
    v.glass_density = glass / glass_area;
    v.wall_density = wall / (band - glass_area);
    free(blob);
    ag_uf_free(uf);
    free(count);
    return v;
}

static void test_proceduralize_and_read_back(void **state)
{
    (void)state;
    const ag_gen_building_options vs[] = {
        {.points = 100000, .cols = 5, .rows = 2, .seed = 31},
        {.points = 100000, .cols = 4, .rows = 3, .rotation = 33, .window = AG_GEN_WINDOW_PROUD,
         .origin = {431207.5, 5411732.25, 300}, .seed = 32},
    };
    for (size_t v = 0; v < sizeof vs / sizeof *vs; v++) {
        ag_cloud *c = building(&vs[v]);
        ag_cloud *input;
        assert_int_equal(ag_cloud_clone(c, &input, NULL), AG_OK);
        ag_proceduralize_cloud_result *r = proceduralize(c);
        ag_pointmodel *pm = r->model;
        print_message("building %zu: %zu terminals, %zu placements, %zu consensus labels, "
                      "%zu rules, %zu patterns\n",
                      v, pm->nterminals, pm->nplacements, r->ncompletion,
                      pm->em->proc->grammar ? pm->em->proc->grammar->nrules : 0,
                      pm->em->proc->tree->npatterns);
        assert_true(r->ncompletion >= 1);
        /* the windows of the front and back (one size) are one consensus label */
        size_t most = 0;
        for (size_t k = 0; k < r->ncompletion; k++)
            if (r->completion[k].members > most)
                most = r->completion[k].members;
        assert_true(most >= 2 * (size_t)vs[v].cols * vs[v].rows * 9 / 10);
        /* the grammar text and its PLY terminals, read back and derived */
        ag_points_state st = {0};
        ag_error e;
        if (ag_points_state_make(pm, &st, &e) != AG_OK)
            fail_msg("state: %s", e.text);
        assert_non_null(strstr(st.text, ".ply\""));
        ag_cloud *d = derive(st.pm);
        ag_pointmodel_fidelity f;
        assert_int_equal(ag_pointmodel_compare(input, d, 2 * r->seg->spacing, &f, &e), AG_OK);
        print_message("  read back: %zu derived points of %zu, coverage %.4f, precision %.4f\n",
                      d->n, input->n, f.coverage, f.precision);
        assert_true(f.coverage >= 0.97);
        assert_true(f.precision >= 0.97);
        assert_true(d->n >= input->n * 9 / 10 && d->n <= input->n * 11 / 10);
        /* the same offset back: coordinates in the input's system */
        for (int a = 0; a < 3; a++)
            assert_true(fabs(d->offset[a] + d->xyz[a] - (input->offset[a] + input->xyz[a])) < 100);
        ag_cloud_free(d);
        ag_points_state_clear(&st);
        ag_proceduralize_cloud_free(r);
        ag_cloud_free(input);
        ag_cloud_free(c);
    }
}

static void test_resize_doubles_the_windows_at_the_density(void **state)
{
    (void)state;
    /* a flat roof: the front is the whole x extent */
    ag_gen_building_options o = {.points = 150000, .width = 16, .depth = 8, .height = 7,
                                 .ridge = -1, .cols = 5, .rows = 2, .seed = 41,
                                 .origin = {85000, 446000, 0}};
    ag_cloud *c = building(&o);
    front_view before = look_at_front(c, o.origin, o.height - 0.3);
    print_message("input front: %zu windows, glass %.1f / m², wall %.1f / m², %.2f m wide\n",
                  before.windows, before.glass_density, before.wall_density, before.x_extent);
    assert_int_equal(before.windows, (size_t)o.cols * o.rows);
    ag_proceduralize_cloud_result *r = proceduralize(c);
    ag_pointmodel *pm = r->model;
    /* the front wall's node: long in x, thin in y, at y = 0 */
    const ag_splittree *t = pm->em->proc->tree;
    int32_t wall = -1;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_box *b = &t->nodes[n].box;
        double y0 = b->min[1] + pm->offset[1] - o.origin[1];
        if (t->nodes[n].component >= 0 && b->max[0] - b->min[0] > 0.9 * o.width &&
            b->max[1] - b->min[1] < 0.6 && fabs(y0) < 0.2 && b->max[2] - b->min[2] > 0.9 * o.height)
            wall = (int32_t)n;
    }
    assert_true(wall >= 0);
    ag_box nb = t->nodes[wall].box;
    nb.max[0] = nb.min[0] + 2 * (nb.max[0] - nb.min[0]);
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = wall, .has_box = 1, .box = nb};
    ag_pointmodel *out;
    ag_edit_report rep = {0};
    ag_error e;
    if (ag_pointedit_apply(pm, &op, NULL, &out, &rep, &e) != AG_OK)
        fail_msg("resize: %s", e.text);
    print_message("resize: %zu equations, %zu unknowns, %zu splits, max residual %.3g m; "
                  "%zu placements (from %zu)\n",
                  rep.equations, rep.unknowns, rep.splits, rep.max_residual, out->nplacements,
                  pm->nplacements);
    ag_cloud *d = derive(out);
    front_view after = look_at_front(d, o.origin, o.height - 0.3);
    print_message("resized front: %zu windows, glass %.1f / m², wall %.1f / m², %.2f m wide\n",
                  after.windows, after.glass_density, after.wall_density, after.x_extent);
    assert_true(fabs(after.x_extent - 2 * before.x_extent) < 0.5);
    assert_int_equal(after.windows, 2 * before.windows);
    assert_true(fabs(after.glass_density / before.glass_density - 1) <= 0.1);
    assert_true(fabs(after.wall_density / before.wall_density - 1) <= 0.1);
    /* a slight stretch (under 1.5) keeps the windows, stretched, density still kept */
    nb = t->nodes[wall].box;
    nb.max[0] = nb.min[0] + 1.3 * (nb.max[0] - nb.min[0]);
    ag_edit_op small = {.kind = AG_EDIT_RESIZE, .node = wall, .has_box = 1, .box = nb};
    ag_pointmodel *out2;
    ag_edit_report rep2 = {0};
    if (ag_pointedit_apply(pm, &small, NULL, &out2, &rep2, &e) != AG_OK)
        fail_msg("resize 1.3: %s", e.text);
    ag_cloud *d2 = derive(out2);
    front_view s = look_at_front(d2, o.origin, o.height - 0.3);
    print_message("stretched 1.3: %zu windows, glass %.1f / m², wall %.1f / m², %.2f m wide\n",
                  s.windows, s.glass_density, s.wall_density, s.x_extent);
    assert_int_equal(s.windows, before.windows);
    assert_true(fabs(s.x_extent - 1.3 * before.x_extent) < 0.5);
    assert_true(fabs(s.wall_density / before.wall_density - 1) <= 0.1);
    ag_cloud_free(d2);
    ag_pointmodel_free(out2);
    ag_edit_report_clear(&rep2);
    ag_cloud_free(d);
    ag_pointmodel_free(out);
    ag_edit_report_clear(&rep);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

/* The front window's node whose box is about w x h on the facade: thin in `thin` (0: x, 1: y),
 * its lowest-z one with the smallest coordinate along the facade. */
static int32_t window_node(const ag_pointmodel *pm, int thin, double w, double h)
{
    const ag_splittree *t = pm->em->proc->tree;
    int32_t best = -1;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_box *b = &t->nodes[n].box;
        double e[3] = {b->max[0] - b->min[0], b->max[1] - b->min[1], b->max[2] - b->min[2]};
        int along = 1 - thin;
        if (t->nodes[n].component < 0 || e[thin] > 0.6 || fabs(e[along] - w) > 0.3 ||
            fabs(e[2] - h) > 0.3)
            continue;
        if (best < 0 || b->min[2] < t->nodes[best].box.min[2] - 0.5 ||
            (fabs(b->min[2] - t->nodes[best].box.min[2]) < 0.5 &&
             b->min[along] < t->nodes[best].box.min[along]))
            best = (int32_t)n;
    }
    return best;
}

/* A paste of a front window onto a side window: turned to face the side (its glass spread
 * along y, one plane in x), measured on the derived points inside the side window's box
 * (less a margin that leaves the reveals out). */
static void test_paste_turns_to_the_target(void **state)
{
    (void)state;
    ag_gen_building_options o = {.points = 120000, .width = 16, .depth = 10, .height = 7,
                                 .ridge = -1, .cols = 4, .rows = 2, .side_cols = 2, .seed = 71};
    ag_cloud *c = building(&o);
    ag_proceduralize_cloud_result *r = proceduralize(c);
    ag_pointmodel *pm = r->model;
    int32_t src = window_node(pm, 1, 1.2 + 0.2, 1.5 + 0.2);
    int32_t dst = window_node(pm, 0, 1.2 + 0.2, 1.5 + 0.2);
    print_message("front window node %d, side window node %d\n", src, dst);
    assert_true(src >= 0 && dst >= 0);
    ag_box db = pm->em->proc->tree->nodes[dst].box;
    int32_t nodes[1] = {src};
    ag_edit_op op = {.kind = AG_EDIT_PASTE, .node = dst, .nnodes = 1, .nodes = nodes,
                     .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_FILL};
    ag_pointmodel *out;
    ag_edit_report rep = {0};
    ag_error e;
    if (ag_pointedit_apply(pm, &op, NULL, &out, &rep, &e) != AG_OK)
        fail_msg("paste: %s", e.text);
    print_message("paste: %s\n", rep.message);
    ag_cloud *d = derive(out);
    /* the derived points in the side window's box (less a margin): spread along y, the glass
     * and reveals' depth in x */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t in = 0;
    for (size_t i = 0; i < d->n; i++) {
        const double *p = d->xyz + 3 * i;
        if (p[0] < db.min[0] || p[0] > db.max[0] || p[1] < db.min[1] + 0.15 ||
            p[1] > db.max[1] - 0.15 || p[2] < db.min[2] + 0.15 || p[2] > db.max[2] - 0.15)
            continue;
        in++;
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], p[a]);
            hi[a] = fmax(hi[a], p[a]);
        }
    }
    print_message("%zu points in the side window's box: x %.2f, y %.2f, z %.2f m\n", in,
                  hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    assert_true(in > 100);
    /* the glass is one plane across x (unturned, the front window's glass squeezed into the
     * side's box would spread over its depth) */
    assert_true(hi[0] - lo[0] < 0.1);
    assert_true(hi[1] - lo[1] > 0.8);
    ag_cloud_free(d);
    ag_pointmodel_free(out);
    ag_edit_report_clear(&rep);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

/* The proxy label name of node n (its placement's terminal), "" for invisible nodes. */
static const char *proxy_name(const ag_pointmodel *pm, int32_t n)
{
    const ag_tnode *x = &pm->em->proc->tree->nodes[n];
    const ag_mesh *m = pm->em->proc->mesh;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 || m->component_group[x->component] < 0)
        return "";
    return m->group_names[m->component_group[x->component]];
}

/* The terminal node n places (its component's variant: a terminal of the model), NULL for
 * invisible nodes. */
static const ag_pointmodel_terminal *placed(const ag_pointmodel *pm, int32_t n)
{
    const ag_tnode *x = &pm->em->proc->tree->nodes[n];
    const ag_labels *L = pm->em->proc->labels;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 ||
        (size_t)x->component >= L->ncomponents)
        return NULL;
    int32_t v = L->variant[x->component];
    return v >= 0 && (size_t)v < pm->nterminals ? &pm->terminals[v] : NULL;
}

/* Every visible node of a but those `gone` (NULL: none) has its id in b, on the same box and
 * placing the same terminal; returns how many. */
static size_t ids_kept(const ag_pointmodel *a, const ag_pointmodel *b, const uint8_t *gone,
                       const char *what)
{
    const ag_splittree *ta = a->em->proc->tree, *tb = b->em->proc->tree;
    size_t kept = 0;
    for (size_t n = 0; n < ta->nnodes; n++) {
        if (ta->nodes[n].kind != AG_NODE_COMPONENT || (gone && gone[n]))
            continue;
        if (n >= tb->nnodes || tb->nodes[n].kind != AG_NODE_COMPONENT)
            fail_msg("%s: node %zu (%s) lost its id", what, n, proxy_name(a, (int32_t)n));
        for (int k = 0; k < 3; k++)
            if (fabs(ta->nodes[n].box.min[k] - tb->nodes[n].box.min[k]) > 1e-6 ||
                fabs(ta->nodes[n].box.max[k] - tb->nodes[n].box.max[k]) > 1e-6)
                fail_msg("%s: node %zu names another box", what, n);
        const ag_pointmodel_terminal *pa = placed(a, (int32_t)n), *pb = placed(b, (int32_t)n);
        if (!pa || !pb || pa->points->n != pb->points->n ||
            fabs(pa->size[0] - pb->size[0]) + fabs(pa->size[1] - pb->size[1]) +
                    fabs(pa->size[2] - pb->size[2]) > 1e-9)
            fail_msg("%s: node %zu placed %zu points, now %zu", what, n,
                     pa ? pa->points->n : 0, pb ? pb->points->n : 0);
        kept++;
    }
    return kept;
}

/* A point edit keeps the ids of the nodes it leaves alone (issue 14 §4), in its result and in
 * the state the service keeps (read back through the grammar text): a window removed is dead,
 * every other visible node has its id, box and terminal. */
static void test_point_edits_keep_ids(void **state)
{
    (void)state;
    ag_gen_building_options o = {.points = 60000, .width = 12, .depth = 8, .height = 7,
                                 .ridge = -1, .cols = 3, .rows = 2, .seed = 43};
    ag_cloud *c = building(&o);
    ag_proceduralize_cloud_result *r = proceduralize(c);
    ag_points_state st0 = {0};
    ag_error e;
    if (ag_points_state_make(r->model, &st0, &e) != AG_OK)
        fail_msg("state: %s", e.text);
    ag_pointmodel *pm = st0.pm; /* as the service holds it */
    const ag_splittree *t = pm->em->proc->tree;
    int32_t win = window_node(pm, 1, 1.2 + 0.2, 1.5 + 0.2);
    assert_true(win > 0);
    uint8_t *gone = calloc(t->nnodes, 1);
    gone[win] = 1;
    int32_t nodes[1] = {win};
    ag_edit_op rm = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = nodes};
    ag_pointmodel *out = NULL;
    if (ag_pointedit_apply(pm, &rm, NULL, &out, NULL, &e) != AG_OK)
        fail_msg("remove: %s", e.text);
    size_t visible = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        visible += t->nodes[n].kind == AG_NODE_COMPONENT;
    ag_points_state st = {0};
    if (ag_points_state_make(out, &st, &e) != AG_OK)
        fail_msg("state after the remove: %s", e.text);
    if (ag_pointedit_keep_ids(st.pm, pm, &rm, NULL, &e) != AG_OK)
        fail_msg("keep ids: %s", e.text);
    assert_int_equal(ids_kept(pm, st.pm, gone, "remove a window, read back"), visible - 1);
    const ag_splittree *t1 = st.pm->em->proc->tree;
    assert_true((size_t)win >= t1->nnodes || t1->nodes[win].kind != AG_NODE_COMPONENT);
    /* and a second edit on the state so kept: another window removed */
    int32_t win2 = window_node(st.pm, 1, 1.2 + 0.2, 1.5 + 0.2);
    assert_true(win2 > 0 && win2 != win);
    uint8_t *gone2 = calloc(t1->nnodes, 1);
    gone2[win2] = 1;
    nodes[0] = win2;
    ag_pointmodel *out2 = NULL;
    if (ag_pointedit_apply(st.pm, &rm, NULL, &out2, NULL, &e) != AG_OK)
        fail_msg("second remove: %s", e.text);
    ag_points_state st2 = {0};
    if (ag_points_state_make(out2, &st2, &e) != AG_OK)
        fail_msg("state after the second remove: %s", e.text);
    if (ag_pointedit_keep_ids(st2.pm, st.pm, &rm, NULL, &e) != AG_OK)
        fail_msg("keep ids: %s", e.text);
    assert_int_equal(ids_kept(st.pm, st2.pm, gone2, "remove another window"), visible - 2);
    gone[win2] = 1;
    assert_int_equal(ids_kept(pm, st2.pm, gone, "both removes"), visible - 2);
    /* what the state derives is the model less the two windows: its placements */
    assert_int_equal(st2.pm->nplacements, pm->nplacements - 2);
    ag_points_state_clear(&st2);
    ag_pointmodel_free(out2);
    free(gone2);
    ag_points_state_clear(&st);
    ag_pointmodel_free(out);
    free(gone);
    ag_points_state_clear(&st0);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

/* Every visible node of a has its id in b, visible, its box within `far` of its old one (no node
 * takes the id of one elsewhere); returns how many. */
static size_t ids_kept_near(const ag_pointmodel *a, const ag_pointmodel *b, double far,
                            const char *what)
{
    const ag_splittree *ta = a->em->proc->tree, *tb = b->em->proc->tree;
    size_t kept = 0;
    for (size_t n = 0; n < ta->nnodes; n++) {
        if (ta->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        if (n >= tb->nnodes || tb->nodes[n].kind != AG_NODE_COMPONENT)
            fail_msg("%s: node %zu (%s) lost its id", what, n, proxy_name(a, (int32_t)n));
        for (int k = 0; k < 3; k++)
            if (fabs(ta->nodes[n].box.min[k] - tb->nodes[n].box.min[k]) > far ||
                fabs(ta->nodes[n].box.max[k] - tb->nodes[n].box.max[k]) > far)
                fail_msg("%s: node %zu moved %g m on axis %d", what, n,
                         fmax(fabs(ta->nodes[n].box.min[k] - tb->nodes[n].box.min[k]),
                              fabs(ta->nodes[n].box.max[k] - tb->nodes[n].box.max[k])),
                         k);
        kept++;
    }
    return kept;
}

static int box_near(const ag_box *a, const ag_box *b, double eps)
{
    for (int k = 0; k < 3; k++)
        if (fabs(a->min[k] - b->min[k]) > eps || fabs(a->max[k] - b->max[k]) > eps)
            return 0;
    return 1;
}

/* op applied to pm, read back as the service keeps it and numbered after pm. */
static void edit_kept(ag_pointmodel *pm, const ag_edit_op *op, ag_points_state *st,
                      ag_pointmodel **out)
{
    ag_error e;
    if (ag_pointedit_apply(pm, op, NULL, out, NULL, &e) != AG_OK)
        fail_msg("edit: %s", e.text);
    if (ag_points_state_make(*out, st, &e) != AG_OK ||
        ag_pointedit_keep_ids(st->pm, pm, op, NULL, &e) != AG_OK)
        fail_msg("state after the edit: %s", e.text);
}

/* The building both id tests edit: proceduralized, its state made, its visible nodes counted,
 * and the id of a first-floor window of its front. */
static int32_t ids_building(ag_cloud **c, ag_proceduralize_cloud_result **r, ag_points_state *st0,
                            size_t *visible)
{
    ag_gen_building_options o = {.points = 60000, .width = 12, .depth = 8, .height = 7,
                                 .ridge = -1, .cols = 3, .rows = 2, .seed = 43};
    *c = building(&o);
    *r = proceduralize(*c);
    ag_error e;
    if (ag_points_state_make((*r)->model, st0, &e) != AG_OK)
        fail_msg("state: %s", e.text);
    const ag_splittree *t = st0->pm->em->proc->tree;
    *visible = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        *visible += t->nodes[n].kind == AG_NODE_COMPONENT;
    int32_t win = window_node(st0->pm, 1, 1.2 + 0.2, 1.5 + 0.2);
    assert_true(win > 0);
    return win;
}

/* A node an edit changed but did not remove keeps its id (issue 14 §4), found where the edit
 * put it: a resized window and the front windows of its rule, resized with it, keep their ids
 * with their new boxes; a split window keeps its id with its lower half, and its upper half is
 * a new node after every old id; a join keeps every node, its members too. */
static void test_moved_nodes_keep_ids(void **state)
{
    (void)state;
    ag_cloud *c = NULL;
    ag_proceduralize_cloud_result *r = NULL;
    ag_points_state st0 = {0};
    size_t visible = 0;
    int32_t win = ids_building(&c, &r, &st0, &visible);
    ag_pointmodel *pm = st0.pm;
    const ag_splittree *t = pm->em->proc->tree;
    const ag_tnode *w = &t->nodes[win];
    ag_box asked = w->box;
    asked.max[0] += 0.1;
    asked.max[2] += 0.1;
    ag_edit_op grow = {.kind = AG_EDIT_RESIZE, .node = win, .has_box = 1, .box = asked};
    ag_points_state st = {0};
    ag_pointmodel *out = NULL;
    edit_kept(pm, &grow, &st, &out);
    assert_int_equal(ids_kept_near(pm, st.pm, 0.2, "resize a window"), visible);
    const ag_splittree *t1 = st.pm->em->proc->tree;
    assert_true(box_near(&t1->nodes[win].box, &asked, 1e-3));
    /* the front windows of its rule went with it, each at its id */
    size_t mates = 0;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if ((int32_t)n == win || x->kind != AG_NODE_COMPONENT || x->rule != w->rule ||
            fabs((x->box.max[1] - x->box.min[1]) - (w->box.max[1] - w->box.min[1])) > 1e-3 ||
            fabs((x->box.max[0] - x->box.min[0]) - (w->box.max[0] - w->box.min[0])) > 1e-3)
            continue;
        ag_box want = x->box;
        want.max[0] += 0.1;
        want.max[2] += 0.1;
        if (!box_near(&t1->nodes[n].box, &want, 1e-3))
            fail_msg("window node %zu was not resized with node %d", n, win);
        mates++;
    }
    print_message("window node %d resized with %zu of its rule\n", win, mates);
    assert_true(mates >= 2);
    /* a split of that window at its middle: the lower half keeps its id, the upper one is new */
    const ag_box wb = t1->nodes[win].box;
    double mid = (wb.min[0] + wb.max[0]) / 2;
    ag_edit_op split = {.kind = AG_EDIT_SPLIT, .node = win, .axis = 0, .at = mid};
    ag_points_state st2 = {0};
    ag_pointmodel *out2 = NULL;
    edit_kept(st.pm, &split, &st2, &out2);
    assert_int_equal(ids_kept_near(st.pm, st2.pm, wb.max[0] - mid + 1e-3, "split a window"),
                     visible);
    const ag_splittree *t2 = st2.pm->em->proc->tree;
    ag_box lower = wb, upper = wb;
    lower.max[0] = upper.min[0] = mid;
    assert_true(box_near(&t2->nodes[win].box, &lower, 1e-3));
    size_t uppers = 0;
    for (size_t n = 0; n < t2->nnodes; n++)
        if (t2->nodes[n].kind == AG_NODE_COMPONENT && box_near(&t2->nodes[n].box, &upper, 1e-3)) {
            assert_true(n >= t1->nnodes);
            uppers++;
        }
    assert_int_equal(uppers, 1);
    /* a join of the lower half and the next window of its row: a point join keeps its
     * placements where they were (a point model has no joined terminal), so every node keeps
     * its id, box and points, the two joined windows too, and nothing is added */
    int32_t next = -1;
    for (size_t n = 0; n < t2->nnodes; n++) {
        const ag_tnode *x = &t2->nodes[n];
        if ((int32_t)n != win && x->kind == AG_NODE_COMPONENT &&
            fabs((x->box.max[0] - x->box.min[0]) - (wb.max[0] - wb.min[0])) < 1e-3 &&
            fabs(x->box.min[2] - lower.min[2]) < 1e-3 &&
            fabs(x->box.min[1] - lower.min[1]) < 1e-3 && x->box.min[0] > lower.max[0] &&
            (next < 0 || x->box.min[0] < t2->nodes[next].box.min[0]))
            next = (int32_t)n;
    }
    assert_true(next > 0);
    int32_t sel[2] = {win, next};
    ag_edit_op join = {.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = sel};
    ag_points_state st3 = {0};
    ag_pointmodel *out3 = NULL;
    edit_kept(st2.pm, &join, &st3, &out3);
    const ag_splittree *t3 = st3.pm->em->proc->tree;
    assert_int_equal(ids_kept(st2.pm, st3.pm, NULL, "join two windows"), visible + 1);
    for (size_t n = t2->nnodes; n < t3->nnodes; n++)
        if (t3->nodes[n].kind == AG_NODE_COMPONENT)
            fail_msg("join two windows: node %zu is new", n);
    ag_points_state_clear(&st3);
    ag_pointmodel_free(out3);
    ag_points_state_clear(&st2);
    ag_pointmodel_free(out2);
    ag_points_state_clear(&st);
    ag_pointmodel_free(out);
    ag_points_state_clear(&st0);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

/* The state kept as the store keeps it (its text, its terminals and its kept tree) reads back
 * numbered as it was saved, and a second edit of what was read back keeps the ids again: the
 * service's round trip between two ops and over a restart (app/store_ws_points.c). */
static void test_point_ids_survive_reload(void **state)
{
    (void)state;
    ag_cloud *c = NULL;
    ag_proceduralize_cloud_result *r = NULL;
    ag_points_state st0 = {0};
    size_t visible = 0;
    int32_t win = ids_building(&c, &r, &st0, &visible);
    ag_pointmodel *pm = st0.pm;
    const ag_splittree *t = pm->em->proc->tree;
    ag_error e;
    uint8_t *gone = calloc(t->nnodes, 1);
    gone[win] = 1;
    int32_t nodes[1] = {win};
    ag_edit_op rm = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = nodes};
    ag_pointmodel *out = NULL;
    if (ag_pointedit_apply(pm, &rm, NULL, &out, NULL, &e) != AG_OK)
        fail_msg("remove: %s", e.text);
    ag_points_state st = {0};
    if (ag_points_state_make(out, &st, &e) != AG_OK ||
        ag_pointedit_keep_ids(st.pm, pm, &rm, NULL, &e) != AG_OK)
        fail_msg("state after the remove: %s", e.text);
    /* stored and read back */
    char *kept = ag_model_kept_tree_text(st.pm->em);
    assert_non_null(kept);
    ag_pointmodel *back = NULL;
    long col = 0;
    if (ag_points_state_read(st.text, st.text_len, ag_terminals_set_lookup, &st.terms, &back,
                             &e, &col) != AG_OK ||
        ag_points_state_reload_kept(back, kept, &e) != AG_OK)
        fail_msg("read back: %s", e.text);
    assert_int_equal(ids_kept(pm, back, gone, "read back with its kept tree"), visible - 1);
    /* without the kept tree, the text numbers the nodes afresh: what the service served */
    ag_pointmodel *plain = NULL;
    if (ag_points_state_read(st.text, st.text_len, ag_terminals_set_lookup, &st.terms, &plain,
                             &e, &col) != AG_OK)
        fail_msg("read back: %s", e.text);
    const ag_splittree *tp = plain->em->proc->tree;
    assert_true((size_t)win < tp->nnodes && tp->nodes[win].kind == AG_NODE_COMPONENT);
    /* a second edit of what was read back: another window removed, the ids kept again */
    int32_t win2 = window_node(back, 1, 1.2 + 0.2, 1.5 + 0.2);
    assert_true(win2 > 0 && win2 != win);
    nodes[0] = win2;
    ag_pointmodel *out2 = NULL;
    if (ag_pointedit_apply(back, &rm, NULL, &out2, NULL, &e) != AG_OK)
        fail_msg("second remove: %s", e.text);
    ag_points_state st2 = {0};
    if (ag_points_state_make(out2, &st2, &e) != AG_OK ||
        ag_pointedit_keep_ids(st2.pm, back, &rm, NULL, &e) != AG_OK)
        fail_msg("state after the second remove: %s", e.text);
    gone[win2] = 1;
    assert_int_equal(ids_kept(pm, st2.pm, gone, "both removes, read back between"), visible - 2);
    assert_int_equal(st2.pm->nplacements, pm->nplacements - 2);
    /* a stored tree that is not one over the model is refused, never trusted */
    char *other = ag_model_kept_tree_text(pm->em);
    assert_int_equal(ag_points_state_reload_kept(plain, other, &e), AG_ERR_PARSE);
    free(other);
    ag_points_state_clear(&st2);
    ag_pointmodel_free(out2);
    ag_pointmodel_free(plain);
    ag_pointmodel_free(back);
    free(kept);
    ag_points_state_clear(&st);
    ag_pointmodel_free(out);
    free(gone);
    ag_points_state_clear(&st0);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

static void test_bad_ops(void **state)
{
    (void)state;
    ag_gen_building_options o = {.points = 50000, .cols = 3, .rows = 2, .seed = 51};
    ag_cloud *c = building(&o);
    ag_proceduralize_cloud_result *r = proceduralize(c);
    ag_pointmodel *out = NULL;
    ag_error e;
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 99999, .has_scale = 1, .scale = {2, 1, 1}};
    assert_int_not_equal(ag_pointedit_apply(r->model, &op, NULL, &out, NULL, &e), AG_OK);
    assert_null(out);
    print_message("unknown node: %s\n", e.text);
    ag_edit_op neg = {.kind = AG_EDIT_RESIZE, .node = AG_EDIT_ROOT, .has_scale = 1,
                      .scale = {-1, 1, 1}};
    assert_int_not_equal(ag_pointedit_apply(r->model, &neg, NULL, &out, NULL, &e), AG_OK);
    assert_null(out);
    print_message("negative scale: %s\n", e.text);
    ag_proceduralize_cloud_free(r);
    ag_cloud_free(c);
}

/* Hard cases give precise errors, never a model of nothing. */
static void test_hard_clouds(void **state)
{
    (void)state;
    ag_error e;
    ag_proceduralize_cloud_result *r = NULL;
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_proceduralize_cloud_run(c, NULL, &r, &e), AG_ERR_EMPTY);
    assert_null(r);
    assert_int_equal(ag_cloud_resize(c, 1, NULL), AG_OK);
    c->xyz[0] = c->xyz[1] = c->xyz[2] = 1;
    assert_int_not_equal(ag_proceduralize_cloud_run(c, NULL, &r, &e), AG_OK);
    assert_null(r);
    print_message("one point: %s\n", e.text);
    ag_cloud_free(c);
    /* a NaN among good points */
    ag_gen_building_options o = {.points = 20000, .cols = 2, .rows = 1, .seed = 61};
    c = building(&o);
    c->xyz[3 * 777 + 1] = NAN;
    assert_int_equal(ag_proceduralize_cloud_run(c, NULL, &r, &e), AG_ERR_PARSE);
    assert_null(r);
    print_message("NaN: %s\n", e.text);
    assert_non_null(strstr(e.text, "point 778")); /* 1-based */
    ag_cloud_free(c);
    /* points on a line */
    c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, 500, NULL), AG_OK);
    for (size_t i = 0; i < 500; i++) {
        c->xyz[3 * i] = 0.01 * (double)i;
        c->xyz[3 * i + 1] = c->xyz[3 * i + 2] = 0;
    }
    ag_status s = ag_proceduralize_cloud_run(c, NULL, &r, &e);
    print_message("collinear: %s\n", s ? e.text : "a model");
    if (s == AG_OK) {
        /* a model of a line is fine as long as it gives the line back */
        ag_cloud *d = derive(r->model);
        assert_true(d->n >= 450);
        ag_cloud_free(d);
        ag_proceduralize_cloud_free(r);
    } else {
        assert_null(r);
    }
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_proceduralize_and_read_back),
        cmocka_unit_test(test_resize_doubles_the_windows_at_the_density),
        cmocka_unit_test(test_paste_turns_to_the_target),
        cmocka_unit_test(test_point_edits_keep_ids),
        cmocka_unit_test(test_point_ids_survive_reload),
        cmocka_unit_test(test_moved_nodes_keep_ids),
        cmocka_unit_test(test_bad_ops),
        cmocka_unit_test(test_hard_clouds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
