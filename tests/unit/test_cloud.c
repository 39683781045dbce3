/* The point cloud type: properties of every scalar type, conversions, subsets, origins. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/points/cloud.h"

static void test_properties(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    ag_error e = {0};
    assert_int_equal(ag_cloud_resize(c, 5, &e), AG_OK);
    size_t idx[AG_SCALAR_COUNT];
    const char *names[AG_SCALAR_COUNT] = {"i8", "u8", "i16", "u16", "i32", "u32", "i64", "u64", "f32", "f64"};
    for (int t = 0; t < AG_SCALAR_COUNT; t++)
        assert_int_equal(ag_cloud_add_property(c, names[t], (ag_scalar_type)t, &idx[t], &e), AG_OK);
    /* new values are zero; clamping and rounding per type */
    for (int t = 0; t < AG_SCALAR_COUNT; t++)
        assert_true(ag_cloud_get(&c->props[idx[t]], 4) == 0);
    ag_cloud_set(&c->props[idx[AG_SCALAR_INT8]], 0, -200);
    ag_cloud_set(&c->props[idx[AG_SCALAR_UINT8]], 0, 300);
    ag_cloud_set(&c->props[idx[AG_SCALAR_UINT16]], 0, -5);
    ag_cloud_set(&c->props[idx[AG_SCALAR_INT32]], 0, 2.6);
    ag_cloud_set(&c->props[idx[AG_SCALAR_UINT32]], 0, NAN);
    ag_cloud_set(&c->props[idx[AG_SCALAR_INT64]], 0, -1e30);
    ag_cloud_set(&c->props[idx[AG_SCALAR_UINT64]], 0, 123456789012.0);
    ag_cloud_set(&c->props[idx[AG_SCALAR_FLOAT64]], 0, 0.1);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT8]], 0) == -128);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_UINT8]], 0) == 255);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_UINT16]], 0) == 0);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT32]], 0) == 3);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_UINT32]], 0) == 0);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT64]], 0) < -9e18);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_UINT64]], 0) == 123456789012.0);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_FLOAT64]], 0) == 0.1);
    /* duplicate, empty and over-long names are refused with a reason */
    assert_int_equal(ag_cloud_add_property(c, "u8", AG_SCALAR_UINT8, NULL, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "twice"));
    assert_int_equal(ag_cloud_add_property(c, "", AG_SCALAR_UINT8, NULL, &e), AG_ERR_INVALID);
    char longname[100];
    memset(longname, 'a', sizeof longname - 1);
    longname[99] = 0;
    assert_int_equal(ag_cloud_add_property(c, longname, AG_SCALAR_UINT8, NULL, &e), AG_ERR_INVALID);
    /* growth keeps values and zeroes the new points */
    ag_cloud_set(&c->props[idx[AG_SCALAR_INT16]], 4, -7);
    assert_int_equal(ag_cloud_resize(c, 1000, &e), AG_OK);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT16]], 4) == -7);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT16]], 999) == 0);
    /* shrinking then growing gives zeros again */
    assert_int_equal(ag_cloud_resize(c, 2, &e), AG_OK);
    assert_int_equal(ag_cloud_resize(c, 6, &e), AG_OK);
    assert_true(ag_cloud_get(&c->props[idx[AG_SCALAR_INT16]], 4) == 0);
    ag_cloud_remove_property(c, "i16");
    assert_null(ag_cloud_find(c, "i16"));
    assert_non_null(ag_cloud_find(c, "f64"));
    assert_int_equal(c->nprops, AG_SCALAR_COUNT - 1);
    /* the property limit */
    for (size_t k = c->nprops; k < AG_CLOUD_MAX_PROPERTIES; k++) {
        char nm[16];
        snprintf(nm, sizeof nm, "p%zu", k);
        assert_int_equal(ag_cloud_add_property(c, nm, AG_SCALAR_UINT8, NULL, &e), AG_OK);
    }
    assert_int_equal(ag_cloud_add_property(c, "one_more", AG_SCALAR_UINT8, NULL, &e), AG_ERR_TOO_LARGE);
    ag_cloud_free(c);
}

static void test_subset_and_origin(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    ag_error e = {0};
    assert_int_equal(ag_cloud_resize(c, 4, &e), AG_OK);
    assert_int_equal(ag_cloud_add_normals(c, &e), AG_OK);
    size_t cls;
    assert_int_equal(ag_cloud_add_property(c, "classification", AG_SCALAR_UINT8, &cls, &e), AG_OK);
    /* RD New sized absolute coordinates */
    const double abs_pts[4][3] = {{84808.25, 447412.5, 1.5}, {84900.125, 447500.75, 9.25},
                                  {84999.001, 447641.299, 19.398}, {84850.5, 447450.5, -0.568}};
    for (int i = 0; i < 4; i++) {
        memcpy(c->xyz + 3 * i, abs_pts[i], sizeof abs_pts[i]);
        c->normals[3 * i + 2] = 1;
        ag_cloud_set(&c->props[cls], (size_t)i, 2 + i);
    }
    double mn[3], mx[3], o[3];
    ag_cloud_bounds(c, mn, mx);
    ag_cloud_choose_origin(mn, mx, o);
    assert_true(o[0] == 84808 && o[1] == 447412 && o[2] == 0);
    ag_cloud_rebase(c, o);
    /* absolute coordinates are unchanged to well below a millimetre */
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++)
            assert_true(fabs(c->xyz[3 * i + a] + c->offset[a] - abs_pts[i][a]) < 1e-9);
    assert_true(c->xyz[0] < 1 && c->xyz[0] >= 0);
    uint32_t pick[2] = {2, 0};
    ag_cloud *s;
    assert_int_equal(ag_cloud_subset(c, pick, 2, &s, &e), AG_OK);
    assert_int_equal(s->n, 2);
    assert_true(s->offset[0] == c->offset[0]);
    assert_true(ag_cloud_get(ag_cloud_find(s, "classification"), 0) == 4);
    assert_true(ag_cloud_get(ag_cloud_find(s, "classification"), 1) == 2);
    assert_true(s->normals[2] == 1 && s->normals[5] == 1);
    assert_true(fabs(s->xyz[0] + s->offset[0] - abs_pts[2][0]) < 1e-9);
    /* small model coordinates keep a zero origin */
    double smn[3] = {-10, -5, 0}, smx[3] = {10, 5, 3};
    ag_cloud_choose_origin(smn, smx, o);
    assert_true(o[0] == 0 && o[1] == 0 && o[2] == 0);
    assert_true(ag_cloud_diagonal(s) > 200);
    /* non-finite positions are named */
    c->xyz[3 * 3 + 1] = NAN;
    assert_int_equal(ag_cloud_check_finite(c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "point 4"));
    ag_cloud_free(s);
    ag_cloud_free(c);
}

static void test_empty(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    double mn[3], mx[3];
    ag_cloud_bounds(c, mn, mx);
    assert_true(mn[0] > mx[0]);
    assert_true(ag_cloud_diagonal(c) == 0);
    ag_error e;
    assert_int_equal(ag_cloud_check_finite(c, &e), AG_OK);
    ag_cloud *s;
    assert_int_equal(ag_cloud_subset(c, NULL, 0, &s, &e), AG_OK);
    assert_int_equal(s->n, 0);
    ag_cloud_free(s);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_properties),
        cmocka_unit_test(test_subset_and_origin),
        cmocka_unit_test(test_empty),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
