/* The stored encoding of point cloud columns (io/cloudblob.h): which position encoding each
 * kind of input gets (float PLY → f32, a LAS grid at RD New / UTM coordinates → i32, other
 * doubles → f64), every encoding decoding to what was stored (bit for bit, or onto the LAS
 * grid), properties of every scalar type, ids in every width with -1, and chunks whose size
 * does not match refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/cloudblob.h"
#include "random_fixture.h"

static ag_cloud *cloud_of(size_t n)
{
    ag_cloud *c = ag_cloud_create();
    assert_non_null(c);
    assert_int_equal(ag_cloud_resize(c, n, NULL), AG_OK);
    return c;
}

/* Encodes [start, start + count) and decodes it into a fresh cloud of the same scale. */
static void round_trip(const ag_cloud *c, ag_cloudblob_positions e, ag_cloud *back, size_t start,
                       size_t count)
{
    uint8_t *data;
    size_t len;
    assert_int_equal(ag_cloudblob_encode_positions(c, e, start, count, &data, &len, NULL), AG_OK);
    assert_int_equal(len, count * ag_cloudblob_positions_size(e));
    assert_int_equal(ag_cloudblob_decode_positions(data, len, e, back, start, count, NULL), AG_OK);
    ag_error err;
    assert_int_equal(ag_cloudblob_decode_positions(data, len - 1, e, back, start, count, &err),
                     AG_ERR_PARSE);
    free(data);
}

static void each_input_gets_the_encoding_that_keeps_it(void **state)
{
    (void)state;
    uint64_t seed = 3;
    size_t n = 1000;
    /* float input (a float PLY): f32, bit for bit */
    ag_cloud *c = cloud_of(n);
    for (size_t i = 0; i < 3 * n; i++)
        c->xyz[i] = (double)(float)uniform(&seed, -50, 50);
    assert_int_equal(ag_cloudblob_positions_choose(c), AG_CLOUDBLOB_F32);
    ag_cloud *b = cloud_of(n);
    round_trip(c, AG_CLOUDBLOB_F32, b, 0, n);
    assert_memory_equal(b->xyz, c->xyz, 3 * n * sizeof(double));
    ag_cloud_free(b);
    /* a LAS grid (centimetres) moved to a local origin as the reader does: i32, onto the grid */
    const double origin[3] = {85000, 446000, 0}, las_offset[3] = {84000.5, 445000.25, -3};
    for (int k = 0; k < 3; k++)
        c->scale[k] = 0.01;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            int32_t X = (int32_t)(next_random(&seed) % 400000) - 100000;
            c->xyz[3 * i + k] = (X * 0.01 + las_offset[k]) - origin[k];
        }
    assert_int_equal(ag_cloudblob_positions_choose(c), AG_CLOUDBLOB_I32);
    b = cloud_of(n);
    memcpy(b->scale, c->scale, sizeof b->scale);
    round_trip(c, AG_CLOUDBLOB_I32, b, 0, n);
    for (size_t i = 0; i < 3 * n; i++) {
        assert_true(fabs(b->xyz[i] - c->xyz[i]) <= 1e-6);
        double steps = b->xyz[i] / 0.01;
        assert_true(fabs(steps - round(steps)) < 1e-9);
    }
    ag_cloud_free(b);
    /* one coordinate off the grid: f64, bit for bit */
    c->xyz[17] += 0.003;
    assert_int_equal(ag_cloudblob_positions_choose(c), AG_CLOUDBLOB_F64);
    b = cloud_of(n);
    round_trip(c, AG_CLOUDBLOB_F64, b, 0, n);
    assert_memory_equal(b->xyz, c->xyz, 3 * n * sizeof(double));
    /* a chunk in the middle lands at its place */
    memset(b->xyz, 0, 3 * n * sizeof(double));
    round_trip(c, AG_CLOUDBLOB_F64, b, 300, 250);
    assert_memory_equal(b->xyz + 900, c->xyz + 900, 750 * sizeof(double));
    assert_true(b->xyz[0] == 0 && b->xyz[3 * 550] == 0);
    ag_cloud_free(b);
    /* a grid that does not fit 32 bits: f64 */
    c->xyz[17] = 3e7;
    for (size_t i = 0; i < 3 * n; i++)
        c->xyz[i] = round(c->xyz[i] / 0.01) * 0.01;
    assert_int_equal(ag_cloudblob_positions_choose(c), AG_CLOUDBLOB_F64);
    ag_cloud_free(c);
    assert_int_equal(ag_cloudblob_positions_from_name("i32"), AG_CLOUDBLOB_I32);
    assert_int_equal(ag_cloudblob_positions_from_name("f16"), 0);
}

static void properties_and_normals_keep_their_values(void **state)
{
    (void)state;
    size_t n = 257;
    ag_cloud *c = cloud_of(n), *b = cloud_of(n);
    assert_int_equal(ag_cloud_add_normals(c, NULL), AG_OK);
    assert_int_equal(ag_cloud_add_normals(b, NULL), AG_OK);
    uint64_t seed = 9;
    for (size_t i = 0; i < 3 * n; i++)
        c->normals[i] = (float)uniform(&seed, -1, 1);
    for (int t = 0; t < AG_SCALAR_COUNT; t++) {
        char name[16];
        snprintf(name, sizeof name, "p%d", t);
        assert_int_equal(ag_cloud_add_property(c, name, (ag_scalar_type)t, NULL, NULL), AG_OK);
        assert_int_equal(ag_cloud_add_property(b, name, (ag_scalar_type)t, NULL, NULL), AG_OK);
        size_t size = ag_scalar_size((ag_scalar_type)t);
        uint8_t *v = c->props[t].values;
        for (size_t i = 0; i < n * size; i++)
            v[i] = (uint8_t)next_random(&seed);
        if (t == AG_SCALAR_FLOAT32 || t == AG_SCALAR_FLOAT64) /* no NaN payloads to compare */
            for (size_t i = 0; i < n; i++)
                ag_cloud_set(&c->props[t], i, uniform(&seed, -1e6, 1e6));
    }
    uint8_t *data;
    size_t len;
    assert_int_equal(ag_cloudblob_encode_normals(c, 0, n, &data, &len, NULL), AG_OK);
    assert_int_equal(ag_cloudblob_decode_normals(data, len, b, 0, n, NULL), AG_OK);
    assert_memory_equal(b->normals, c->normals, 3 * n * sizeof(float));
    free(data);
    for (size_t p = 0; p < c->nprops; p++) {
        size_t size = ag_scalar_size(c->props[p].type);
        assert_int_equal(ag_cloudblob_encode_property(c, p, 10, n - 10, &data, &len, NULL), AG_OK);
        assert_int_equal(len, (n - 10) * size);
        assert_int_equal(ag_cloudblob_decode_property(data, len, b, p, 10, n - 10, NULL), AG_OK);
        assert_memory_equal((uint8_t *)b->props[p].values + 10 * size,
                            (uint8_t *)c->props[p].values + 10 * size, (n - 10) * size);
        ag_error err;
        assert_int_equal(ag_cloudblob_decode_property(data, len + 1, b, p, 10, n - 10, &err),
                         AG_ERR_PARSE);
        assert_non_null(strstr(err.text, c->props[p].name));
        free(data);
    }
    ag_cloud_free(c);
    ag_cloud_free(b);
}

static void ids_take_the_smallest_width(void **state)
{
    (void)state;
    assert_int_equal(ag_cloudblob_id_width(0), 1);
    assert_int_equal(ag_cloudblob_id_width(126), 1);
    assert_int_equal(ag_cloudblob_id_width(127), 2);
    assert_int_equal(ag_cloudblob_id_width(40000), 4);
    const int32_t maxima[3] = {126, 32766, 2000000000};
    for (int w = 0; w < 3; w++) {
        int32_t ids[100], back[100];
        for (int i = 0; i < 100; i++)
            ids[i] = i % 7 == 0 ? -1 : (int32_t)((int64_t)maxima[w] * i / 99);
        unsigned width = ag_cloudblob_id_width(maxima[w]);
        uint8_t *data;
        size_t len;
        assert_int_equal(ag_cloudblob_encode_ids(ids, 100, width, &data, &len, NULL), AG_OK);
        assert_int_equal(len, 100 * width);
        assert_int_equal(ag_cloudblob_decode_ids(data, len, width, back, 100, NULL), AG_OK);
        assert_memory_equal(back, ids, sizeof ids);
        free(data);
    }
    /* an id too wide for the width is refused, not cut */
    int32_t wide[2] = {5, 300};
    uint8_t *data = NULL;
    size_t len;
    assert_int_equal(ag_cloudblob_encode_ids(wide, 2, 1, &data, &len, NULL), AG_ERR_INTERNAL);
    assert_null(data);
    uint32_t idx[5] = {4, 0, 3, 1, 2}, got[5];
    assert_int_equal(ag_cloudblob_encode_indices(idx, 5, &data, &len, NULL), AG_OK);
    assert_int_equal(ag_cloudblob_decode_indices(data, len, got, 5, NULL), AG_OK);
    assert_memory_equal(got, idx, sizeof idx);
    assert_int_equal(ag_cloudblob_decode_indices(data, len, got, 4, NULL), AG_ERR_PARSE);
    free(data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(each_input_gets_the_encoding_that_keeps_it),
        cmocka_unit_test(properties_and_normals_keep_their_values),
        cmocka_unit_test(ids_take_the_smallest_width),
    };
    return cmocka_run_group_tests_name("cloudblob", tests, NULL, NULL);
}
