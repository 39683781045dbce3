/* Which uploads the point cloud import takes (app/usecase_import_cloud.h): clouds by name and
 * by content, meshes left to the mesh import — a PLY with faces, and a PLY whose header does
 * not parse (the mesh readers answer it, or the sandbox's deadline does), named or sniffed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/usecase_import_cloud.h"

/* A temporary file holding text; its path in path. */
static void write_temp(char *path, size_t len, const char *text, size_t n)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(path, len, "%s/ag_test_import_cloud_XXXXXX", tmp && tmp[0] ? tmp : P_tmpdir);
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, text, n), (ssize_t)n);
    close(fd);
}

static int accepts(const char *text, size_t n, const char *format, const char *filename)
{
    char path[1024];
    write_temp(path, sizeof path, text, n);
    ag_mesh_source src = {.path = path, .format = format, .filename = filename};
    int yes = ag_usecase_import_cloud_accepts(&src);
    unlink(path);
    return yes;
}

#define ACCEPTS(text, format, filename) accepts(text, sizeof text - 1, format, filename)

static const char POINTS_PLY[] = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                 "property float y\nproperty float z\nend_header\n0 0 0\n1 2 3\n";
static const char MESH_PLY[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
/* the end of the header run into bytes that are not text: no parsable header */
static const char BROKEN_PLY[] = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 1\n"
                                 "property list uchar int vertex_indice\x89\xf5"
                                 "end_header\n0 0 0\n2 0 0\n2 1 0\n0  0\n14 0 1 2 3\n";
static const char NO_VERTICES_PLY[] = "ply\nformat ascii 1.0\nend_header\n";
static const char XYZ[] = "1.5 2.5 3.5\n4 5 6\n7 8 9\n";
static const char OBJ[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

static void clouds_by_name_and_content(void **state)
{
    (void)state;
    assert_int_equal(ACCEPTS(POINTS_PLY, "ply", NULL), 1);
    assert_int_equal(ACCEPTS(POINTS_PLY, NULL, "scan.ply"), 1);
    assert_int_equal(ACCEPTS(XYZ, NULL, "scan.txt"), 1);
    assert_int_equal(ACCEPTS(XYZ, "xyz", NULL), 1);
    /* las, laz and xyz by name are clouds whatever the bytes (their reader names the fault) */
    assert_int_equal(ACCEPTS(OBJ, "las", NULL), 1);
    assert_int_equal(ACCEPTS(OBJ, "laz", NULL), 1);
}

static void meshes_stay_meshes(void **state)
{
    (void)state;
    assert_int_equal(ACCEPTS(MESH_PLY, "ply", NULL), 0);
    assert_int_equal(ACCEPTS(MESH_PLY, NULL, "house.ply"), 0);
    assert_int_equal(ACCEPTS(OBJ, NULL, "house.obj"), 0);
    assert_int_equal(ACCEPTS(POINTS_PLY, "obj", NULL), 0); /* a mesh format by name */
    /* a header that does not parse says nothing of faces: the mesh import answers it */
    assert_int_equal(ACCEPTS(BROKEN_PLY, "ply", NULL), 0);
    assert_int_equal(ACCEPTS(BROKEN_PLY, NULL, "loops.ply"), 0);
    assert_int_equal(ACCEPTS(NO_VERTICES_PLY, "ply", NULL), 0);
    /* a file that cannot be read is not a cloud */
    ag_mesh_source missing = {.path = "/nonexistent/archgram/cloud.ply", .format = "ply"};
    assert_int_equal(ag_usecase_import_cloud_accepts(&missing), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(clouds_by_name_and_content),
        cmocka_unit_test(meshes_stay_meshes),
    };
    return cmocka_run_group_tests_name("usecase_import_cloud", tests, NULL, NULL);
}
