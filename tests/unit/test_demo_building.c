#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/demo_building.h"

/* Every edge of a component is used once in each direction: closed, consistently oriented. */
static void assert_closed(const ag_mesh *m, uint32_t comp)
{
    size_t n = 0;
    uint64_t *edges = malloc(3 * m->ntris * sizeof *edges);
    for (size_t t = 0; t < m->ntris; t++)
        if (m->tri_component[t] == comp)
            for (int k = 0; k < 3; k++)
                edges[n++] = (uint64_t)m->tri[3 * t + k] << 32 | m->tri[3 * t + (k + 1) % 3];
    assert_true(n > 0);
    for (size_t i = 0; i < n; i++) {
        uint64_t rev = edges[i] << 32 | edges[i] >> 32;
        int fwd = 0, back = 0;
        for (size_t j = 0; j < n; j++) {
            fwd += edges[j] == edges[i];
            back += edges[j] == rev;
        }
        assert_int_equal(fwd, 1);
        assert_int_equal(back, 1);
    }
    free(edges);
}

/* Signed volume (divergence theorem): positive when the faces point outwards. */
static double volume(const ag_mesh *m, uint32_t comp)
{
    double v = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        if (m->tri_component[t] != comp)
            continue;
        const double *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                     *c = m->pos + 3 * m->tri[3 * t + 2];
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    }
    return v;
}

static void component_size(const ag_mesh *m, uint32_t comp, double *size, size_t *ntris)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    *ntris = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        if (m->tri_component[t] != comp)
            continue;
        ++*ntris;
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) {
                double x = m->pos[3 * m->tri[3 * t + k] + a];
                lo[a] = fmin(lo[a], x);
                hi[a] = fmax(hi[a], x);
            }
    }
    for (int a = 0; a < 3; a++)
        size[a] = hi[a] - lo[a];
}

static void check_common(const ag_mesh *m)
{
    assert_true(m->ntris > 0 && m->nverts > 0);
    assert_int_equal(m->ncomponents, m->ngroups);
    for (size_t c = 0; c < m->ncomponents; c++) {
        assert_int_equal(m->component_group[c], (int32_t)c);
        assert_true(strlen(m->group_names[c]) > 0);
        for (size_t d = 0; d < c; d++)
            assert_string_not_equal(m->group_names[c], m->group_names[d]);
        assert_closed(m, (uint32_t)c);
        assert_true(volume(m, (uint32_t)c) > 0);
    }
    for (size_t i = 0; i < 3 * m->ntris; i++)
        assert_true(m->tri[i] < m->nverts);
}

static size_t count_prefix(const ag_mesh *m, const char *prefix, double *size, size_t *ntris)
{
    size_t n = 0;
    for (size_t c = 0; c < m->ncomponents; c++) {
        if (strncmp(m->group_names[c], prefix, strlen(prefix)))
            continue;
        double s[3];
        size_t nt;
        component_size(m, (uint32_t)c, s, &nt);
        if (n == 0) {
            memcpy(size, s, sizeof s);
            *ntris = nt;
        }
        /* Repeated elements are the same shape. */
        for (int a = 0; a < 3; a++)
            assert_true(fabs(s[a] - size[a]) < 1e-9);
        assert_int_equal(nt, *ntris);
        n++;
    }
    return n;
}

static void test_row_house(void **state)
{
    ag_mesh *m = ag_demo_building(0);
    assert_non_null(m);
    assert_string_equal(ag_demo_building_name(0), "Row house");
    check_common(m);
    ag_box b = ag_mesh_bounds(m);
    assert_true(b.max[0] - b.min[0] >= 12 && b.max[0] - b.min[0] < 13);
    assert_true(b.max[1] - b.min[1] >= 8 && b.max[1] - b.min[1] < 9);
    assert_true(b.max[2] > 6 && b.max[2] < 10 && b.min[2] < 0.01);
    double size[3];
    size_t nt;
    assert_int_equal(count_prefix(m, "window_", size, &nt), 12);
    assert_true(size[0] > 0.5 && size[0] < 2 && size[2] > 0.5 && size[2] < 2);
    assert_int_equal(count_prefix(m, "wall_front", size, &nt), 1);
    assert_true(size[0] == 12 && size[2] == 6 && size[1] < 0.5); /* a thin slab */
    assert_int_equal(count_prefix(m, "wall_back", size, &nt), 1);
    assert_int_equal(count_prefix(m, "wall_left", size, &nt), 1);
    assert_int_equal(count_prefix(m, "wall_right", size, &nt), 1);
    assert_int_equal(count_prefix(m, "roof_", size, &nt), 2);
    assert_int_equal(count_prefix(m, "door", size, &nt), 1);
    assert_int_equal(count_prefix(m, "floor", size, &nt), 1);
    ag_mesh_free(m);
}

static void test_tower(void **state)
{
    ag_mesh *m = ag_demo_building(1);
    assert_non_null(m);
    assert_string_equal(ag_demo_building_name(1), "Tower");
    check_common(m);
    double size[3];
    size_t nt;
    assert_int_equal(count_prefix(m, "column_", size, &nt), 24);
    assert_int_equal(count_prefix(m, "slab_", size, &nt), 3);
    assert_int_equal(count_prefix(m, "roof", size, &nt), 1);
    ag_box b = ag_mesh_bounds(m);
    assert_true(b.max[2] > 10);
    ag_mesh_free(m);
}

static void test_out_of_range(void **state)
{
    assert_null(ag_demo_building(-1));
    assert_null(ag_demo_building(2));
    assert_null(ag_demo_building_name(2));
    assert_null(ag_demo_building_name(-1));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_row_house),
        cmocka_unit_test(test_tower),
        cmocka_unit_test(test_out_of_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
