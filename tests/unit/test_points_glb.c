/* GLB of points (io/points_glb.h), read back here with a parser of its own: the container
 * (magic, lengths, chunk types, 4-byte padding), one POINTS primitive whose accessors count
 * the points, POSITION min/max equal to the stored floats' bounds, positions that give the
 * input back through the node's translation and the y-up turn, colours and attributes as
 * given, the extras, an empty cloud, and refused attribute names. Clouds at UTM offsets
 * too. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/points_glb.h"
#include "glb_fixture.h"
#include "random_fixture.h"

/* The bytes of accessor a (checked against its view and the buffer). */
static const uint8_t *accessor(const glb_view *g, json_int_t a, size_t *count, const char **type,
                               int *component)
{
    json_t *acc = json_array_get(json_object_get(g->root, "accessors"), (size_t)a);
    assert_non_null(acc);
    json_t *view = json_array_get(json_object_get(g->root, "bufferViews"),
                                  (size_t)json_integer_value(json_object_get(acc, "bufferView")));
    assert_non_null(view);
    size_t off = (size_t)json_integer_value(json_object_get(view, "byteOffset"));
    size_t len = (size_t)json_integer_value(json_object_get(view, "byteLength"));
    assert_true(off + len <= g->binlen);
    assert_int_equal(off % 4, 0);
    *count = (size_t)json_integer_value(json_object_get(acc, "count"));
    *type = json_string_value(json_object_get(acc, "type"));
    *component = (int)json_integer_value(json_object_get(acc, "componentType"));
    return g->bin + off;
}

static void points_come_back_through_the_node(void **state)
{
    (void)state;
    const double origins[][3] = {{0, 0, 0}, {486512.25, 5719877.75, 47.5}};
    for (int o = 0; o < 2; o++) {
        size_t n = 3000;
        uint64_t seed = 21 + (uint64_t)o;
        double *xyz = malloc(3 * n * sizeof *xyz);
        uint8_t *rgba = malloc(4 * n);
        float *seg = malloc(n * sizeof *seg), *lab = malloc(n * sizeof *lab);
        for (size_t i = 0; i < n; i++) {
            for (int k = 0; k < 3; k++)
                xyz[3 * i + k] = origins[o][k] + uniform(&seed, -20, 20);
            for (int k = 0; k < 4; k++)
                rgba[4 * i + k] = (uint8_t)next_random(&seed);
            seg[i] = (float)(i % 13) - 1;
            lab[i] = (float)(i % 5) - 1;
        }
        ag_points_glb_attribute attrs[2] = {{"_SEGMENT", seg}, {"_LABEL", lab}};
        json_t *extras = json_pack("{s:i, s:s}", "points", 99, "what", "test");
        ag_points_glb in = {n, xyz, rgba, attrs, 2, extras};
        uint8_t *data;
        size_t len;
        assert_int_equal(ag_points_glb_write(&in, &data, &len, NULL), AG_OK);
        glb_view g = check_container(data, len);
        json_t *node = json_array_get(json_object_get(g.root, "nodes"), 0);
        assert_int_equal(json_integer_value(json_object_get(json_object_get(node, "extras"),
                                                            "points")), 99);
        double t[3];
        for (int k = 0; k < 3; k++)
            t[k] = json_number_value(json_array_get(json_object_get(node, "translation"), (size_t)k));
        json_t *prim = json_array_get(
            json_object_get(json_array_get(json_object_get(g.root, "meshes"), 0), "primitives"), 0);
        assert_int_equal(json_integer_value(json_object_get(prim, "mode")), 0);
        json_t *at = json_object_get(prim, "attributes");
        size_t count;
        const char *type;
        int comp;
        json_t *pacc = json_array_get(json_object_get(g.root, "accessors"),
                                      (size_t)json_integer_value(json_object_get(at, "POSITION")));
        const uint8_t *pos = accessor(&g, json_integer_value(json_object_get(at, "POSITION")),
                                      &count, &type, &comp);
        assert_int_equal(count, n);
        assert_string_equal(type, "VEC3");
        assert_int_equal(comp, 5126);
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < n; i++) {
            float v[3] = {f32(pos + 12 * i), f32(pos + 12 * i + 4), f32(pos + 12 * i + 8)};
            for (int k = 0; k < 3; k++) {
                lo[k] = fmin(lo[k], v[k]);
                hi[k] = fmax(hi[k], v[k]);
            }
            /* glTF (x, y, z) + translation = archgram (x, z, -y): millimetres at UTM */
            double back[3] = {v[0] + t[0], -(v[2] + t[2]), v[1] + t[1]};
            for (int k = 0; k < 3; k++)
                assert_true(fabs(back[k] - xyz[3 * i + k]) < 1e-3);
        }
        for (int k = 0; k < 3; k++) {
            assert_true(json_number_value(json_array_get(json_object_get(pacc, "min"), (size_t)k)) == lo[k]);
            assert_true(json_number_value(json_array_get(json_object_get(pacc, "max"), (size_t)k)) == hi[k]);
        }
        const uint8_t *col = accessor(&g, json_integer_value(json_object_get(at, "COLOR_0")),
                                      &count, &type, &comp);
        assert_int_equal(count, n);
        assert_string_equal(type, "VEC4");
        assert_int_equal(comp, 5121);
        assert_memory_equal(col, rgba, 4 * n);
        const char *names[2] = {"_SEGMENT", "_LABEL"};
        const float *want[2] = {seg, lab};
        for (int a = 0; a < 2; a++) {
            const uint8_t *v = accessor(&g, json_integer_value(json_object_get(at, names[a])),
                                        &count, &type, &comp);
            assert_int_equal(count, n);
            assert_string_equal(type, "SCALAR");
            for (size_t i = 0; i < n; i++)
                assert_true(f32(v + 4 * i) == want[a][i]);
        }
        json_decref(g.root);
        json_decref(extras);
        free(data);
        free(xyz);
        free(rgba);
        free(seg);
        free(lab);
    }
}

static void an_empty_cloud_and_bad_names(void **state)
{
    (void)state;
    ag_points_glb in = {0};
    uint8_t *data;
    size_t len;
    assert_int_equal(ag_points_glb_write(&in, &data, &len, NULL), AG_OK);
    glb_view g = check_container(data, len);
    assert_null(g.bin);
    assert_null(json_object_get(g.root, "meshes"));
    assert_true(json_is_array(json_object_get(g.root, "scenes")));
    json_decref(g.root);
    free(data);
    double xyz[3] = {1, 2, 3};
    float v = 1;
    ag_points_glb_attribute bad = {"SEGMENT", &v};
    ag_points_glb one = {1, xyz, NULL, &bad, 1, NULL};
    ag_error err;
    assert_int_equal(ag_points_glb_write(&one, &data, &len, &err), AG_ERR_INVALID);
    one.nattributes = 0;
    assert_int_equal(ag_points_glb_write(&one, &data, &len, NULL), AG_OK);
    g = check_container(data, len);
    json_t *at = json_object_get(json_array_get(json_object_get(
                                     json_array_get(json_object_get(g.root, "meshes"), 0),
                                     "primitives"), 0), "attributes");
    assert_null(json_object_get(at, "COLOR_0"));
    assert_non_null(json_object_get(at, "POSITION"));
    json_decref(g.root);
    free(data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(points_come_back_through_the_node),
        cmocka_unit_test(an_empty_cloud_and_bad_names),
    };
    return cmocka_run_group_tests_name("points_glb", tests, NULL, NULL);
}
