/* Uploads read by assimp in a child process (app/import_sandbox.h): the same mesh as reading
 * in this process; a file assimp takes far longer over (one polygon of 32 000 corners, which its
 * triangulation takes quadratic time over: about 10 s) stops at the deadline with
 * AG_ERR_DEADLINE and leaves no child behind; progress asking to stop cancels; the
 * importer's own refusals come through with their message, and its crashes as a refusal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>

#include "app/import_sandbox.h"
#include "file_fixture.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* No child of this process is left (running or a zombie). */
static void no_children(void)
{
    errno = 0;
    assert_int_equal(waitpid(-1, NULL, WNOHANG), -1);
    assert_int_equal(errno, ECHILD);
}

/* A binary PLY of one star-shaped polygon with n corners (malloc'd, *len bytes). */
static char *many_sided_ply(unsigned n, size_t *len)
{
    char head[256];
    int h = snprintf(head, sizeof head,
                     "ply\nformat binary_little_endian 1.0\nelement vertex %u\n"
                     "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                     "property list int int vertex_indices\nend_header\n",
                     n);
    *len = (size_t)h + 12 * (size_t)n + 4 + 4 * (size_t)n;
    char *d = malloc(*len), *p = d + h;
    assert_non_null(d);
    memcpy(d, head, (size_t)h);
    for (unsigned i = 0; i < n; i++) {
        double r = i % 2 ? 0.5 : 1.0, a = 2 * M_PI * i / n;
        float v[3] = {(float)(r * cos(a)), (float)(r * sin(a)), 0};
        memcpy(p, v, sizeof v); /* little-endian host */
        p += sizeof v;
    }
    int32_t count = (int32_t)n;
    memcpy(p, &count, 4);
    p += 4;
    for (unsigned i = 0; i < n; i++, p += 4)
        memcpy(p, &i, 4);
    return d;
}

#define SLOW_CORNERS 32000 /* assimp refuses polygons of more than 32767 */

static void the_same_mesh_as_in_process(void **state)
{
    (void)state;
    const char *files[] = {"proc/quad.ply", "proc/quad.stl", "proc/tri.dae", "proc/tri.gltf"};
    for (size_t i = 0; i < 4; i++) {
        size_t len = 0;
        char *data = read_fixture(files[i], &len);
        ag_format fmt = ag_format_sniff((const uint8_t *)data, len, files[i]);
        ag_mesh *a = NULL, *b = NULL;
        ag_error err;
        assert_int_equal(ag_import_buffer((const uint8_t *)data, len, fmt, NULL, &a, &err), AG_OK);
        if (ag_import_sandbox_read((const uint8_t *)data, len, fmt, NULL, 10, &b, &err) != AG_OK)
            fail_msg("%s: %s", files[i], err.text);
        assert_int_equal(a->nverts, b->nverts);
        assert_int_equal(a->ntris, b->ntris);
        assert_int_equal(a->ncomponents, b->ncomponents);
        assert_memory_equal(a->tri, b->tri, 3 * a->ntris * sizeof *a->tri);
        assert_memory_equal(a->pos, b->pos, 3 * a->nverts * sizeof *a->pos);
        ag_mesh_free(a);
        ag_mesh_free(b);
        free(data);
    }
    no_children();
}

static void a_file_slower_than_the_deadline_stops_there(void **state)
{
    (void)state;
    size_t len = 0;
    char *data = many_sided_ply(SLOW_CORNERS, &len);
    ag_mesh *m = NULL;
    ag_error err;
    double t0 = now();
    ag_status s = ag_import_sandbox_read((const uint8_t *)data, len, AG_FORMAT_PLY, NULL, 0.5, &m,
                                         &err);
    double took = now() - t0;
    assert_int_equal(s, AG_ERR_DEADLINE);
    assert_null(m);
    assert_non_null(strstr(err.text, "longer than 0.5 s"));
    assert_true(took >= 0.45 && took < 3.0);
    no_children();
    free(data);
}

static int calls;
static int stop_now(void *user, double fraction)
{
    (void)user, (void)fraction;
    return ++calls >= 2;
}

static void progress_cancels_and_refusals_come_through(void **state)
{
    (void)state;
    size_t len = 0;
    char *data = many_sided_ply(SLOW_CORNERS, &len);
    ag_import_options opt = {.progress = stop_now};
    ag_mesh *m = NULL;
    ag_error err;
    calls = 0;
    assert_int_equal(ag_import_sandbox_read((const uint8_t *)data, len, AG_FORMAT_PLY, &opt, 30,
                                            &m, &err),
                     AG_ERR_CANCELLED);
    no_children();
    free(data);
    /* not a glTF at all: the importer's problem, its message kept */
    const char junk[] = "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": 7}";
    ag_import_options plain = {0};
    ag_status s = ag_import_sandbox_read((const uint8_t *)junk, sizeof junk - 1, AG_FORMAT_GLTF,
                                         &plain, 10, &m, &err);
    assert_int_not_equal(s, AG_OK);
    assert_int_not_equal(s, AG_ERR_INTERNAL);
    assert_true(err.text[0] != '\0');
    no_children();
    /* the 189-byte PLY whose header (end_header glued to a property) sends assimp 5.2 into a
     * loop that never ends is refused by archgram's header check, long before the deadline */
    data = read_fixture("import_sandbox/loops.ply", &len);
    double t0 = now();
    s = ag_import_sandbox_read((const uint8_t *)data, len, AG_FORMAT_PLY, &plain, 30, &m, &err);
    assert_int_equal(s, AG_ERR_PARSE);
    assert_non_null(strstr(err.text, "line 9: unknown header keyword"));
    assert_true(now() - t0 < 5);
    no_children();
    free(data);
}

/* A Collada scene that instances itself (a node holding an instance_node of its own scene)
 * takes assimp down with a segmentation fault: read in the child, it is a refusal of the file
 * and the reader goes on (what the command line, reading every file so, relies on). */
static void a_crash_of_the_importer_is_a_refusal(void **state)
{
    (void)state;
    size_t len = 0;
    char *data = read_fixture("import_sandbox/recursive_scene.dae", &len);
    ag_import_options plain = {0};
    ag_mesh *m = (ag_mesh *)1;
    ag_error err;
    ag_status s = ag_import_sandbox_read((const uint8_t *)data, len, AG_FORMAT_DAE, &plain, 0,
                                         &m, &err);
    assert_int_equal(s, AG_ERR_PARSE);
    assert_null(m);
    if (!strstr(err.text, "the importer crashed on this file"))
        fail_msg("%s", err.text);
    no_children();
    free(data);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_same_mesh_as_in_process),
        cmocka_unit_test(a_file_slower_than_the_deadline_stops_there),
        cmocka_unit_test(progress_cancels_and_refusals_come_through),
        cmocka_unit_test(a_crash_of_the_importer_is_a_refusal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
