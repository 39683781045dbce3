/* XYZ text clouds: 3, 6 and 9 columns, normals told from colour, separators, comments,
 * errors with line numbers, large coordinates. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/cloud_import.h"
#include "io/xyz.h"

#define DATA AG_REPO_DIR "/tests/data/points/"

static ag_cloud *read_ok(const char *t)
{
    ag_cloud *c = NULL;
    ag_error e;
    if (ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e) != AG_OK)
        fail_msg("%s", e.text);
    return c;
}

static void test_columns(void **state)
{
    (void)state;
    ag_cloud *c = read_ok("# header comment\n1 2 3\n\n4,5,6\n// other comment\n7;8;9\r\n");
    assert_int_equal(c->n, 3);
    assert_null(c->normals);
    assert_true(c->xyz[3] == 4 && c->xyz[8] == 9);
    ag_cloud_free(c);
    c = read_ok("0 0 0 0 0 1\n1 0 0 0.6 0.8 0\n");
    assert_non_null(c->normals);
    assert_null(ag_cloud_find(c, "red"));
    assert_true(c->normals[3] == 0.6f && c->normals[4] == 0.8f);
    ag_cloud_free(c);
    c = read_ok("0 0 0 255 0 10\n1 0 0 3 4 5\n");
    assert_null(c->normals);
    const ag_cloud_property *r = ag_cloud_find(c, "red");
    assert_non_null(r);
    assert_int_equal(r->type, AG_SCALAR_UINT8);
    assert_true(ag_cloud_get(r, 0) == 255 && ag_cloud_get(ag_cloud_find(c, "blue"), 1) == 5);
    ag_cloud_free(c);
    c = read_ok("0 0 0 0.5 0.25 0\n1 0 0 0.1 0.2 0.3\n"); /* colour as fractions */
    assert_int_equal(ag_cloud_find(c, "green")->type, AG_SCALAR_FLOAT32);
    ag_cloud_free(c);
    c = read_ok("0 0 0 0 0 1 10 20 30\n");
    assert_non_null(c->normals);
    assert_true(ag_cloud_get(ag_cloud_find(c, "green"), 0) == 20);
    ag_cloud_free(c);
}

static void test_errors(void **state)
{
    (void)state;
    ag_cloud *c = NULL;
    ag_error e;
    const char *t = "1 2 3\n4 5\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_PARSE);
    assert_int_equal(e.element, 2);
    assert_non_null(strstr(e.text, "2 values"));
    t = "1 2 3\n4 5 6 7 8 9\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "first point line had 3"));
    t = "1 2 3\n4 x 6\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "'x'"));
    t = "1 2 inf\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_PARSE);
    t = "# only comments\n\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_EMPTY);
    t = "1 2 3 4 5 6 7 8 9 10\n";
    assert_int_equal(ag_xyz_read_buffer((const uint8_t *)t, strlen(t), &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "more than 9"));
    assert_null(c);
}

static void test_large_coordinates(void **state)
{
    (void)state;
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(DATA "huge_coords.xyz", &c, &e), AG_OK);
    assert_int_equal(c->n, 100 * 50 + 99 * 50);
    assert_true(c->offset[0] == 548875 && c->offset[1] == 4176972 && c->offset[2] == 0);
    /* millimetres survive: the first point is 548875.201 4176972.964 171.336 */
    assert_true(fabs(c->xyz[0] - 0.201) < 1e-9 && fabs(c->xyz[1] - 0.964) < 1e-9);
    /* written back absolute, to the millimetre */
    char *buf = NULL;
    size_t len;
    FILE *f = open_memstream(&buf, &len);
    assert_int_equal(ag_xyz_write(c, f, &e), AG_OK);
    fclose(f);
    assert_true(strncmp(buf, "548875.201", 10) == 0);
    ag_cloud *back;
    assert_int_equal(ag_xyz_read_buffer((uint8_t *)buf, len, &back, &e), AG_OK);
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++)
            assert_true(fabs(back->xyz[3 * i + a] + back->offset[a] - c->xyz[3 * i + a] - c->offset[a]) < 1e-9);
    ag_cloud_free(back);
    free(buf);
    ag_cloud_free(c);
    assert_int_equal(ag_cloud_import_file(DATA "collinear.xyz", &c, &e), AG_OK);
    assert_int_equal(c->n, 500);
    ag_cloud_free(c);
}

/* A cloud with a source resolution (a LAS scale) is written to that resolution: the
 * numbers LAS holds, not their sum with the local origin printed to 17 digits; a resolution
 * that needs many decimals, or none, keeps the round-trip form. */
static void test_written_at_the_source_resolution(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    ag_error e;
    assert_int_equal(ag_cloud_resize(c, 2, &e), AG_OK);
    const double abs[2][3] = {{84916.949, 447413.3, 5.977}, {84808.3, 447412.8, -0.568}};
    c->offset[0] = 84808, c->offset[1] = 447412, c->offset[2] = 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 3; k++)
            c->xyz[3 * i + k] = abs[i][k] - c->offset[k];
    const struct {
        double scale[3];
        const char *want;
    } cases[] = {
        {{0.001, 0.001, 0.001}, "84916.949 447413.300 5.977\n84808.300 447412.800 -0.568\n"},
        {{0.25, 0.1, 1}, "84916.95 447413.3 6\n84808.30 447412.8 -1\n"},
        {{0, 0, 0}, NULL}, /* no resolution: round trip */
        {{1e-12, 0.3 / 7, 0}, NULL},
    };
    for (size_t t = 0; t < sizeof cases / sizeof *cases; t++) {
        memcpy(c->scale, cases[t].scale, sizeof c->scale);
        char *buf = NULL;
        size_t len;
        FILE *f = open_memstream(&buf, &len);
        assert_int_equal(ag_xyz_write(c, f, &e), AG_OK);
        fclose(f);
        if (cases[t].want) {
            assert_string_equal(buf, cases[t].want);
        } else {
            ag_cloud *back;
            assert_int_equal(ag_xyz_read_buffer((uint8_t *)buf, len, &back, &e), AG_OK);
            for (int i = 0; i < 2; i++)
                for (int k = 0; k < 3; k++)
                    assert_true(fabs(back->xyz[3 * i + k] + back->offset[k] -
                                     c->xyz[3 * i + k] - c->offset[k]) < 1e-9);
            ag_cloud_free(back);
        }
        free(buf);
    }
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_columns),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_large_coordinates),
        cmocka_unit_test(test_written_at_the_source_resolution),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
