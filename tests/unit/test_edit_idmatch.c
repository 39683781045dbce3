/* Ids matched after proceduralizing again (core/edit/idmatch.h) do not depend on the order the
 * new model lists its nodes in. A wall carries, on its own box, a casing of another label (as a
 * composed part's casing lies on the wall it is set into) and a pane of the casing's label that
 * is a box as the wall is: three nodes on one box, two of one label name. Windows beside them
 * and two identical sills on one box complete it. The same elements in other orders (shuffled)
 * are proceduralized and matched to the model as first proceduralized: every old node gets its
 * id back on a node of its label, box and shape (triangle count), checked against the
 * elements as generated, in every order. */
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
#include "core/edit/idmatch.h"
#include "core/proc/proceduralize.h"

/* One element: one or more boxes making one component. */
typedef struct {
    const char *group;
    size_t nboxes;
    double box[5][6]; /* x0 x1 y0 y1 z0 z1 */
} element;

/* The wall 6 x 0.3 x 3; the casing: four bars framing the wall's face, on the wall's box; two
 * windows on one box, their handles left and right (mirror images: one label); twin sills. */
static const element elements[] = {
    {"wall", 1, {{0, 6, 0, 0.3, 0, 3}}},
    {"casing", 4,
     {{0, 6, 0, 0.3, 0, 0.2}, {0, 6, 0, 0.3, 2.8, 3}, {0, 0.2, 0, 0.3, 0.2, 2.8},
      {5.8, 6, 0, 0.3, 0.2, 2.8}}},
    {"window_left", 2, {{1, 2, -0.1, 0, 1, 2}, {1.1, 1.25, -0.14, -0.1, 1.5, 1.65}}},
    {"window_right", 2, {{1, 2, -0.1, 0, 1, 2}, {1.75, 1.9, -0.14, -0.1, 1.5, 1.65}}},
    {"window_far", 2, {{4, 5, -0.1, 0, 1, 2}, {4.1, 4.25, -0.14, -0.1, 1.5, 1.65}}},
    {"sill", 1, {{2.5, 3.5, -0.2, 0, 0.8, 0.9}}},
    {"sill_twin", 1, {{2.5, 3.5, -0.2, 0, 0.8, 0.9}}},
};
#define NELEMENTS (sizeof elements / sizeof *elements)

static ag_mesh *generated(void)
{
    static const bb_options frame = {.name = "idmatch"};
    bb_gen g = {.m = ag_mesh_create(), .o = &frame};
    assert_non_null(g.m);
    for (size_t i = 0; i < NELEMENTS; i++) {
        const element *e = &elements[i];
        bb_begin(&g, e->group);
        for (size_t b = 0; b < e->nboxes; b++)
            bb_box(&g, e->box[b][0], e->box[b][1], e->box[b][2], e->box[b][3], e->box[b][4],
                   e->box[b][5]);
    }
    assert_false(g.fail);
    return g.m;
}

/* m with its components in the order `order` (groups, triangles and corners as they were). */
static ag_mesh *reordered(const ag_mesh *m, const size_t *order)
{
    ag_mesh *r = ag_mesh_create();
    assert_non_null(r);
    for (size_t k = 0; k < m->ngroups; k++) {
        size_t gi;
        assert_int_equal(ag_mesh_add_group(r, m->group_names[k], &gi), AG_OK);
        assert_int_equal(gi, k);
    }
    for (size_t i = 0; i < m->ncomponents; i++) {
        size_t c = order[i], comp;
        assert_int_equal(ag_mesh_add_component(r, m->component_group[c], &comp), AG_OK);
        for (size_t t = 0; t < m->ntris; t++) {
            if (m->tri_component[t] != c)
                continue;
            uint32_t base = (uint32_t)r->nverts;
            for (int k = 0; k < 3; k++) {
                const double *p = &m->pos[3 * m->tri[3 * t + k]];
                assert_int_equal(ag_mesh_add_vertex(r, p[0], p[1], p[2]), AG_OK);
            }
            assert_int_equal(ag_mesh_add_triangle(r, base, base + 1, base + 2, (uint32_t)comp),
                             AG_OK);
        }
    }
    return r;
}

static const char *name_of(const ag_proceduralize_result *r, int32_t n)
{
    const ag_tnode *x = &r->tree->nodes[n];
    const ag_mesh *m = r->mesh;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 ||
        m->component_group[x->component] < 0)
        return "";
    return m->group_names[m->component_group[x->component]];
}

/* What a visible node is, measured on its model's mesh: label name, box, triangle count and
 * the mean of its triangles' corners (which side the handle is on). */
typedef struct {
    char name[64];
    double lo[3], hi[3], mean[3];
    size_t ntris;
} measured;

static measured measure(const ag_proceduralize_result *r, int32_t n)
{
    measured s = {.lo = {INFINITY, INFINITY, INFINITY}, .hi = {-INFINITY, -INFINITY, -INFINITY}};
    const ag_mesh *m = r->mesh;
    uint32_t c = (uint32_t)r->tree->nodes[n].component;
    snprintf(s.name, sizeof s.name, "%s", name_of(r, n));
    for (size_t t = 0; t < m->ntris; t++) {
        if (m->tri_component[t] != c)
            continue;
        s.ntris++;
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) {
                double v = m->pos[3 * m->tri[3 * t + k] + a];
                s.lo[a] = fmin(s.lo[a], v);
                s.hi[a] = fmax(s.hi[a], v);
                s.mean[a] += v;
            }
    }
    for (int a = 0; a < 3 && s.ntris; a++)
        s.mean[a] /= 3.0 * s.ntris;
    return s;
}

static int same_measure(const measured *a, const measured *b)
{
    int same = !strcmp(a->name, b->name) && a->ntris == b->ntris;
    for (int k = 0; k < 3 && same; k++)
        same = fabs(a->lo[k] - b->lo[k]) < 1e-9 && fabs(a->hi[k] - b->hi[k]) < 1e-9 &&
               fabs(a->mean[k] - b->mean[k]) < 1e-9;
    return same;
}

/* A deterministic shuffle (xorshift) of 0..n-1. */
static void shuffle(size_t *order, size_t n, uint32_t *seed)
{
    for (size_t i = 0; i < n; i++)
        order[i] = i;
    for (size_t i = n - 1; i > 0; i--) {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 17;
        *seed ^= *seed << 5;
        size_t j = *seed % (i + 1);
        size_t t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
}

static void coincident_boxes_match_the_same_way_in_any_order(void **state)
{
    (void)state;
    ag_mesh *m0 = generated();
    ag_edit_model *first = NULL, *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_create(m0, NULL, &first, &err))
        fail_msg("proceduralize: %s", err.text);
    /* as the service keeps it: read back through its grammar, the mesh grouped by label */
    if (ag_edit_model_from_grammar(first->proc->grammar, &first->opt, &em, &err))
        fail_msg("read back: %s", err.text);
    const ag_proceduralize_result *old = em->proc;
    const ag_splittree *t0 = old->tree;
    const ag_mesh *om = old->mesh;
    measured *was = calloc(t0->nnodes, sizeof *was);
    size_t visible = 0;
    for (size_t n = 0; n < t0->nnodes; n++)
        if (t0->nodes[n].kind == AG_NODE_COMPONENT) {
            was[n] = measure(old, (int32_t)n);
            visible++;
        }
    assert_int_equal(visible, NELEMENTS);
    /* the ties are there: the windows share a label and a box, so do the sills */
    assert_true(om->ncomponents == NELEMENTS);
    size_t *order = malloc(om->ncomponents * sizeof *order);
    uint32_t seed = 2463534242u;
    size_t renumbered = 0;
    for (int round = 0; round < 32; round++) {
        shuffle(order, om->ncomponents, &seed);
        ag_mesh *m = reordered(om, order);
        ag_edit_model *fresh = NULL;
        if (ag_edit_model_create(m, &em->opt, &fresh, &err))
            fail_msg("round %d: proceduralize: %s", round, err.text);
        ag_proceduralize_result *r = NULL;
        ag_idmatch_report rep = {0};
        if (ag_idmatch_renumber(old, fresh->proc, NULL, &em->opt.patterns, &r, &rep, &err))
            fail_msg("round %d: match: %s", round, err.text);
        const ag_proceduralize_result *out = r ? r : fresh->proc;
        renumbered += r != NULL;
        const ag_splittree *t1 = out->tree;
        assert_true(t1->nnodes >= t0->nnodes);
        for (size_t n = 0; n < t0->nnodes; n++) {
            if (t0->nodes[n].kind != AG_NODE_COMPONENT)
                continue;
            if (t1->nodes[n].kind != AG_NODE_COMPONENT)
                fail_msg("round %d: node %zu (%s) lost its id", round, n, was[n].name);
            measured is = measure(out, (int32_t)n);
            if (!same_measure(&is, &was[n]))
                fail_msg("round %d: node %zu was %s (%zu triangles, mean x %.4f), is %s (%zu, "
                         "%.4f)",
                         round, n, was[n].name, was[n].ntris, was[n].mean[0], is.name, is.ntris,
                         is.mean[0]);
        }
        assert_int_equal(rep.kept, NELEMENTS);
        assert_int_equal(rep.appended, 0);
        assert_int_equal(rep.dead, 0);
        ag_proceduralize_result_free(r);
        ag_edit_model_free(fresh);
        ag_mesh_free(m);
    }
    /* the orders did number the new models otherwise: the matching had work to do */
    assert_true(renumbered > 0);
    free(order);
    free(was);
    ag_edit_model_free(em);
    ag_edit_model_free(first);
    ag_mesh_free(m0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(coincident_boxes_match_the_same_way_in_any_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
