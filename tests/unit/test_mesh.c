#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh.h"
#include "io/meshjson.h"

static void test_append_and_bounds(void **state)
{
    ag_mesh *m = ag_mesh_create();
    ag_box b = ag_mesh_bounds(m);
    assert_true(isinf(b.min[0]) && b.min[0] > 0 && isinf(b.max[2]) && b.max[2] < 0);
    assert_true(ag_box_diagonal(&b) == 0);
    for (int i = 0; i < 1000; i++) /* crosses several reallocations */
        assert_int_equal(ag_mesh_add_vertex(m, i, -i, 0.5 * i), AG_OK);
    assert_int_equal(m->nverts, 1000);
    assert_true(m->pos[3 * 999] == 999 && m->pos[3 * 999 + 1] == -999);
    size_t c, g;
    assert_int_equal(ag_mesh_add_group(m, "roof", &g), AG_OK);
    assert_int_equal(g, 0);
    assert_int_equal(ag_mesh_add_component(m, 0, &c), AG_OK);
    assert_int_equal(c, 0);
    /* Bounds only count vertices that a triangle uses. */
    assert_int_equal(ag_mesh_add_triangle(m, 1, 2, 4, 0), AG_OK);
    b = ag_mesh_bounds(m);
    assert_true(b.min[0] == 1 && b.max[0] == 4 && b.min[1] == -4 && b.max[1] == -1);
    assert_true(b.min[2] == 0.5 && b.max[2] == 2);
    assert_true(fabs(ag_box_diagonal(&b) - sqrt(9 + 9 + 2.25)) < 1e-12);
    size_t counts[1];
    ag_mesh_component_triangle_counts(m, counts);
    assert_int_equal(counts[0], 1);
    ag_mesh_free(m);
    ag_mesh_free(NULL);
}

/* Component 0 = triangles A and C, which touch only through B of component 1. */
static ag_mesh *chain(void)
{
    ag_mesh *m = ag_mesh_create();
    for (int i = 0; i < 12; i++)
        ag_mesh_add_vertex(m, i, 0, 0);
    size_t g, c;
    ag_mesh_add_group(m, "a", &g);
    ag_mesh_add_group(m, "b", &g);
    ag_mesh_add_component(m, 0, &c);
    ag_mesh_add_component(m, 1, &c);
    ag_mesh_add_component(m, -1, &c); /* no triangles */
    ag_mesh_add_triangle(m, 0, 1, 2, 0);  /* A */
    ag_mesh_add_triangle(m, 2, 3, 4, 1);  /* B */
    ag_mesh_add_triangle(m, 4, 5, 6, 0);  /* C */
    ag_mesh_add_triangle(m, 7, 8, 9, 1);  /* D: B's other piece */
    ag_mesh_add_triangle(m, 6, 10, 11, 0); /* E: joins C */
    ag_mesh_add_triangle(m, 0, 2, 1, 0);  /* F: joins A */
    return m;
}

static void test_split_connected(void **state)
{
    ag_mesh *m = chain();
    assert_int_equal(ag_mesh_split_connected(m), AG_OK);
    /* Pieces in order of their first triangle: A(0) B(1) C(2) D(3). */
    assert_int_equal(m->ncomponents, 4);
    uint32_t want[6] = {0, 1, 2, 3, 2, 0};
    assert_memory_equal(m->tri_component, want, sizeof want);
    int32_t groups[4] = {0, 1, 0, 1};
    assert_memory_equal(m->component_group, groups, sizeof groups);
    /* Idempotent. */
    assert_int_equal(ag_mesh_split_connected(m), AG_OK);
    assert_int_equal(m->ncomponents, 4);
    assert_memory_equal(m->tri_component, want, sizeof want);
    ag_mesh_free(m);

    m = ag_mesh_create();
    assert_int_equal(ag_mesh_split_connected(m), AG_OK);
    assert_int_equal(m->ncomponents, 0);
    ag_mesh_free(m);
}

static void test_split_large_grid(void **state)
{
    /* 50 separate strips of 40 triangles each, triangles interleaved in one component. */
    ag_mesh *m = ag_mesh_create();
    size_t c;
    ag_mesh_add_component(m, -1, &c);
    for (int s = 0; s < 50; s++)
        for (int i = 0; i < 42; i++)
            ag_mesh_add_vertex(m, i, s, 0);
    for (uint32_t i = 0; i < 40; i++)
        for (uint32_t s = 0; s < 50; s++)
            ag_mesh_add_triangle(m, s * 42 + i, s * 42 + i + 1, s * 42 + i + 2, 0);
    assert_int_equal(ag_mesh_split_connected(m), AG_OK);
    assert_int_equal(m->ncomponents, 50);
    for (size_t t = 0; t < m->ntris; t++)
        assert_int_equal(m->tri_component[t], t % 50);
    ag_mesh_free(m);
}

static void test_compact_and_clone(void **state)
{
    ag_mesh *m = chain();
    size_t c;
    ag_mesh_add_component(m, 1, &c); /* component 3, empty */
    m->tri_component[3] = 3;          /* D moves to it */
    ag_mesh_compact_components(m);
    /* Components 0, 1, 3 remain → 0, 1, 2. */
    assert_int_equal(m->ncomponents, 3);
    uint32_t want[6] = {0, 1, 0, 2, 0, 0};
    assert_memory_equal(m->tri_component, want, sizeof want);
    int32_t groups[3] = {0, 1, 1};
    assert_memory_equal(m->component_group, groups, sizeof groups);

    ag_mesh *k = ag_mesh_clone(m);
    assert_non_null(k);
    assert_int_equal(k->nverts, m->nverts);
    assert_int_equal(k->ntris, m->ntris);
    assert_memory_equal(k->pos, m->pos, 3 * m->nverts * sizeof(double));
    assert_memory_equal(k->tri, m->tri, 3 * m->ntris * sizeof(uint32_t));
    assert_memory_equal(k->tri_component, m->tri_component, m->ntris * sizeof(uint32_t));
    assert_memory_equal(k->component_group, m->component_group, m->ncomponents * 4);
    assert_int_equal(k->ngroups, 2);
    assert_string_equal(k->group_names[1], "b");
    assert_ptr_not_equal(k->group_names[1], m->group_names[1]);
    /* The clone is independent and still growable. */
    assert_int_equal(ag_mesh_add_vertex(k, 1, 2, 3), AG_OK);
    assert_int_equal(ag_mesh_add_triangle(k, 0, 1, 12, 0), AG_OK);
    assert_int_equal(m->nverts, 12);
    ag_mesh_free(k);
    ag_mesh_free(m);

    ag_mesh *e = ag_mesh_create();
    k = ag_mesh_clone(e);
    assert_non_null(k);
    assert_int_equal(k->nverts, 0);
    ag_mesh_free(k);
    ag_mesh_free(e);
}

/* The JSON summary (io/meshjson.h) reports what the mesh holds. */
static void test_json_summary(void **state)
{
    ag_mesh *m = chain();
    json_t *j = ag_meshjson_summary(m);
    assert_non_null(j);
    assert_int_equal(json_integer_value(json_object_get(j, "vertices")), 12);
    assert_int_equal(json_integer_value(json_object_get(j, "triangles")), 6);
    assert_int_equal(json_integer_value(json_object_get(j, "components")), 3);
    assert_int_equal(json_integer_value(json_object_get(j, "groups")), 2);
    assert_string_equal(json_string_value(json_array_get(json_object_get(j, "group_names"), 1)),
                        "b");
    json_t *bounds = json_object_get(j, "bounds");
    assert_true(json_real_value(json_array_get(json_object_get(bounds, "max"), 0)) == 11);
    assert_true(json_real_value(json_array_get(json_object_get(bounds, "min"), 0)) == 0);
    assert_true(json_real_value(json_object_get(j, "diagonal")) == 11);
    json_decref(j);
    ag_mesh_free(m);
    m = ag_mesh_create();
    j = ag_meshjson_summary(m);
    assert_non_null(j);
    assert_true(json_is_null(json_object_get(json_object_get(j, "bounds"), "min")));
    assert_true(json_real_value(json_object_get(j, "diagonal")) == 0);
    json_decref(j);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_append_and_bounds),
        cmocka_unit_test(test_split_connected),
        cmocka_unit_test(test_split_large_grid),
        cmocka_unit_test(test_compact_and_clone),
        cmocka_unit_test(test_json_summary),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
