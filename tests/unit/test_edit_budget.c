/* The edit budget (core/edit/edit.h): a resize counts what its emission would place before
 * making any of it, so a limit exactly at the result's size lets it through and one below
 * refuses it with nothing made — checked against the mesh the same resize makes without a
 * budget, on the demo buildings and generated facades, each as given, far from the origin
 * (UTM-sized coordinates), turned a quarter about z and jittered; a budget's callback stops an
 * edit; paste and the re-proceduralization honour the limits too. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/demo_building.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"

typedef enum { AS_GIVEN, FAR_AWAY, TURNED, JITTERED, VARIANTS } variant;

static const char *const variant_names[] = {"as given", "far away", "turned", "jittered"};

/* A copy of m moved as the variant says. */
static ag_mesh *varied(const ag_mesh *m, variant v)
{
    ag_mesh *c = ag_mesh_clone(m);
    assert_non_null(c);
    unsigned seed = 12345;
    for (size_t i = 0; i < c->nverts; i++) {
        double *p = &c->pos[3 * i];
        if (v == FAR_AWAY) {
            p[0] += 512345.25;
            p[1] += 5712345.5;
            p[2] += 41;
        } else if (v == TURNED) {
            double x = p[0];
            p[0] = -p[1];
            p[1] = x;
        } else if (v == JITTERED) {
            for (int k = 0; k < 3; k++) {
                seed = seed * 1103515245u + 12345u;
                p[k] += 1e-7 * ((double)(seed >> 8) / (1u << 24) - 0.5);
            }
        }
    }
    return c;
}

static ag_edit_model *model_of(const ag_mesh *m)
{
    ag_edit_model *em = NULL;
    ag_error err;
    if (ag_edit_model_create(m, NULL, &em, &err) != AG_OK)
        fail_msg("proceduralize: %s", err.text);
    return em;
}

/* The largest visible node: a wall or a slab. */
static int32_t largest_visible(const ag_proceduralize_result *r)
{
    int32_t best = 0;
    double bv = -1;
    for (size_t i = 0; i < r->tree->nnodes; i++) {
        const ag_tnode *n = &r->tree->nodes[i];
        if (n->kind != AG_NODE_COMPONENT)
            continue;
        double v = 0;
        for (int a = 0; a < 3; a++)
            v += n->box.max[a] - n->box.min[a];
        if (v > bv) {
            bv = v;
            best = (int32_t)i;
        }
    }
    return best;
}

/* The resize with no budget, then with limits at its size (let through, the same size) and
 * one below (refused, nothing made). */
static void check_estimate(const ag_edit_model *em, const ag_edit_op *base, const char *what)
{
    ag_edit_op op = *base;
    ag_mesh *free_run = NULL;
    ag_error err;
    ag_status s = ag_edit_resize(em->proc, &op, &free_run, NULL, &err);
    if (s != AG_OK)
        fail_msg("%s: %s", what, err.text);
    size_t tris = free_run->ntris, comps = free_run->ncomponents;
    ag_mesh_free(free_run);

    ag_edit_budget at = {.max_triangles = tris, .max_components = comps};
    op.budget = &at;
    ag_mesh *out = NULL;
    if (ag_edit_resize(em->proc, &op, &out, NULL, &err) != AG_OK)
        fail_msg("%s: refused at its own size (%zu triangles, %zu components): %s", what, tris,
                 comps, err.text);
    assert_int_equal(out->ntris, tris);
    assert_int_equal(out->ncomponents, comps);
    ag_mesh_free(out);

    ag_edit_budget below_tris = {.max_triangles = tris - 1};
    op.budget = &below_tris;
    out = NULL;
    assert_int_equal(ag_edit_resize(em->proc, &op, &out, NULL, &err), AG_ERR_RESULT_TOO_LARGE);
    assert_null(out);
    assert_non_null(strstr(err.text, "triangles"));

    if (comps > 1) {
        ag_edit_budget below_comps = {.max_components = comps - 1};
        op.budget = &below_comps;
        assert_int_equal(ag_edit_resize(em->proc, &op, &out, NULL, &err),
                         AG_ERR_RESULT_TOO_LARGE);
        assert_null(out);
        assert_non_null(strstr(err.text, "terminals"));
    }
}

static void estimates_match_what_the_resize_makes(void **state)
{
    (void)state;
    ag_mesh *sources[4];
    sources[0] = ag_demo_building(0);
    sources[1] = ag_demo_building(1);
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 4, .rows = 3}, &sources[2],
                                   NULL),
                     AG_OK);
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 3, .rows = 2, .side_cols = 2,
                                                             .back = 1, .left = 1, .annex = 1},
                                   &sources[3], NULL),
                     AG_OK);
    static const double scales[][3] = {{4, 1, 1}, {2, 2, 1}, {3, 1, 1.5}, {0.5, 1, 1}};
    for (size_t m = 0; m < 4; m++) {
        assert_non_null(sources[m]);
        for (variant v = 0; v < VARIANTS; v++) {
            ag_mesh *mesh = varied(sources[m], v);
            ag_edit_model *em = model_of(mesh);
            for (size_t k = 0; k < sizeof scales / sizeof scales[0]; k++) {
                char what[96];
                ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 0, .has_scale = 1,
                                 .scale = {scales[k][0], scales[k][1], scales[k][2]}};
                snprintf(what, sizeof what, "building %zu %s, root × [%g %g %g]", m,
                         variant_names[v], op.scale[0], op.scale[1], op.scale[2]);
                check_estimate(em, &op, what);
                /* the same on the largest visible node (the solve, then the emission) */
                op.node = largest_visible(em->proc);
                snprintf(what, sizeof what, "building %zu %s, node %d × [%g %g %g]", m,
                         variant_names[v], (int)op.node, op.scale[0], op.scale[1], op.scale[2]);
                check_estimate(em, &op, what);
            }
            ag_edit_model_free(em);
            ag_mesh_free(mesh);
        }
        ag_mesh_free(sources[m]);
    }
}

/* The demo Tower stretched [4,1,1], [50,1,1], [20,20,1] would pass 17 million triangles: the
 * count stops at the limit, long before. */
static void a_runaway_stretch_is_refused_before_it_is_made(void **state)
{
    (void)state;
    ag_mesh *tower = ag_demo_building(1);
    ag_edit_model *em = model_of(tower);
    ag_mesh_free(tower);
    static const double chain[][3] = {{4, 1, 1}, {50, 1, 1}};
    ag_error err;
    for (size_t i = 0; i < 2; i++) {
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 0, .has_scale = 1,
                         .scale = {chain[i][0], chain[i][1], chain[i][2]}};
        ag_edit_model *next = NULL;
        assert_int_equal(ag_edit_apply_ex(em, &op, 0, &next, NULL, &err), AG_OK);
        ag_edit_model_free(em);
        em = next;
    }
    ag_edit_budget b = {.max_triangles = 2000000, .max_components = 200000};
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 0, .has_scale = 1, .scale = {20, 20, 1},
                     .budget = &b};
    ag_edit_model *next = NULL;
    assert_int_equal(ag_edit_apply_ex(em, &op, 0, &next, NULL, &err), AG_ERR_RESULT_TOO_LARGE);
    assert_null(next);
    assert_non_null(strstr(err.text, "more than"));
    ag_edit_model_free(em);
}

static int calls;
static int stop_after(void *user)
{
    return ++calls > *(int *)user;
}

static void a_budget_callback_stops_the_edit(void **state)
{
    (void)state;
    ag_mesh *house = ag_demo_building(0);
    ag_edit_model *em = model_of(house);
    ag_mesh_free(house);
    ag_error err;
    /* stopped at each place it is asked: the emission, then each stage of proceduralizing */
    for (int allowed = 0; allowed < 8; allowed++) {
        calls = 0;
        ag_edit_budget b = {.cancelled = stop_after, .user = &allowed};
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 0, .has_scale = 1, .scale = {2, 1, 1},
                         .budget = &b};
        ag_edit_model *next = NULL;
        ag_status s = ag_edit_apply_ex(em, &op, 0, &next, NULL, &err);
        if (calls > allowed) {
            assert_int_equal(s, AG_ERR_CANCELLED);
            assert_null(next);
        } else {
            assert_int_equal(s, AG_OK); /* asked fewer times than it would allow */
            ag_edit_model_free(next);
        }
    }
    ag_edit_model_free(em);
}

static void paste_and_proceduralize_honour_the_limits(void **state)
{
    (void)state;
    ag_mesh *f = NULL;
    assert_int_equal(ag_gen_facade(&(ag_gen_facade_options){.cols = 3, .rows = 2}, &f, NULL),
                     AG_OK);
    ag_edit_model *em = model_of(f);
    /* fill the wall with copies of a window: a few hundred copies */
    int32_t wall = largest_visible(em->proc), win = -1;
    for (size_t i = 0; i < em->proc->tree->nnodes && win < 0; i++)
        if (em->proc->tree->nodes[i].kind == AG_NODE_COMPONENT && (int32_t)i != wall)
            win = (int32_t)i;
    int32_t src[1] = {win};
    ag_edit_op op = {.kind = AG_EDIT_PASTE, .node = wall, .nnodes = 1, .nodes = src,
                     .placement = AG_EDIT_INSERT, .fit = AG_EDIT_FILL};
    ag_error err;
    ag_mesh *free_run = NULL;
    if (ag_edit_paste(em->proc, &op, &free_run, NULL, &err) != AG_OK)
        fail_msg("paste: %s", err.text);
    size_t tris = free_run->ntris, comps = free_run->ncomponents;
    ag_mesh_free(free_run);
    /* the copies alone pass the limit: refused before they are made */
    assert_true(tris > em->proc->mesh->ntris);
    ag_edit_budget small = {.max_triangles = (tris - em->proc->mesh->ntris) / 2};
    op.budget = &small;
    ag_mesh *out = NULL;
    assert_int_equal(ag_edit_paste(em->proc, &op, &out, NULL, &err), AG_ERR_RESULT_TOO_LARGE);
    assert_null(out);
    /* the whole result past a limit: the applied edit stops before proceduralizing it */
    ag_edit_budget few = {.max_components = comps - 1};
    op.budget = &few;
    ag_edit_model *next = NULL;
    assert_int_equal(ag_edit_apply_ex(em, &op, 0, &next, NULL, &err), AG_ERR_RESULT_TOO_LARGE);
    assert_null(next);
    ag_edit_model_free(em);
    ag_mesh_free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(estimates_match_what_the_resize_makes),
        cmocka_unit_test(a_runaway_stretch_is_refused_before_it_is_made),
        cmocka_unit_test(a_budget_callback_stops_the_edit),
        cmocka_unit_test(paste_and_proceduralize_honour_the_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
