/* glTF, Collada, PLY and STL through assimp; GLB output read back. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/assimp_import.h"
#include "io/glb.h"
#include "io/import.h"

#define DATA AG_REPO_DIR "/tests/data/proc"

static uint8_t *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)n + 1);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *len = (size_t)n;
    return b;
}

static ag_mesh *load(const char *file, ag_format fmt, ag_up_axis up)
{
    size_t len;
    uint8_t *d = slurp(file, &len);
    ag_import_options o = {.up = up};
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_status st = ag_import_buffer(d, len, fmt, &o, &m, &err);
    free(d);
    if (st)
        fail_msg("%s: %s", file, err.text);
    return m;
}

static void test_stl_and_ply(void **state)
{
    (void)state;
    ag_mesh *m = load(DATA "/quad.stl", AG_FORMAT_STL, AG_UP_DEFAULT);
    assert_int_equal(m->ntris, 2);
    ag_box b = ag_mesh_bounds(m);
    /* STL is taken as z-up: the quad stays in the z = 0 plane */
    assert_true(fabs(b.max[0] - 2) < 1e-6 && fabs(b.max[1] - 1) < 1e-6 && fabs(b.max[2]) < 1e-6);
    ag_mesh_free(m);
    m = load(DATA "/quad.ply", AG_FORMAT_PLY, AG_UP_DEFAULT);
    assert_int_equal(m->ntris, 2); /* the quad face is triangulated */
    ag_mesh_free(m);
    /* an explicit y-up turns it upright */
    m = load(DATA "/quad.ply", AG_FORMAT_PLY, AG_UP_Y);
    b = ag_mesh_bounds(m);
    assert_true(fabs(b.max[2] - 1) < 1e-6 && fabs(b.min[1]) < 1e-6 && fabs(b.max[1]) < 1e-6);
    ag_mesh_free(m);
}

/* STL sniffed from its content (an upload without ?format=): ASCII, and binary whose header
 * begins with "solid" as many exporters write it; a text that only begins with "solid" is
 * not taken for one. */
static void test_stl_sniffed(void **state)
{
    (void)state;
    const char *ascii = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
                        "   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n";
    assert_int_equal(ag_format_sniff((const uint8_t *)ascii, strlen(ascii), NULL), AG_FORMAT_STL);
    uint8_t bin[84 + 50] = {0};
    memcpy(bin, "solid but binary", 16);
    bin[80] = 1;
    float v[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(bin + 84, v, sizeof v);
    assert_int_equal(ag_format_sniff(bin, sizeof bin, NULL), AG_FORMAT_STL);
    ag_mesh *m = NULL;
    ag_error err = {0};
    assert_int_equal(ag_import_buffer(bin, sizeof bin, AG_FORMAT_UNKNOWN, NULL, &m, &err), AG_OK);
    assert_int_equal(m->ntris, 1);
    ag_mesh_free(m);
    /* one byte more or less is no binary STL */
    assert_int_equal(ag_format_sniff(bin, sizeof bin - 1, NULL), AG_FORMAT_UNKNOWN);
    const char *words = "solid ground is what a building needs\n";
    assert_int_equal(ag_format_sniff((const uint8_t *)words, strlen(words), NULL),
                     AG_FORMAT_UNKNOWN);
}

/* A PLY mesh in double at UTM coordinates keeps the file's values (assimp holds floats: 0.5 m
 * steps at a northing of 5.4e6), in ASCII and binary. */
static void test_ply_double_positions(void **state)
{
    (void)state;
    const double X = 678088.123456, Y = 5403784.654321, Z = 413.017;
    const double p[4][3] = {{X, Y, Z}, {X + 1.001, Y, Z}, {X + 1.001, Y + 0.3337, Z}, {X, Y + 0.3337, Z + 2.25}};
    char text[1024];
    int n = snprintf(text, sizeof text,
                     "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                     "property double z\nelement face 1\nproperty list uchar int vertex_indices\n"
                     "end_header\n");
    for (int i = 0; i < 4; i++)
        n += snprintf(text + n, sizeof text - (size_t)n, "%.6f %.6f %.6f\n", p[i][0], p[i][1], p[i][2]);
    n += snprintf(text + n, sizeof text - (size_t)n, "4 0 1 2 3\n");
    uint8_t bin[512];
    const char *head = "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double x\n"
                       "property double y\nproperty double z\nelement face 1\n"
                       "property list uchar int vertex_indices\nend_header\n";
    size_t bn = strlen(head);
    memcpy(bin, head, bn);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            uint64_t u;
            memcpy(&u, &p[i][k], 8);
            for (int b = 7; b >= 0; b--)
                bin[bn++] = (uint8_t)(u >> (8 * b));
        }
    const uint8_t face[17] = {4, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3};
    memcpy(bin + bn, face, sizeof face);
    bn += sizeof face;
    const uint8_t *files[2] = {(const uint8_t *)text, bin};
    size_t lens[2] = {(size_t)n, bn};
    for (int f = 0; f < 2; f++) {
        ag_import_options o = {.up = AG_UP_Z};
        ag_mesh *m = NULL;
        ag_error err = {0};
        assert_int_equal(ag_import_buffer(files[f], lens[f], AG_FORMAT_PLY, &o, &m, &err), AG_OK);
        assert_int_equal(m->nverts, 4);
        assert_int_equal(m->ntris, 2);
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++)
                if (fabs(m->pos[3 * i + k] - p[i][k]) > 1e-6)
                    fail_msg("file %d vertex %d axis %d: %.6f, not %.6f", f, i, k, m->pos[3 * i + k],
                             p[i][k]);
        ag_mesh_free(m);
    }
}

static void test_gltf_node_becomes_a_group(void **state)
{
    (void)state;
    ag_mesh *m = load(DATA "/tri.gltf", AG_FORMAT_UNKNOWN, AG_UP_DEFAULT);
    assert_int_equal(m->ntris, 1);
    assert_int_equal(m->ngroups, 1);
    assert_string_equal(m->group_names[0], "Window");
    /* translated by 10 along x; glTF's +y (the triangle's height 2) becomes +z */
    ag_box b = ag_mesh_bounds(m);
    assert_true(fabs(b.min[0] - 10) < 1e-6 && fabs(b.max[0] - 11) < 1e-6);
    assert_true(fabs(b.max[2] - 2) < 1e-6);
    ag_mesh_free(m);
}

static void test_collada_z_up(void **state)
{
    (void)state;
    ag_mesh *m = load(DATA "/tri.dae", AG_FORMAT_DAE, AG_UP_DEFAULT);
    assert_int_equal(m->ntris, 1);
    assert_int_equal(m->ngroups, 1);
    assert_non_null(strstr(m->group_names[0], "Door"));
    /* Z_UP in the file: after assimp's y-up scene and our turn back, the node sits 5 up */
    ag_box b = ag_mesh_bounds(m);
    assert_true(fabs(b.min[2] - 5) < 1e-5 && fabs(b.max[2] - 5) < 1e-5);
    assert_true(fabs(b.max[1] - 2) < 1e-5);
    ag_mesh_free(m);
}

static void test_garbage_is_an_error(void **state)
{
    (void)state;
    const char junk[] = "glTF\x02\0\0\0garbage that is not a valid binary glTF";
    ag_mesh *m = NULL;
    ag_error err = {0};
    assert_int_not_equal(ag_import_buffer((const uint8_t *)junk, sizeof junk, AG_FORMAT_GLB, NULL,
                                          &m, &err),
                         AG_OK);
    assert_null(m);
    assert_true(strlen(err.text) > 0);
    /* a truncated PLY header (assimp itself would spin on it) */
    const char ply[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n";
    assert_int_not_equal(ag_import_buffer((const uint8_t *)ply, sizeof ply - 1, AG_FORMAT_PLY,
                                          NULL, &m, &err),
                         AG_OK);
    assert_null(m);
}

/* A PLY mesh's header is checked by archgram's reader before assimp sees it: an end_header
 * glued to the line before (assimp 5.2 loops on it forever: this test would hang) and counts
 * of rows the bytes after the header cannot hold (assimp spent 10 s and 1.2 GB on a 180-byte
 * file declaring 1e8 vertices) are refused at once, naming the line or the element. */
static void test_ply_header_checked_before_assimp(void **state)
{
    (void)state;
    static const char head[] = "ply\nformat %s 1.0\nelement vertex %s\nproperty float x\n"
                               "property float y\nproperty float z\nelement face %s\n"
                               "property list uchar int vertex_indices\nend_header\n";
    static const char ascii_rows[] = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    /* (0,0,0) (1,0,0) (0,1,0) as floats, then the face 3: 0 1 2 */
    static const uint8_t binary_rows[49] = {[15] = 0x3f, [14] = 0x80, [31] = 0x3f, [30] = 0x80,
                                            [36] = 3, [41] = 1, [45] = 2};
    static const struct {
        const char *format, *vertices, *faces;
        const char *want; /* in the message; NULL: imports */
    } cases[] = {
        {"ascii", "3", "1", NULL},
        {"binary_little_endian", "3", "1", NULL},
        {"ascii", "100000000", "1", "declares 100000000 vertex rows of at least 6 bytes"},
        {"ascii", "3", "4000000000", "declares 4000000000 face rows"},
        {"binary_little_endian", "100000000", "1", "declares 100000000 vertex rows of at least 12"},
        {"binary_little_endian", "3", "100000000", "declares 100000000 face rows of at least 1"},
        /* rows that fit one by one but not together */
        {"binary_little_endian", "4", "2", "declares 2 face rows"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int binary = cases[i].format[0] == 'b';
        char text[512];
        int n = snprintf(text, sizeof text, head, cases[i].format, cases[i].vertices,
                         cases[i].faces);
        size_t rows = binary ? sizeof binary_rows : strlen(ascii_rows);
        memcpy(text + n, binary ? (const void *)binary_rows : ascii_rows, rows);
        ag_mesh *m = (ag_mesh *)1;
        ag_error err = {0};
        ag_status st = ag_import_buffer((const uint8_t *)text, (size_t)n + rows, AG_FORMAT_PLY,
                                        NULL, &m, &err);
        if (!cases[i].want) {
            if (st != AG_OK)
                fail_msg("case %zu: %s", i, err.text);
            assert_int_equal(m->ntris, 1);
            ag_mesh_free(m);
            continue;
        }
        if (st != AG_ERR_PARSE || !strstr(err.text, cases[i].want))
            fail_msg("case %zu: status %d, %s", i, st, err.text);
        assert_null(m);
    }
    /* the glued end_header: no end_header line, the first row is taken for a keyword */
    const char glued[] = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                         "property float y\nproperty float z\nelement face 1\n"
                         "property list uchar int vertex_indice\x89\xf5" "end_header\n"
                         "0 0 0\n2 0 0\n2 1 0\n0  0\n14 0 1 2 3\n";
    ag_mesh *m = (ag_mesh *)1;
    ag_error err = {0};
    assert_int_equal(ag_import_buffer((const uint8_t *)glued, sizeof glued - 1, AG_FORMAT_PLY,
                                      NULL, &m, &err),
                     AG_ERR_PARSE);
    assert_null(m);
    assert_int_equal(err.element, 9);
    assert_non_null(strstr(err.text, "line 9: unknown header keyword '0'"));
}

/* A PLY of the four corners of a unit square and the faces given (each: its corner count,
 * then its corners), in format fmt (0 ascii, 1 little-endian, 2 big-endian); cut: bytes
 * dropped from the end. Returns the length written into out. */
static size_t square_ply(int fmt, const int *faces, size_t nfaces, size_t cut, uint8_t *out)
{
    static const char *const names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    int n = sprintf((char *)out,
                    "ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                    "property float z\nelement face %zu\nproperty list uchar int vertex_indices\n"
                    "end_header\n",
                    names[fmt], nfaces);
    uint8_t *p = out + n;
    static const float xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    for (int v = 0; v < 4; v++)
        for (int a = 0; a < 3; a++) {
            if (!fmt) {
                p += sprintf((char *)p, a < 2 ? "%g " : "%g\n", xyz[v][a]);
                continue;
            }
            uint8_t b[4];
            memcpy(b, &xyz[v][a], 4);
            for (int k = 0; k < 4; k++)
                *p++ = b[fmt == 1 ? k : 3 - k]; /* a little-endian host */
        }
    const int *f = faces;
    for (size_t i = 0; i < nfaces; i++) {
        int count = *f++;
        if (!fmt)
            p += sprintf((char *)p, "%d", count);
        else
            *p++ = (uint8_t)count;
        for (int j = 0; j < count; j++, f++) {
            if (!fmt) {
                p += sprintf((char *)p, " %d", *f);
                continue;
            }
            uint8_t b[4];
            memcpy(b, f, 4);
            for (int k = 0; k < 4; k++)
                *p++ = b[fmt == 1 ? k : 3 - k];
        }
        if (!fmt)
            *p++ = '\n';
    }
    return (size_t)(p - out) - cut;
}

/* The faces are checked before assimp sees them: a face without corners made assimp abort
 * (an assertion in its triangulation), a file cut inside its face list made it invent
 * triangles, an index past the vertices was its own validation's message. Each is now
 * refused naming the face (binary) or the line (ASCII), in every encoding. */
static void test_ply_faces_checked_before_assimp(void **state)
{
    (void)state;
    static const int good[] = {3, 0, 1, 2, 3, 0, 2, 3};
    static const int no_corners[] = {3, 0, 1, 2, 0};
    static const int past_end[] = {3, 0, 1, 2, 3, 0, 2, 9};
    static const int negative[] = {3, 0, 1, 2, 3, -1, 2, 3};
    static const int a_line[] = {3, 0, 1, 2, 2, 0, 2, 3, 0, 2, 3};
    static const struct {
        const int *faces;
        size_t nfaces, cut;
        int tris;              /* when it imports */
        const char *want[2];   /* ASCII, binary message parts; NULL: imports */
        long element[2];       /* ASCII line, binary face */
    } cases[] = {
        {good, 2, 0, 2, {NULL, NULL}, {0, 0}},
        {a_line, 3, 0, 2, {NULL, NULL}, {0, 0}}, /* one or two corners: dropped, as before */
        {no_corners, 2, 0, 0, {"line 15: face 2 has no corners", "face 2 has no corners"}, {15, 2}},
        {past_end, 2, 0, 0,
         {"line 15: face 2 names vertex 9, but the vertices are numbered 0 to 3",
          "face 2 names vertex 9, but the vertices are numbered 0 to 3"},
         {15, 2}},
        {negative, 2, 0, 0, {"face 2 names vertex -1", "face 2 names vertex -1"}, {15, 2}},
        /* the last index cut away */
        {good, 2, 2, 0, {"the data ends inside list 'vertex_indices'", "list 'vertex_indices'"},
         {15, 0}},
    };
    uint8_t buf[1024];
    for (int fmt = 0; fmt < 3; fmt++)
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            size_t len = square_ply(fmt, cases[i].faces, cases[i].nfaces, cases[i].cut, buf);
            ag_mesh *m = (ag_mesh *)1;
            ag_error err = {0};
            ag_status st = ag_import_buffer(buf, len, AG_FORMAT_PLY, NULL, &m, &err);
            const char *want = cases[i].want[fmt > 0];
            if (!want) {
                if (st != AG_OK)
                    fail_msg("format %d case %zu: %s", fmt, i, err.text);
                assert_int_equal(m->ntris, cases[i].tris);
                ag_mesh_free(m);
                continue;
            }
            if (st != AG_ERR_PARSE || !strstr(err.text, want))
                fail_msg("format %d case %zu: status %d, %s", fmt, i, st, err.text);
            if (cases[i].element[fmt > 0] && err.element != cases[i].element[fmt > 0])
                fail_msg("format %d case %zu: element %ld, not %ld", fmt, i, err.element,
                         cases[i].element[fmt > 0]);
            assert_null(m);
        }
}

static void test_derived_glb_reads_back(void **state)
{
    (void)state;
    ag_mesh *g;
    ag_gen_facade_options o = {.cols = 3, .rows = 2, .side_cols = 2, .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &g, NULL), AG_OK);
    ag_proceduralize_result *r;
    assert_int_equal(ag_proceduralize_run(g, NULL, &r, NULL), AG_OK);
    ag_mesh *d;
    assert_int_equal(ag_grammar_derive(r->grammar, NULL, &d, NULL), AG_OK);
    uint8_t *glb;
    size_t len;
    ag_error err = {0};
    assert_int_equal(ag_glb_write(d, &glb, &len, &err), AG_OK);
    ag_mesh *back = NULL;
    assert_int_equal(ag_import_buffer(glb, len, AG_FORMAT_GLB, NULL, &back, &err), AG_OK);
    assert_int_equal(back->ntris, g->ntris);
    ag_fidelity f;
    assert_int_equal(ag_grammar_fidelity(g, back, 1e-4, &f, NULL), AG_OK);
    assert_int_equal(f.unmatched, 0);
    assert_true(f.relative < 1e-6); /* GLB stores 32-bit floats */
    free(glb);
    ag_mesh_free(back);
    ag_mesh_free(d);
    ag_proceduralize_result_free(r);
    ag_mesh_free(g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stl_and_ply),
        cmocka_unit_test(test_stl_sniffed),
        cmocka_unit_test(test_ply_double_positions),
        cmocka_unit_test(test_gltf_node_becomes_a_group),
        cmocka_unit_test(test_collada_z_up),
        cmocka_unit_test(test_garbage_is_an_error),
        cmocka_unit_test(test_ply_header_checked_before_assimp),
        cmocka_unit_test(test_ply_faces_checked_before_assimp),
        cmocka_unit_test(test_derived_glb_reads_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
