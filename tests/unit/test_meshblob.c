#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
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

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* The mesh in the first layout (AGM1), written here from its description: the blobs of
 * databases made before AGM2 must still decode. */
static uint8_t *agm1_of(const ag_mesh *m, size_t *len)
{
    size_t n = 36 + 24 * m->nverts + 16 * m->ntris + 4 * m->ncomponents;
    for (size_t g = 0; g < m->ngroups; g++)
        n += 4 + strlen(m->group_names[g]);
    uint8_t *b = calloc(1, n), *p = b;
    memcpy(p, "AGM1", 4);
    put64(p + 4, m->nverts);
    put64(p + 12, m->ntris);
    put64(p + 20, m->ngroups);
    put64(p + 28, m->ncomponents);
    p += 36;
    for (size_t i = 0; i < 3 * m->nverts; i++, p += 8) {
        uint64_t u;
        memcpy(&u, &m->pos[i], 8);
        put64(p, u);
    }
    for (size_t i = 0; i < 3 * m->ntris; i++, p += 4)
        put32(p, m->tri[i]);
    for (size_t i = 0; i < m->ntris; i++, p += 4)
        put32(p, m->tri_component[i]);
    for (size_t i = 0; i < m->ncomponents; i++, p += 4)
        put32(p, (uint32_t)m->component_group[i]);
    for (size_t g = 0; g < m->ngroups; g++) {
        size_t l = strlen(m->group_names[g]);
        put32(p, (uint32_t)l);
        memcpy(p + 4, m->group_names[g], l);
        p += 4 + l;
    }
    *len = n;
    return b;
}

static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* Generated meshes of the shapes the encoding assumes and of those it does not: boxes on a
 * lattice (coordinates repeat), every coordinate distinct (a scan), triangles naming vertices
 * far apart in either direction, components interleaved and out of order, groups of none. */
static ag_mesh *generated(int variant, uint64_t seed)
{
    ag_mesh *m = ag_mesh_create();
    size_t nv = 50 + (size_t)(rng_next(&seed) % 3000), nc = 1 + (size_t)(rng_next(&seed) % 40);
    for (int g = 0; g < 5; g++) {
        char name[16];
        snprintf(name, sizeof name, "g%d_%d", variant, g);
        ag_mesh_add_group(m, name, NULL);
    }
    for (size_t c = 0; c < nc; c++)
        ag_mesh_add_component(m, (int32_t)(rng_next(&seed) % 6) - 1, NULL);
    for (size_t v = 0; v < nv; v++) {
        double p[3];
        for (int a = 0; a < 3; a++) {
            uint64_t r = rng_next(&seed);
            p[a] = variant == 0   ? 0.3 * (double)(r % 17) - 2.4          /* lattice */
                   : variant == 1 ? (double)(r >> 11) * 0x1p-53 * 1e5 - 5e4 /* all distinct */
                                  : (r % 4 ? 1.25 * (double)(r % 9) : -0.0);
        }
        ag_mesh_add_vertex(m, p[0], p[1], p[2]);
    }
    size_t nt = 1 + (size_t)(rng_next(&seed) % 5000);
    uint32_t c = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = (uint32_t)(variant == 2 ? rng_next(&seed) % nv : (t * 7) % nv);
        uint32_t b = (uint32_t)((a + 1 + rng_next(&seed) % 3) % nv);
        uint32_t d = (uint32_t)(rng_next(&seed) % nv); /* anywhere */
        if (rng_next(&seed) % (variant == 1 ? 2 : 50) == 0)
            c = (uint32_t)(rng_next(&seed) % nc);
        ag_mesh_add_triangle(m, a, b, d, c);
    }
    return m;
}

static void test_round_trip(void **state)
{
    ag_mesh *meshes[4] = {small(), ag_demo_building(0), ag_demo_building(1), ag_mesh_create()};
    for (int i = 0; i < 4; i++) {
        uint8_t *blob;
        size_t len;
        assert_int_equal(ag_meshblob_encode(meshes[i], &blob, &len), AG_OK);
        assert_memory_equal(blob, "AGM2", 4);
        ag_mesh *back = NULL;
        ag_error e;
        assert_int_equal(ag_meshblob_decode(blob, len, &back, &e), AG_OK);
        assert_same(meshes[i], back);
        if (i == 0)
            assert_true(signbit(back->pos[0]));
        ag_mesh_free(back);
        /* the old layout of the same mesh reads back the same */
        size_t old_len;
        uint8_t *old = agm1_of(meshes[i], &old_len);
        assert_int_equal(ag_meshblob_decode(old, old_len, &back, &e), AG_OK);
        assert_same(meshes[i], back);
        ag_mesh_free(back);
        /* what AGM2 is for: a building's mesh in far fewer bytes */
        if (i == 1 || i == 2) {
            if (len * 2 > old_len)
                print_error("demo building %d: %zu bytes, AGM1 %zu\n", i - 1, len, old_len);
            assert_true(len * 2 <= old_len);
        }
        free(old);
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

static void test_generated_round_trip(void **state)
{
    for (int variant = 0; variant < 3; variant++)
        for (uint64_t seed = 1; seed <= 12; seed++) {
            ag_mesh *m = generated(variant, seed * 0x9E3779B97F4A7C15ull + (uint64_t)variant);
            uint8_t *blob;
            size_t len;
            assert_int_equal(ag_meshblob_encode(m, &blob, &len), AG_OK);
            ag_mesh *back = NULL;
            ag_error e;
            assert_int_equal(ag_meshblob_decode(blob, len, &back, &e), AG_OK);
            assert_same(m, back);
            /* distinct coordinates cost at most a byte a vertex more than AGM1's 24 */
            size_t old_len;
            free(agm1_of(m, &old_len));
            assert_true(len <= old_len + m->nverts);
            if (variant == 0)
                assert_true(len * 2 <= old_len);
            ag_mesh_free(back);
            free(blob);
            ag_mesh_free(m);
        }
}

/* AGM2 damaged anywhere: every truncation and every byte changed decodes to an error or to a
 * mesh whose every index is in range, never reads past the buffer. */
static void test_corrupt_v2(void **state)
{
    ag_mesh *m = generated(0, 7);
    uint8_t *blob;
    size_t len;
    assert_int_equal(ag_meshblob_encode(m, &blob, &len), AG_OK);
    for (size_t n = 0; n < len; n += n < 400 ? 1 : 37) {
        uint8_t *cut = malloc(n ? n : 1);
        memcpy(cut, blob, n);
        expect_reject(cut, n, NULL);
        free(cut);
    }
    uint8_t *copy = malloc(len);
    uint64_t seed = 99;
    for (size_t i = 4; i < len; i += 1 + (i < 300 ? 0 : 23)) {
        memcpy(copy, blob, len);
        copy[i] ^= (uint8_t)(1 + rng_next(&seed) % 255);
        ag_mesh *back = NULL;
        ag_error e;
        ag_status s = ag_meshblob_decode(copy, len, &back, &e);
        if (s != AG_OK) {
            assert_int_equal(s, AG_ERR_PARSE);
            assert_null(back);
            continue;
        }
        for (size_t t = 0; t < back->ntris; t++) {
            for (int q = 0; q < 3; q++)
                assert_true(back->tri[3 * t + q] < back->nverts);
            assert_true(back->tri_component[t] < back->ncomponents);
        }
        for (size_t c = 0; c < back->ncomponents; c++)
            assert_true(back->component_group[c] >= -1 &&
                        back->component_group[c] < (int32_t)back->ngroups);
        for (size_t v = 0; v < 3 * back->nverts; v++)
            assert_true(isfinite(back->pos[v]));
        ag_mesh_free(back);
    }
    free(copy);
    free(blob);
    ag_mesh_free(m);

    /* named faults, on a blob written here byte by byte: one vertex, one triangle */
    uint8_t b[128];
    size_t n;
    const double one = 1.0;
    uint64_t u;
    memcpy(&u, &one, 8);
#define HEAD(nv, nt, ng, nc)                                                                     \
    do {                                                                                         \
        memcpy(b, "AGM2", 4);                                                                    \
        put64(b + 4, nv);                                                                        \
        put64(b + 12, nt);                                                                       \
        put64(b + 20, ng);                                                                       \
        put64(b + 28, nc);                                                                       \
        n = 36;                                                                                  \
    } while (0)
    /* a good one first, so each fault below is the only one */
    HEAD(1, 1, 0, 1);
    b[n++] = 6; /* x new; y and z repeat values their axes were never given */
    put64(b + n, u);
    n += 8;
    b[n++] = 0, b[n++] = 0, b[n++] = 0, b[n++] = 0; /* two slots never given */
    b[n++] = 0, b[n++] = 0, b[n++] = 0;             /* triangle 0 0 0 */
    b[n++] = 0, b[n++] = 1;                         /* component 0, one triangle */
    b[n++] = 0;                                     /* group -1 */
    expect_reject(b, n, "never given");

    HEAD(1, 1, 0, 1);
    b[n++] = 0;
    for (int a = 0; a < 3; a++, n += 8)
        put64(b + n, u);
    size_t tri = n;
    b[n++] = 0, b[n++] = 0, b[n++] = 0;
    size_t run = n;
    b[n++] = 0, b[n++] = 1;
    size_t group = n;
    b[n++] = 0;
    ag_mesh *good = NULL;
    ag_error e;
    assert_int_equal(ag_meshblob_decode(b, n, &good, &e), AG_OK);
    assert_int_equal(good->ntris, 1);
    assert_true(good->pos[2] == 1.0);
    ag_mesh_free(good);
    uint8_t bad[128];
    memcpy(bad, b, n);
    bad[36] = 8;
    expect_reject(bad, n, "flags");
    memcpy(bad, b, n);
    bad[tri + 1] = 2; /* b = a + 1 = vertex 1 of 1 */
    expect_reject(bad, n, "vertex 1");
    memcpy(bad, b, n);
    bad[tri] = 1; /* a = -1 */
    expect_reject(bad, n, "uses vertex");
    memcpy(bad, b, n);
    bad[run] = 2; /* component 1 of 1 */
    expect_reject(bad, n, "component 1");
    memcpy(bad, b, n);
    bad[run + 1] = 2; /* a run past the last triangle */
    expect_reject(bad, n, "run of 2");
    memcpy(bad, b, n);
    bad[run + 1] = 0;
    expect_reject(bad, n, "run of 0");
    memcpy(bad, b, n);
    bad[group] = 2; /* group 1 of 0 */
    expect_reject(bad, n, "group 1");
    memcpy(bad, b, n);
    memset(bad + 37, 0xff, 8); /* x a NaN */
    expect_reject(bad, n, "not finite");
    memcpy(bad, b, n);
    bad[n] = 0;
    expect_reject(bad, n + 1, "trailing");
    memcpy(bad, b, n);
    put64(bad + 4, (uint64_t)1 << 31); /* 2^31 vertices in a 60-byte blob: refused unallocated */
    expect_reject(bad, n, "truncated");
    memcpy(bad, b, n);
    put64(bad + 12, (uint64_t)1 << 40);
    expect_reject(bad, n, "truncated");
#undef HEAD
}

static void test_corrupt(void **state)
{
    ag_mesh *m = small();
    size_t len;
    uint8_t *blob = agm1_of(m, &len);
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
        cmocka_unit_test(test_generated_round_trip),
        cmocka_unit_test(test_corrupt_v2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
