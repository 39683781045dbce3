/* Component labeling: equal shapes share a label, quarter turns are found and stored. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/label.h"

static int32_t label_of_group(const ag_mesh *m, const ag_labels *L, const char *name, int *rot)
{
    for (size_t c = 0; c < m->ncomponents; c++) {
        int32_t g = m->component_group[c];
        if (g >= 0 && !strcmp(m->group_names[g], name)) {
            if (rot)
                *rot = L->rot[c];
            return L->label[c];
        }
    }
    fail_msg("no group %s", name);
    return -1;
}

static void test_windows_share_a_label_across_turned_facades(void **state)
{
    (void)state;
    ag_mesh *m;
    ag_gen_facade_options o = {.cols = 6, .rows = 4, .side_cols = 3, .back = 1, .left = 1,
                               .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    ag_labels *L;
    assert_int_equal(ag_label_components(m, NULL, &L, NULL), AG_OK);
    int r0, r1, r2, r3;
    int32_t w = label_of_group(m, L, "window_front_0_0", &r0);
    assert_int_equal(label_of_group(m, L, "window_front_5_3", NULL), w);
    assert_int_equal(label_of_group(m, L, "window_right_2_1", &r1), w);
    assert_int_equal(label_of_group(m, L, "window_back_1_1", &r2), w);
    assert_int_equal(label_of_group(m, L, "window_left_0_2", &r3), w);
    /* the facades are turned by 90, 180, 270 degrees from the front */
    assert_int_equal((r1 - r0) & 3, 1);
    assert_int_equal((r2 - r0) & 3, 2);
    assert_int_equal((r3 - r0) & 3, 3);
    /* 24 + 12 + 24 + 12 windows */
    assert_int_equal(L->count[w], 72);
    /* front and back walls match turned by 180, the annex is alone */
    int a, b;
    assert_int_equal(label_of_group(m, L, "wall_front", &a), label_of_group(m, L, "wall_back", &b));
    assert_int_equal((b - a) & 3, 2);
    int32_t annex = label_of_group(m, L, "annex", NULL);
    assert_int_equal(L->count[annex], 1);
    assert_int_not_equal(annex, w);
    /* labels: window, front/back wall, side walls, roof, annex */
    assert_int_equal(L->nlabels, 5);

    ag_label_options no = {.no_rotation = 1};
    ag_labels *L2;
    assert_int_equal(ag_label_components(m, &no, &L2, NULL), AG_OK);
    assert_int_not_equal(label_of_group(m, L2, "window_front_0_0", NULL),
                         label_of_group(m, L2, "window_right_0_0", NULL));
    ag_labels_free(L2);
    ag_labels_free(L);
    ag_mesh_free(m);
}

static void test_tolerance_is_relative_to_the_diagonal(void **state)
{
    (void)state;
    /* two triangles, one moved by 1e-4 of its size in one vertex */
    ag_mesh *m = ag_mesh_create();
    size_t c;
    for (int k = 0; k < 2; k++) {
        ag_mesh_add_component(m, -1, &c);
        double x = 10.0 * k;
        ag_mesh_add_vertex(m, x, 0, 0);
        ag_mesh_add_vertex(m, x + 1, 0, 0);
        ag_mesh_add_vertex(m, x, 1 + (k ? 2e-4 : 0), 1);
        ag_mesh_add_triangle(m, (uint32_t)(3 * k), (uint32_t)(3 * k + 1), (uint32_t)(3 * k + 2),
                             (uint32_t)c);
    }
    ag_labels *L;
    ag_label_options strict = {.tolerance = 1e-6};
    assert_int_equal(ag_label_components(m, &strict, &L, NULL), AG_OK);
    assert_int_equal(L->nlabels, 2);
    ag_labels_free(L);
    ag_label_options loose = {.tolerance = 1e-4}; /* diagonal ~11: 1.1e-3 absolute */
    assert_int_equal(ag_label_components(m, &loose, &L, NULL), AG_OK);
    assert_int_equal(L->nlabels, 1);
    assert_true(L->tol > 1e-3 && L->tol < 1.2e-3);
    ag_labels_free(L);
    ag_mesh_free(m);
}

static void test_same_box_different_shape_differs(void **state)
{
    (void)state;
    /* same triangle count and box, different geometry inside */
    ag_mesh *m = ag_mesh_create();
    size_t c;
    for (int k = 0; k < 2; k++) {
        ag_mesh_add_component(m, -1, &c);
        double x = 5.0 * k;
        uint32_t b = (uint32_t)m->nverts;
        ag_mesh_add_vertex(m, x, 0, 0);
        ag_mesh_add_vertex(m, x + 1, 0, 0);
        ag_mesh_add_vertex(m, x, 1, 0);
        ag_mesh_add_vertex(m, x + (k ? 0.3 : 0.7), 0.5, 1);
        ag_mesh_add_triangle(m, b, b + 1, b + 3, (uint32_t)c);
        ag_mesh_add_triangle(m, b + 1, b + 2, b + 3, (uint32_t)c);
    }
    ag_labels *L;
    assert_int_equal(ag_label_components(m, NULL, &L, NULL), AG_OK);
    assert_int_equal(L->nlabels, 2);
    ag_labels_free(L);
    ag_mesh_free(m);
}

static void test_match_triangles(void **state)
{
    (void)state;
    double a[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, /**/ 5, 5, 5, 6, 5, 5, 5, 6, 5};
    /* same triangles, other order, vertices cyclically shifted, tiny noise */
    double b[18] = {6, 5, 5, 5, 6, 5, 5, 5, 5.0000001, /**/ 0, 1, 0, 0, 0, 0, 1, 0, 0};
    size_t miss = 9;
    double w = ag_label_match_triangles(a, 2, b, 2, 1e-6, &miss);
    assert_int_equal(miss, 0);
    assert_true(w > 0.9e-7 && w < 1.1e-7);
    /* reversed orientation does not match */
    double c[9] = {0, 0, 0, 0, 1, 0, 1, 0, 0};
    ag_label_match_triangles(a, 2, c, 1, 1e-6, &miss);
    assert_int_equal(miss, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_windows_share_a_label_across_turned_facades),
        cmocka_unit_test(test_tolerance_is_relative_to_the_diagonal),
        cmocka_unit_test(test_same_box_different_shape_differs),
        cmocka_unit_test(test_match_triangles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
