/* PLY point clouds: ASCII and both binary byte orders, every scalar type, list properties
 * and other elements skipped, the offset comment, and bad input (truncation at every byte,
 * counts that lie, random corruption) giving errors rather than crashes. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/points/rng.h"
#include "io/cloud_import.h"
#include "io/ply.h"

#define DATA AG_REPO_DIR "/tests/data/points/"

/* A cloud with every PLY scalar type, normals and an offset. */
static ag_cloud *sample_cloud(size_t n)
{
    ag_cloud *c = ag_cloud_create();
    ag_error e;
    assert_int_equal(ag_cloud_resize(c, n, &e), AG_OK);
    assert_int_equal(ag_cloud_add_normals(c, &e), AG_OK);
    const ag_scalar_type types[] = {AG_SCALAR_INT8,  AG_SCALAR_UINT8,   AG_SCALAR_INT16,
                                    AG_SCALAR_UINT16, AG_SCALAR_INT32,  AG_SCALAR_UINT32,
                                    AG_SCALAR_FLOAT32, AG_SCALAR_FLOAT64};
    const char *names[] = {"i8", "u8", "i16", "u16", "i32", "u32", "f32", "f64"};
    for (int t = 0; t < 8; t++)
        assert_int_equal(ag_cloud_add_property(c, names[t], types[t], NULL, &e), AG_OK);
    c->offset[0] = 84808;
    c->offset[1] = 447412;
    ag_rng r;
    ag_rng_seed(&r, 3);
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            /* float-exact local positions so that float output is exact */
            c->xyz[3 * i + a] = (double)(float)(ag_rng_unit(&r) * 200 - (a == 2 ? 1 : 0));
            c->normals[3 * i + a] = (float)(ag_rng_unit(&r) - 0.5);
        }
        ag_cloud_set(&c->props[0], i, (double)(int)(ag_rng_below(&r, 256)) - 128);
        ag_cloud_set(&c->props[1], i, (double)ag_rng_below(&r, 256));
        ag_cloud_set(&c->props[2], i, (double)(int)ag_rng_below(&r, 65536) - 32768);
        ag_cloud_set(&c->props[3], i, (double)ag_rng_below(&r, 65536));
        ag_cloud_set(&c->props[4], i, (double)(int64_t)(ag_rng_next(&r) % 4000000000ull) - 2000000000.0);
        ag_cloud_set(&c->props[5], i, (double)(ag_rng_next(&r) % 4294967296ull));
        ag_cloud_set(&c->props[6], i, (double)(float)(ag_rng_gauss(&r) * 1e5));
        ag_cloud_set(&c->props[7], i, ag_rng_gauss(&r) * 1e-7);
    }
    return c;
}

static char *write_mem(const ag_cloud *c, const ag_ply_write_options *o, size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    ag_error e;
    assert_int_equal(ag_ply_write(c, o, f, &e), AG_OK);
    fclose(f);
    return buf;
}

static void assert_same(const ag_cloud *a, const ag_cloud *b, double xyz_tol)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->nprops, b->nprops);
    assert_non_null(b->normals);
    for (size_t i = 0; i < a->n; i++) {
        for (int k = 0; k < 3; k++) {
            double pa = a->xyz[3 * i + k] + a->offset[k], pb = b->xyz[3 * i + k] + b->offset[k];
            assert_true(fabs(pa - pb) <= xyz_tol);
            assert_true(a->normals[3 * i + k] == b->normals[3 * i + k]);
        }
        for (size_t p = 0; p < a->nprops; p++) {
            const ag_cloud_property *q = ag_cloud_find(b, a->props[p].name);
            assert_non_null(q);
            assert_int_equal(q->type, a->props[p].type);
            assert_true(ag_cloud_get(q, i) == ag_cloud_get(&a->props[p], i));
        }
    }
}

static void test_round_trips(void **state)
{
    (void)state;
    ag_cloud *c = sample_cloud(300);
    const ag_ply_encoding enc[] = {AG_PLY_BINARY_LE, AG_PLY_BINARY_BE, AG_PLY_ASCII};
    for (int k = 0; k < 3; k++)
        for (int dbl = 0; dbl < 2; dbl++) {
            ag_ply_write_options o = {enc[k], dbl};
            size_t len;
            char *buf = write_mem(c, &o, &len);
            /* float output carries the offset in the header, double output does not */
            assert_true((strstr(buf, "comment offset 84808 447412 0") != NULL) == !dbl);
            ag_cloud *back;
            ag_error e;
            assert_int_equal(ag_ply_read_buffer((uint8_t *)buf, len, &back, &e), AG_OK);
            assert_same(c, back, dbl ? 1e-9 : 0);
            if (!dbl)
                assert_true(back->offset[0] == 84808 && back->offset[1] == 447412);
            ag_cloud_free(back);
            free(buf);
        }
    ag_cloud_free(c);
}

/* A big-endian file built byte by byte here (independent of the writer): a face element
 * before the vertices, a list property inside the vertex element, every type. */
static void test_hand_made_big_endian(void **state)
{
    (void)state;
    const char *hdr = "ply\r\nformat binary_big_endian 1.0\r\n"
                      "comment made by hand\r\n"
                      "element face 2\r\nproperty list uchar int vertex_indices\r\n"
                      "element vertex 2\r\nproperty short x\r\nproperty double y\r\nproperty float z\r\n"
                      "property list uint8 float extra\r\nproperty uint intensity\r\n"
                      "property char flag\r\nproperty float64 gps\r\nend_header\n";
    uint8_t data[512];
    size_t n = strlen(hdr);
    memcpy(data, hdr, n);
    /* faces: 3 indices, then 4 */
    data[n++] = 3;
    for (int i = 0; i < 3; i++) {
        uint8_t be[4] = {0, 0, 0, (uint8_t)i};
        memcpy(data + n, be, 4);
        n += 4;
    }
    data[n++] = 4;
    for (int i = 0; i < 4; i++) {
        uint8_t be[4] = {0, 0, 1, (uint8_t)i};
        memcpy(data + n, be, 4);
        n += 4;
    }
    /* vertices: x = -2 (short), y = 0.5 (double), z = 3 (float), extra list of 2 floats,
     * intensity 65536 + 5, flag -3, gps 1.25; then x = 300, y = -1, z = 0.25, empty list */
    const uint8_t v1[] = {0xFF, 0xFE, 0x3F, 0xE0, 0, 0, 0, 0, 0, 0, 0x40, 0x40, 0, 0,
                          2, 0x3F, 0x80, 0, 0, 0x40, 0, 0, 0, 0, 1, 0, 5, 0xFD,
                          0x3F, 0xF4, 0, 0, 0, 0, 0, 0};
    const uint8_t v2[] = {0x01, 0x2C, 0xBF, 0xF0, 0, 0, 0, 0, 0, 0, 0x3E, 0x80, 0, 0,
                          0, 0, 0, 0, 7, 0x01, 0x40, 0x08, 0, 0, 0, 0, 0, 0};
    memcpy(data + n, v1, sizeof v1);
    n += sizeof v1;
    memcpy(data + n, v2, sizeof v2);
    n += sizeof v2;
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_ply_read_buffer(data, n, &c, &e), AG_OK);
    assert_int_equal(c->n, 2);
    assert_true(c->xyz[0] == -2 && c->xyz[1] == 0.5 && c->xyz[2] == 3);
    assert_true(c->xyz[3] == 300 && c->xyz[4] == -1 && c->xyz[5] == 0.25);
    assert_null(ag_cloud_find(c, "extra")); /* lists are skipped */
    assert_true(ag_cloud_get(ag_cloud_find(c, "intensity"), 0) == 65541);
    assert_true(ag_cloud_get(ag_cloud_find(c, "intensity"), 1) == 7);
    assert_true(ag_cloud_get(ag_cloud_find(c, "flag"), 0) == -3);
    assert_true(ag_cloud_get(ag_cloud_find(c, "gps"), 0) == 1.25);
    assert_true(ag_cloud_get(ag_cloud_find(c, "gps"), 1) == 3);
    assert_int_equal(ag_cloud_find(c, "flag")->type, AG_SCALAR_INT8);
    assert_true(ag_ply_has_faces(data, n));
    ag_cloud_free(c);
}

static void test_ascii_details(void **state)
{
    (void)state;
    const char *text = "ply\nformat ascii 1.0\nobj_info generated\n"
                       "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "property float normal_x\nproperty float normal_y\nproperty float normal_z\n"
                       "property list uchar int tags\nproperty int segment_index\n"
                       "element face 0\nproperty list uchar int vertex_indices\nend_header\n"
                       "0 0 0 0 0 1 2 5 6 -1\n"
                       "1.5 2 3e2   0 1 0 0 7\n\n"
                       "-4 5 6 1 0 0 1 9 18\n";
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_ply_read_buffer((const uint8_t *)text, strlen(text), &c, &e), AG_OK);
    assert_int_equal(c->n, 3);
    assert_non_null(c->normals);
    assert_true(c->normals[2] == 1 && c->normals[4] == 1 && c->normals[6] == 1);
    assert_true(c->xyz[5] == 300);
    const ag_cloud_property *s = ag_cloud_find(c, "segment_index");
    assert_true(ag_cloud_get(s, 0) == -1 && ag_cloud_get(s, 1) == 7 && ag_cloud_get(s, 2) == 18);
    assert_false(ag_ply_has_faces((const uint8_t *)text, strlen(text)));
    assert_true(ag_cloud_import_is_cloud((const uint8_t *)text, strlen(text), NULL));
    /* a header that does not end is no cloud of this reader's: the mesh importer judges it */
    const char *cut = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 1\nend_hea";
    assert_false(ag_cloud_import_is_cloud((const uint8_t *)cut, strlen(cut), NULL));
    ag_cloud_free(c);
}

static ag_status read_text(const char *t, ag_error *e)
{
    ag_cloud *c = NULL;
    ag_error_clear(e);
    ag_status st = ag_ply_read_buffer((const uint8_t *)t, strlen(t), &c, e);
    ag_cloud_free(c);
    return st;
}

static void test_errors(void **state)
{
    (void)state;
    ag_error e;
    assert_int_equal(read_text("plyx\n", &e), AG_ERR_PARSE);
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "end_header"));
    assert_int_equal(read_text("ply\nformat ascii 2.0\nend_header\n", &e), AG_ERR_PARSE);
    assert_int_equal(e.element, 2);
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "no z"));
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "quad"));
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nend_header\n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "twice"));
    /* counts that lie: more rows than the bytes could hold, before anything is allocated */
    assert_int_equal(read_text("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                               "property float x\nproperty float y\nproperty float z\nend_header\n0123456789ab",
                               &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "1000000000000"));
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 99999999999999\n"
                               "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n",
                               &e), AG_ERR_PARSE);
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 18446744073709551616\n"
                               "property float x\nend_header\n", &e), AG_ERR_PARSE);
    /* a list that claims more items than there are bytes */
    const char hdr[] = "ply\nformat binary_little_endian 1.0\nelement face 1\n"
                       "property list uint int idx\nelement vertex 1\nproperty float x\nproperty float y\n"
                       "property float z\nend_header\n";
    uint8_t buf[256];
    memcpy(buf, hdr, sizeof hdr - 1);
    uint8_t lie[4] = {0xFF, 0xFF, 0xFF, 0x7F};
    memcpy(buf + sizeof hdr - 1, lie, 4);
    memset(buf + sizeof hdr - 1 + 4, 0, 16);
    ag_cloud *c = NULL;
    assert_int_equal(ag_ply_read_buffer(buf, sizeof hdr - 1 + 20, &c, &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "claims"));
    /* bad values name the line */
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                               "property float z\nproperty uchar c\nend_header\n1 2 3 4\n1 2 3 256\n", &e),
                     AG_ERR_PARSE);
    assert_int_equal(e.element, 10);
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                               "property float z\nend_header\n1 2 3\n1 2\n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "more than the 10 bytes"));
    assert_int_equal(read_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                               "property float z\nend_header\n1 2 3\n1 2          \n", &e), AG_ERR_PARSE);
    assert_non_null(strstr(e.text, "ends inside vertex row 2"));
    /* the fixture with a NaN names its line */
    assert_int_equal(ag_cloud_import_file(DATA "nan.ply", &c, &e), AG_ERR_PARSE);
    assert_int_equal(e.element, 10);
    assert_non_null(strstr(e.text, "point 3 has x = nan"));
}

static void test_truncation_and_corruption(void **state)
{
    (void)state;
    ag_cloud *c = sample_cloud(20);
    for (int enc = 0; enc < 3; enc++) {
        ag_ply_write_options o = {(ag_ply_encoding)enc, 0};
        size_t len;
        char *buf = write_mem(c, &o, &len);
        /* every truncation is an error; nothing reads past the end (the copy is exact) */
        for (size_t l = 0; l < len; l++) {
            uint8_t *cut = malloc(l ? l : 1);
            memcpy(cut, buf, l);
            ag_cloud *r = NULL;
            ag_error e;
            ag_status st = ag_ply_read_buffer(cut, l, &r, &e);
            /* an ASCII file cut after the last digit of the last value is still whole */
            if (st == AG_OK) {
                assert_int_equal(enc, AG_PLY_ASCII);
                assert_int_equal(r->n, 20);
            } else {
                assert_null(r);
                assert_true(e.text[0] != 0);
            }
            ag_cloud_free(r);
            free(cut);
        }
        /* random byte changes: errors or clouds, never a crash */
        ag_rng rng;
        ag_rng_seed(&rng, 99 + (uint64_t)enc);
        for (int k = 0; k < 3000; k++) {
            uint8_t *bad = malloc(len);
            memcpy(bad, buf, len);
            int flips = 1 + (int)ag_rng_below(&rng, 4);
            for (int f = 0; f < flips; f++)
                bad[ag_rng_below(&rng, len)] = (uint8_t)ag_rng_next(&rng);
            ag_cloud *r = NULL;
            ag_error e;
            if (ag_ply_read_buffer(bad, len, &r, &e) == AG_OK)
                assert_true(r->n <= 20 + len);
            ag_cloud_free(r);
            free(bad);
        }
        free(buf);
    }
    ag_cloud_free(c);
}

static void test_fixtures(void **state)
{
    (void)state;
    ag_cloud *c;
    ag_error e;
    assert_int_equal(ag_cloud_import_file(DATA "empty.ply", &c, &e), AG_OK);
    assert_int_equal(c->n, 0);
    ag_cloud_free(c);
    assert_int_equal(ag_cloud_import_file(DATA "one_point.ply", &c, &e), AG_OK);
    assert_int_equal(c->n, 1);
    assert_true(c->xyz[0] == 1.5 && c->xyz[2] == 3.5);
    assert_true(ag_cloud_get(ag_cloud_find(c, "classification"), 0) == 6);
    ag_cloud_free(c);
    assert_int_equal(ag_cloud_import_file(DATA "duplicates.ply", &c, &e), AG_OK);
    assert_int_equal(c->n, 2050);
    ag_cloud_free(c);
}

/* An element without properties has rows of no bytes: any count the header declares is read
 * at once (it used to loop once per declared row), and the points after it are all there. */
static void test_elements_without_properties(void **state)
{
    (void)state;
    const char *counts[] = {"0", "7", "4000000000", "18446744073709551615"};
    for (int binary = 0; binary < 2; binary++)
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
            char text[512];
            int n = snprintf(text, sizeof text,
                             "ply\nformat %s 1.0\nelement empty %s\nelement vertex 2\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "element trailer %s\nend_header\n",
                             binary ? "binary_little_endian" : "ascii", counts[i], counts[i]);
            uint8_t buf[600];
            memcpy(buf, text, (size_t)n);
            size_t len = (size_t)n;
            const float xyz[6] = {1, 2, 3, -4, 5.5f, 6};
            if (binary) {
                memcpy(buf + len, xyz, sizeof xyz); /* this machine is little-endian */
                len += sizeof xyz;
            } else {
                len += (size_t)snprintf((char *)buf + len, sizeof buf - len, "1 2 3\n-4 5.5 6\n");
            }
            ag_cloud *c = NULL;
            ag_error e;
            assert_int_equal(ag_ply_read_buffer(buf, len, &c, &e), AG_OK);
            assert_int_equal(c->n, 2);
            for (int k = 0; k < 6; k++)
                assert_true(c->xyz[k] == (double)xyz[k]);
            ag_cloud_free(c);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trips),
        cmocka_unit_test(test_hand_made_big_endian),
        cmocka_unit_test(test_ascii_details),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_truncation_and_corruption),
        cmocka_unit_test(test_fixtures),
        cmocka_unit_test(test_elements_without_properties),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
