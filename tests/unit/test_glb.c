#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/demo_building.h"
#include "core/mesh.h"
#include "io/glb.h"
#include "glb_fixture.h"

/* Two components (one in a group, one group-less), an empty component between them,
 * far from the origin like UTM data. */
static ag_mesh *sample(void)
{
    ag_mesh *m = ag_mesh_create();
    size_t g, c;
    const double X = 678088.25, Y = 5403784.5, Z = 413;
    double v[6][3] = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}, {5, 5, 5}, {6, 5, 5}};
    for (int i = 0; i < 6; i++)
        ag_mesh_add_vertex(m, X + v[i][0], Y + v[i][1], Z + v[i][2]);
    ag_mesh_add_group(m, "Wall_1", &g);
    ag_mesh_add_component(m, (int32_t)g, &c);
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_triangle(m, 0, 1, 2, 0);
    ag_mesh_add_triangle(m, 0, 3, 4, 2);
    ag_mesh_add_triangle(m, 0, 2, 3, 0);
    ag_mesh_add_triangle(m, 1, 5, 4, 2);
    return m;
}

static void test_sample_structure(void **state)
{
    ag_mesh *m = sample();
    uint8_t *buf;
    size_t len;
    ag_error e;
    assert_int_equal(ag_glb_write(m, &buf, &len, &e), AG_OK);
    glb_view v = check_container(buf, len);
    json_t *root = v.root;
    assert_string_equal(json_string_value(json_object_get(json_object_get(root, "asset"),
                                                          "version")),
                        "2.0");
    json_t *nodes = json_object_get(root, "nodes");
    assert_int_equal(json_array_size(nodes), 2); /* the empty component gives no node */
    json_t *scene_nodes = json_object_get(json_array_get(json_object_get(root, "scenes"), 0),
                                          "nodes");
    assert_int_equal(json_array_size(scene_nodes), 2);
    assert_non_null(v.bin);
    json_t *buffers = json_object_get(root, "buffers");
    assert_true(json_integer_value(json_object_get(json_array_get(buffers, 0), "byteLength")) <=
                (json_int_t)v.binlen);
    json_t *views = json_object_get(root, "bufferViews"), *view;
    size_t i;
    json_array_foreach(views, i, view)
    {
        json_int_t off = json_integer_value(json_object_get(view, "byteOffset"));
        json_int_t bl = json_integer_value(json_object_get(view, "byteLength"));
        assert_true(off % 4 == 0 && off + bl <= (json_int_t)v.binlen);
    }
    size_t comp_of_node[2] = {0, 2};
    size_t tris_of_node[2] = {2, 2};
    json_t *meshes = json_object_get(root, "meshes"), *accessors = json_object_get(root, "accessors");
    for (size_t n = 0; n < 2; n++) {
        json_t *node = json_array_get(nodes, n);
        char want[32];
        snprintf(want, sizeof want, "component %zu", comp_of_node[n]);
        assert_string_equal(json_string_value(json_object_get(node, "name")), want);
        json_t *extras = json_object_get(node, "extras");
        assert_int_equal(json_integer_value(json_object_get(extras, "component")), comp_of_node[n]);
        json_t *group = json_object_get(extras, "group");
        if (n == 0)
            assert_string_equal(json_string_value(group), "Wall_1");
        else
            assert_true(json_is_null(group));
        /* Translation = the bounds' centre in glTF axes: (x, z, -y). */
        json_t *tr = json_object_get(node, "translation");
        double t[3] = {json_real_value(json_array_get(tr, 0)), json_real_value(json_array_get(tr, 1)),
                       json_real_value(json_array_get(tr, 2))};
        assert_true(t[0] == 678088.25 + 3 && t[1] == 413 + 2.5 && t[2] == -(5403784.5 + 2.5));
        json_t *mesh = json_array_get(meshes, (size_t)json_integer_value(json_object_get(node, "mesh")));
        json_t *prim = json_array_get(json_object_get(mesh, "primitives"), 0);
        assert_int_equal(json_integer_value(json_object_get(prim, "mode")), 4);
        json_t *attr = json_object_get(prim, "attributes");
        json_t *pa = json_array_get(accessors, (size_t)json_integer_value(json_object_get(attr, "POSITION")));
        json_t *na = json_array_get(accessors, (size_t)json_integer_value(json_object_get(attr, "NORMAL")));
        assert_int_equal(json_integer_value(json_object_get(pa, "count")), 3 * tris_of_node[n]);
        assert_int_equal(json_integer_value(json_object_get(na, "count")), 3 * tris_of_node[n]);
        assert_int_equal(json_integer_value(json_object_get(pa, "componentType")), 5126);
        assert_string_equal(json_string_value(json_object_get(pa, "type")), "VEC3");
        /* min/max equal the extremes of the stored floats; positions + translation
         * reproduce the mesh; normals are unit length. */
        json_t *pv = json_array_get(views, (size_t)json_integer_value(json_object_get(pa, "bufferView")));
        json_t *nv = json_array_get(views, (size_t)json_integer_value(json_object_get(na, "bufferView")));
        const uint8_t *pp = v.bin + json_integer_value(json_object_get(pv, "byteOffset"));
        const uint8_t *np = v.bin + json_integer_value(json_object_get(nv, "byteOffset"));
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t k = 0; k < 3 * tris_of_node[n]; k++) {
            double len2 = 0;
            for (int a = 0; a < 3; a++) {
                float f = f32(pp + 12 * k + 4 * a);
                lo[a] = fminf(lo[a], f);
                hi[a] = fmaxf(hi[a], f);
                double nn = f32(np + 12 * k + 4 * a);
                len2 += nn * nn;
            }
            assert_true(fabs(len2 - 1) < 1e-6);
        }
        for (int a = 0; a < 3; a++) {
            assert_true((float)json_real_value(json_array_get(json_object_get(pa, "min"), a)) == lo[a]);
            assert_true((float)json_real_value(json_array_get(json_object_get(pa, "max"), a)) == hi[a]);
        }
        /* The first triangle of component 0 is vertices 0 1 2 of the mesh. */
        if (n == 0)
            for (int k = 0; k < 3; k++) {
                const double *p = m->pos + 3 * k;
                double x = f32(pp + 12 * k) + t[0], y = f32(pp + 12 * k + 4) + t[1],
                       z = f32(pp + 12 * k + 8) + t[2];
                assert_true(fabs(x - p[0]) < 1e-6 && fabs(y - p[2]) < 1e-6 &&
                            fabs(z + p[1]) < 1e-6);
            }
    }
    /* Triangle (0,1,2) lies in z = const facing +z (archgram) → +y in glTF. */
    const uint8_t *np0 = v.bin + json_integer_value(json_object_get(json_array_get(views, 1), "byteOffset"));
    assert_true(fabsf(f32(np0 + 4) - 1) < 1e-6f);
    json_t *mat = json_array_get(json_object_get(root, "materials"), 0);
    assert_true(json_is_true(json_object_get(mat, "doubleSided")));
    json_decref(root);
    free(buf);
    ag_mesh_free(m);
}

static void test_empty_mesh(void **state)
{
    ag_mesh *m = ag_mesh_create();
    uint8_t *buf;
    size_t len;
    assert_int_equal(ag_glb_write(m, &buf, &len, NULL), AG_OK);
    glb_view v = check_container(buf, len);
    assert_null(v.bin);
    assert_null(json_object_get(v.root, "nodes"));
    json_decref(v.root);
    free(buf);
    ag_mesh_free(m);
}

static void test_demo_file(void **state)
{
    ag_mesh *m = ag_demo_building(0);
    assert_non_null(m);
    char path[] = "/tmp/archgram_test_glb_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(ag_glb_write_file(m, path, NULL), AG_OK);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    static uint8_t buf[1 << 20];
    size_t len = fread(buf, 1, sizeof buf, f);
    fclose(f);
    unlink(path);
    glb_view v = check_container(buf, len);
    assert_int_equal(json_array_size(json_object_get(v.root, "nodes")), m->ncomponents);
    size_t total = 0, i;
    json_t *acc;
    json_array_foreach(json_object_get(v.root, "accessors"), i, acc)
        total += (size_t)json_integer_value(json_object_get(acc, "count"));
    assert_int_equal(total, 2 * 3 * m->ntris);
    json_decref(v.root);
    ag_error e;
    assert_int_equal(ag_glb_write_file(m, "/nonexistent-dir/x.glb", &e), AG_ERR_IO);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sample_structure),
        cmocka_unit_test(test_empty_mesh),
        cmocka_unit_test(test_demo_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
