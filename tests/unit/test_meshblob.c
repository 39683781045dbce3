#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/demo_building.h"
#include "core/mesh.h"
#include "io/meshblob.h"

static void assert_same(const ag_mesh *a, const ag_mesh *b)
{
    assert_int_equal(a->nverts, b->nverts);
    assert_int_equal(a->ntris, b->ntris);
    assert_int_equal(a->ngroups, b->ngroups);
    assert_int_equal(a->ncomponents, b->ncomponents);
    if (a->nverts)
        assert_memory_equal(a->pos, b->pos, 3 * a->nverts * sizeof(double));
    if (a->ntris) {
        assert_memory_equal(a->tri, b->tri, 3 * a->ntris * sizeof(uint32_t));
        assert_memory_equal(a->tri_component, b->tri_component, a->ntris * sizeof(uint32_t));
    }
    if (a->ncomponents)
        assert_memory_equal(a->component_group, b->component_group, a->ncomponents * 4);
    for (size_t g = 0; g < a->ngroups; g++)
        assert_string_equal(a->group_names[g], b->group_names[g]);
}

/* A small mesh with awkward values: negative zero, subnormals, huge, a group-less
 * component, an empty group name. */
static ag_mesh *small(void)
{
    ag_mesh *m = ag_mesh_create();
    size_t g, c;
    ag_mesh_add_vertex(m, -0.0, 4.9e-324, 1e300);
    ag_mesh_add_vertex(m, 0.1, -678088.123456789, 3);
    ag_mesh_add_vertex(m, 1, 2, 3);
    ag_mesh_add_vertex(m, 7, 8, 9);
    ag_mesh_add_group(m, "Window_1", &g);
    ag_mesh_add_group(m, "", &g);
    ag_mesh_add_component(m, 0, &c);
    ag_mesh_add_component(m, -1, &c);
    ag_mesh_add_component(m, 1, &c);
    ag_mesh_add_triangle(m, 0, 1, 2, 0);
    ag_mesh_add_triangle(m, 1, 2, 3, 2);
    ag_mesh_add_triangle(m, 3, 2, 0, 1);
    return m;
}

static void test_round_trip(void **state)
{
    ag_mesh *meshes[4] = {small(), ag_demo_building(0), ag_demo_building(1), ag_mesh_create()};
    for (int i = 0; i < 4; i++) {
        uint8_t *blob;
        size_t len;
        assert_int_equal(ag_meshblob_encode(meshes[i], &blob, &len), AG_OK);
        assert_memory_equal(blob, "AGM1", 4);
        ag_mesh *back = NULL;
        ag_error e;
        assert_int_equal(ag_meshblob_decode(blob, len, &back, &e), AG_OK);
        assert_same(meshes[i], back);
        if (i == 0)
            assert_true(signbit(back->pos[0]));
        ag_mesh_free(back);
        free(blob);
        ag_mesh_free(meshes[i]);
    }
}

static void expect_reject(const uint8_t *blob, size_t len, const char *needle)
{
    ag_mesh *m = (ag_mesh *)1;
    ag_error e;
    ag_error_clear(&e);
    assert_int_equal(ag_meshblob_decode(blob, len, &m, &e), AG_ERR_PARSE);
    assert_null(m);
    assert_int_equal(e.code, AG_ERR_PARSE);
    if (needle && !strstr(e.text, needle))
        print_error("message '%s' lacks '%s'\n", e.text, needle);
    if (needle)
        assert_non_null(strstr(e.text, needle));
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void test_corrupt(void **state)
{
    ag_mesh *m = small();
    uint8_t *blob;
    size_t len;
    assert_int_equal(ag_meshblob_encode(m, &blob, &len), AG_OK);
    /* Every truncation, each copied to an exact-size buffer so a read past its end would
     * be caught by the sanitizers / valgrind. */
    for (size_t n = 0; n < len; n++) {
        uint8_t *cut = malloc(n ? n : 1);
        memcpy(cut, blob, n);
        expect_reject(cut, n, NULL);
        free(cut);
    }
    uint8_t *copy = malloc(len + 1);
    memcpy(copy, blob, len);
    copy[len] = 0;
    expect_reject(copy, len + 1, "trailing");

    const size_t pos = 36, tri = pos + 4 * 24, tc = tri + 3 * 12, cg = tc + 3 * 4;
    memcpy(copy, blob, len);
    copy[0] = 'X';
    expect_reject(copy, len, "magic");
    memcpy(copy, blob, len);
    copy[4 + 7] = 0x80; /* nverts ≈ 2^63 */
    expect_reject(copy, len, "counts");
    memcpy(copy, blob, len);
    memset(copy + 12, 0xff, 8); /* ntris = 2^64 - 1: must not overflow a size */
    expect_reject(copy, len, "truncated");
    memcpy(copy, blob, len);
    put32(copy + 12, 0x40000000); /* ntris × 16 overflows 32 bits */
    expect_reject(copy, len, "truncated");
    memcpy(copy, blob, len);
    put32(copy + tri + 4, 4); /* vertex index == nverts */
    expect_reject(copy, len, "vertex 4");
    memcpy(copy, blob, len);
    put32(copy + tc + 4, 3); /* component index == ncomponents */
    expect_reject(copy, len, "component 3");
    memcpy(copy, blob, len);
    put32(copy + cg, 2); /* group index == ngroups */
    expect_reject(copy, len, "group 2");
    memcpy(copy, blob, len);
    put32(copy + cg, (uint32_t)-2);
    expect_reject(copy, len, "group -2");
    memcpy(copy, blob, len);
    memset(copy + pos + 8, 0xff, 8); /* a NaN coordinate */
    expect_reject(copy, len, "not finite");
    memcpy(copy, blob, len);
    put32(copy + cg + 12, 1000); /* first name's length past the end */
    expect_reject(copy, len, "group name");
    memcpy(copy, blob, len);
    copy[cg + 12 + 4 + 2] = 0; /* NUL inside a name */
    expect_reject(copy, len, "group name");
    free(copy);
    free(blob);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_corrupt),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
