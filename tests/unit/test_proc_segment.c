/* Segmentation into components: validation, loose parts, planar fallback. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/segment.h"

/* Axis-aligned box with 8 shared vertices and 12 triangles in component comp. */
static void add_box(ag_mesh *m, double x0, double y0, double z0, double x1, double y1, double z1,
                    uint32_t comp)
{
    uint32_t b = (uint32_t)m->nverts;
    for (int i = 0; i < 8; i++)
        assert_int_equal(ag_mesh_add_vertex(m, i & 1 ? x1 : x0, i & 2 ? y1 : y0, i & 4 ? z1 : z0),
                         AG_OK);
    static const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int i = 0; i < 12; i++)
        assert_int_equal(ag_mesh_add_triangle(m, b + f[i][0], b + f[i][1], b + f[i][2], comp), AG_OK);
}

static void test_rejects_bad_input(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create(), *out = NULL;
    ag_error err = {0};
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, &err), AG_ERR_EMPTY);
    assert_null(out);
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_vertex(m, 0, 0, 0);
    ag_mesh_add_vertex(m, 1, 0, 0);
    ag_mesh_add_vertex(m, 0, 1, 0);
    ag_mesh_add_triangle(m, 0, 1, 7, 0); /* bad index */
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, &err), AG_ERR_INVALID);
    assert_int_equal(err.element, 1);
    assert_non_null(strstr(err.text, "vertex 8"));
    m->tri[2] = 2;
    m->pos[4] = NAN;
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, &err), AG_ERR_INVALID);
    assert_int_equal(err.element, 2);
    m->pos[4] = 0;
    m->tri_component[0] = 5; /* component out of range */
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, &err), AG_ERR_INVALID);
    m->tri_component[0] = 0;
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, &err), AG_OK);
    assert_int_equal(out->ncomponents, 1);
    ag_mesh_free(out);
    ag_mesh_free(m);
}

static void test_sole_group_with_loose_parts_is_split(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create(), *out = NULL;
    size_t g, c;
    ag_mesh_add_group(m, "temple", &g);
    ag_mesh_add_component(m, (int32_t)g, &c);
    for (int i = 0; i < 5; i++)
        add_box(m, 3.0 * i, 0, 0, 3.0 * i + 1, 1, 4, 0); /* five loose columns */
    add_box(m, -1, -1, 4, 14, 2, 5, 0);                  /* the roof, also loose */
    ag_segment_info info;
    assert_int_equal(ag_segment_run(m, NULL, &out, &info, NULL), AG_OK);
    assert_int_equal(out->ncomponents, 6);
    assert_int_equal(info.groups_split, 1);
    assert_int_equal(out->ntris, m->ntris);
    for (size_t i = 0; i < out->ncomponents; i++)
        assert_int_equal(out->component_group[i], 0);
    /* triangle order and vertices are kept */
    for (size_t t = 0; t < 3 * m->ntris; t++)
        assert_int_equal(out->tri[t], m->tri[t]);
    ag_mesh_free(out);

    ag_segment_options o = {.keep_groups = 1};
    assert_int_equal(ag_segment_run(m, &o, &out, &info, NULL), AG_OK);
    assert_int_equal(out->ncomponents, 1);
    ag_mesh_free(out);
    ag_mesh_free(m);
}

static void test_group_of_distinct_parts_stays_whole(void **state)
{
    (void)state;
    /* two groups: a window made of three different loose pieces stays one component */
    ag_mesh *m = ag_mesh_create(), *out = NULL;
    size_t g0, g1, c0, c1;
    ag_mesh_add_group(m, "Window_1", &g0);
    ag_mesh_add_group(m, "Wall_1", &g1);
    ag_mesh_add_component(m, (int32_t)g0, &c0);
    ag_mesh_add_component(m, (int32_t)g1, &c1);
    add_box(m, 0, 0, 0, 1, 0.1, 0.1, 0);
    add_box(m, 0, 0, 0.2, 1, 0.1, 1.5, 0);
    add_box(m, 0, 0, 1.6, 1.2, 0.2, 1.7, 0);
    add_box(m, -2, -1, -1, 5, 0, 5, 1);
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, NULL), AG_OK);
    assert_int_equal(out->ncomponents, 2);
    ag_mesh_free(out);
    ag_mesh_free(m);
}

static void test_single_piece_falls_back_to_planes(void **state)
{
    (void)state;
    ag_mesh *m = ag_mesh_create(), *out = NULL;
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    add_box(m, 0, 0, 0, 2, 3, 4, 0);
    ag_segment_info info;
    assert_int_equal(ag_segment_run(m, NULL, &out, &info, NULL), AG_OK);
    assert_true(info.planar_fallback);
    assert_int_equal(out->ncomponents, 6); /* the six faces */
    size_t counts[6];
    ag_mesh_component_triangle_counts(out, counts);
    for (int i = 0; i < 6; i++)
        assert_int_equal(counts[i], 2);
    ag_mesh_free(out);
    ag_mesh_free(m);
}

static void test_generated_building_keeps_groups(void **state)
{
    (void)state;
    ag_mesh *m, *out;
    ag_gen_facade_options o = {.annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    assert_int_equal(ag_segment_run(m, NULL, &out, NULL, NULL), AG_OK);
    assert_int_equal(out->ncomponents, m->ncomponents);
    ag_mesh_free(out);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rejects_bad_input),
        cmocka_unit_test(test_sole_group_with_loose_parts_is_split),
        cmocka_unit_test(test_group_of_distinct_parts_stays_whole),
        cmocka_unit_test(test_single_piece_falls_back_to_planes),
        cmocka_unit_test(test_generated_building_keeps_groups),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
