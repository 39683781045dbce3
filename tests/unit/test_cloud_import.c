/* Point cloud format detection: signatures first, extensions only for text, meshes (PLY with
 * faces) told from clouds. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "io/cloud_import.h"

static ag_cloud_format sniff(const char *t, const char *name)
{
    return ag_cloud_format_sniff((const uint8_t *)t, strlen(t), name);
}

static void test_sniff(void **state)
{
    (void)state;
    uint8_t las[120] = {'L', 'A', 'S', 'F'};
    assert_int_equal(ag_cloud_format_sniff(las, sizeof las, NULL), AG_CLOUD_FORMAT_LAS);
    las[104] = 0x81; /* LASzip sets the top bit of the point format */
    assert_int_equal(ag_cloud_format_sniff(las, sizeof las, "x.las"), AG_CLOUD_FORMAT_LAZ);
    assert_int_equal(sniff("ply\nformat ascii 1.0\n", "a.xyz"), AG_CLOUD_FORMAT_PLY);
    assert_int_equal(sniff("1 2 3\n4 5 6\n", NULL), AG_CLOUD_FORMAT_XYZ);
    assert_int_equal(sniff("# comment\n1,2,3,0,0,1\n", NULL), AG_CLOUD_FORMAT_XYZ);
    assert_int_equal(sniff("v 1 2 3\nf 1 2 3\n", "house.obj"), AG_CLOUD_FORMAT_UNKNOWN);
    assert_int_equal(sniff("1 2\n", NULL), AG_CLOUD_FORMAT_UNKNOWN);
    /* an extension alone does not make a binary format */
    assert_int_equal(sniff("garbage", "x.las"), AG_CLOUD_FORMAT_UNKNOWN);
    assert_int_equal(sniff("", "x.xyz"), AG_CLOUD_FORMAT_XYZ);
    assert_int_equal(sniff("grammar text, not numbers\n", "notes.txt"), AG_CLOUD_FORMAT_UNKNOWN);
    assert_int_equal(ag_cloud_format_from_name("LAZ"), AG_CLOUD_FORMAT_LAZ);
    assert_int_equal(ag_cloud_format_from_name("txt"), AG_CLOUD_FORMAT_XYZ);
    assert_int_equal(ag_cloud_format_from_name("obj"), AG_CLOUD_FORMAT_UNKNOWN);
    assert_string_equal(ag_cloud_format_name(AG_CLOUD_FORMAT_LAZ), "laz");
}

static void test_mesh_or_cloud(void **state)
{
    (void)state;
    const char *mesh = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    const char *cloud = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                        "property float z\nend_header\n0 0 0\n";
    assert_false(ag_cloud_import_is_cloud((const uint8_t *)mesh, strlen(mesh), "m.ply"));
    assert_true(ag_cloud_import_is_cloud((const uint8_t *)cloud, strlen(cloud), "c.ply"));
    assert_false(ag_cloud_import_is_cloud((const uint8_t *)"v 0 0 0\n", 8, "m.obj"));
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_cloud_import_buffer((const uint8_t *)"v 0 0 0\n", 8, AG_CLOUD_FORMAT_UNKNOWN, &c, &e),
                     AG_ERR_UNSUPPORTED);
    assert_int_equal(ag_cloud_import_buffer((const uint8_t *)"", 0, AG_CLOUD_FORMAT_PLY, &c, &e), AG_ERR_EMPTY);
    /* the cloud reader takes a mesh's vertices */
    assert_int_equal(ag_cloud_import_buffer((const uint8_t *)mesh, strlen(mesh), AG_CLOUD_FORMAT_UNKNOWN, &c, &e),
                     AG_OK);
    assert_int_equal(c->n, 3);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sniff),
        cmocka_unit_test(test_mesh_or_cloud),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
