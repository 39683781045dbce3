/* A large OBJ read in two parts at once (io/obj.h split_bytes, with the runner of
 * app/threads.h installed) gives what a read in turn gives: the same mesh byte for byte
 * (ag_mesh_difference), or the same status, line and message. Each text is read with the
 * split moved across every one of its lines (comment lines put before and after it), so the
 * later part starts inside groups, before and after g/o lines, next to a continued line,
 * with negative indices reaching back into the first part, `vt`/`vn` counts from the first
 * part, CRLF ends and comments; and with errors in either part or in both (the first one
 * in the file is reported, with its line). */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "app/threads.h"
#include "core/base/parallel.h"
#include "io/obj.h"

typedef struct {
    ag_status st;
    ag_mesh *m;
    ag_error err;
} outcome;

static outcome read_text(const char *text, size_t len, int split, size_t max_vertices)
{
    outcome o = {0};
    if (split)
        ag_threads_install();
    else
        ag_parallel_install(NULL, 0);
    ag_obj_read_options opt = {.up = AG_UP_Z, .split_bytes = split ? 1 : SIZE_MAX,
                               .max_vertices = max_vertices};
    o.st = ag_obj_read_buffer(text, len, &opt, &o.m, &o.err);
    ag_parallel_install(NULL, 0);
    return o;
}

/* text with pad comment lines before it: read in turn and split, compared */
static void check_same(const char *body, size_t max_vertices, ag_status expect)
{
    size_t blen = strlen(body), lines = 0;
    for (size_t i = 0; i < blen; i++)
        lines += body[i] == '\n';
    /* comment lines before and after body, so that the middle moves across every line */
    size_t all = 2 * lines + 2;
    for (size_t pad = 0; pad <= all; pad++) {
        size_t cap = blen + 8 * all + 1;
        char *text = malloc(cap);
        size_t n = 0;
        for (size_t k = 0; k < pad; k++)
            n += (size_t)snprintf(text + n, cap - n, "# pad\n");
        memcpy(text + n, body, blen + 1);
        n += blen;
        for (size_t k = pad; k < all; k++)
            n += (size_t)snprintf(text + n, cap - n, "# end\n");
        outcome a = read_text(text, n, 0, max_vertices), b = read_text(text, n, 1, max_vertices);
        if (a.st != b.st || a.err.element != b.err.element || strcmp(a.err.text, b.err.text))
            fail_msg("pad %zu: in turn %d line %ld '%s', split %d line %ld '%s'", pad, a.st,
                     a.err.element, a.err.text, b.st, b.err.element, b.err.text);
        assert_int_equal(a.st, expect);
        if (a.st == AG_OK) {
            const char *d = ag_mesh_difference(a.m, b.m);
            if (*d)
                fail_msg("pad %zu: the split read's %s differ", pad, d);
        }
        ag_mesh_free(a.m);
        ag_mesh_free(b.m);
        free(text);
    }
}

static const char mixed[] =
    "# a house\r\n"
    "mtllib house.mtl\r\n"
    "v 0 0 0\r\n"
    "v 1 0 0\r\n"
    "v 1 1 0\r\n"
    "v 0 1 0\r\n"
    "vt 0 0\r\n"
    "vt 1 0\r\n"
    "vn 0 0 1\r\n"
    "f 1/1/1 2/2/1 3/1/1\r\n"          /* before any group: a group-less component */
    "g wall\r\n"
    "usemtl brick\r\n"
    "f 1//1 3//1 4//1 # a comment\r\n"
    "v 2 0 0\n"
    "v 2 1 0\n"
    "f -1 -2 -4\n"                     /* relative: may reach into the first part */
    "f -3/-1 -4/-2 -5/-1\n"
    "g roof\n"
    "v 0 0 1\n"
    "v 1 0 1\n"
    "v 1 1 1\n"
    "f 7 8 9\n"
    "f -3 -2 -1 -5\n"                  /* a quad, fanned */
    "o\n"
    "g wall\n"                         /* the wall again: its component goes on */
    "f 1 5 6 3\n"
    "f 1 1 2\n"                        /* degenerate: dropped */
    "f 2 -7 3\n"                       /* absolute and relative together */
    "g window \\\n  pane\n"            /* a continued group name */
    "v 5 5 5\n"
    "v 6 5 5\n"
    "v 6 6 5\n"
    "f -1 -2 -3\n"
    "vn 1 0 0\n"
    "f 10//2 11//2 12//1\n"
    "g\n"
    "f 1 2 4\n"
    "g wall\n"
    "f 4 3 2\n";

static void test_mixed_file_reads_the_same_split_anywhere(void **state)
{
    (void)state;
    check_same(mixed, 0, AG_OK);
}

static void test_groupless_file_reads_the_same(void **state)
{
    (void)state;
    /* no group at all: the connected pieces become the components after the merge */
    check_same("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n"
               "v 9 9 9\nv 8 9 9\nv 9 8 9\nf -1 -2 -3\nf 4 6 5\n",
               0, AG_OK);
}

static void test_errors_are_those_of_a_read_in_turn(void **state)
{
    (void)state;
    static const char *bad[] = {
        /* an index past the vertices so far, late in the file */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ng a\nf 1 2 3\nf 1 2 4\nv 1 1 1\nf 1 2 4\n",
        /* a relative index reaching before the first vertex */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf -1 -2 -3\ng b\nf -1 -2 -4\n",
        /* a texture index past the vt lines so far */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\ng c\nf 1/1 2/2 3/1\nvt 1 1\n",
        /* a normal index 0, and a face index 0 */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//0 2//1 3//1\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nf 0 1 2\n",
        /* a bad coordinate late, and two errors (the first is reported) */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nv 1 nan 0\n",
        "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nf 1 2 9\n",
        /* a face with two vertices, and binary-looking data */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\nf 1 2\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 3\n\x01\x02 junk\n",
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        check_same(bad[i], 0, AG_ERR_PARSE);
}

static void test_limits_are_those_of_a_read_in_turn(void **state)
{
    (void)state;
    /* 5 vertices allowed: the sixth, in the later part, is refused at its line */
    check_same("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 2 0 0\nv 3 0 0\nf 1 4 5\nv 4 0 0\n"
               "f 1 5 6\n",
               5, AG_ERR_PARSE);
}

static void test_a_split_large_file_reads_the_same(void **state)
{
    (void)state;
    /* a few thousand lines: the default threshold is not needed, split_bytes is 1 */
    size_t cap = 1 << 20, n = 0;
    char *text = malloc(cap);
    for (int k = 0; k < 2000; k++) {
        n += (size_t)snprintf(text + n, cap - n,
                              "g part%d\nv %d 0 0\nv %d 1 0\nv %d 0 1\nvt 0 %d\nf -3/-1 -2/-1 -1/-1\n"
                              "f %d %d %d\n",
                              k % 7, k, k, k, k, 3 * k + 1, 3 * k + 3, 3 * k + 2);
    }
    outcome a = read_text(text, n, 0, 0), b = read_text(text, n, 1, 0);
    assert_int_equal(a.st, AG_OK);
    assert_int_equal(b.st, AG_OK);
    assert_string_equal(ag_mesh_difference(a.m, b.m), "");
    assert_int_equal(a.m->ntris, 4000);
    assert_int_equal(a.m->ncomponents, 7);
    ag_mesh_free(a.m);
    ag_mesh_free(b.m);
    free(text);
}

/* Every OBJ of the shared data sets (buildings with groups, one-object meshes split into
 * their connected pieces), read split and in turn. */
static void test_shared_files_read_the_same(void **state)
{
    (void)state;
    static const char *dirs[] = {AG_REPO_DIR "/../shared/data/lod3_ingolstadt/obj",
                                 AG_REPO_DIR "/../shared/data/meshes_0ad"};
    size_t files = 0;
    for (size_t d = 0; d < sizeof dirs / sizeof *dirs; d++) {
        DIR *dir = opendir(dirs[d]);
        if (!dir) {
            printf("skipping: %s is absent\n", dirs[d]);
            skip();
        }
        struct dirent *e;
        while ((e = readdir(dir))) {
            size_t n = strlen(e->d_name);
            if (n < 5 || strcmp(e->d_name + n - 4, ".obj"))
                continue;
            char path[2048];
            snprintf(path, sizeof path, "%s/%s", dirs[d], e->d_name);
            ag_mesh *a = NULL, *b = NULL;
            ag_error ea, eb;
            ag_parallel_install(NULL, 0);
            ag_obj_read_options o = {.up = AG_UP_Y, .split_bytes = SIZE_MAX};
            assert_int_equal(ag_obj_read_file(path, &o, &a, &ea), AG_OK);
            ag_threads_install();
            o.split_bytes = 1;
            assert_int_equal(ag_obj_read_file(path, &o, &b, &eb), AG_OK);
            ag_parallel_install(NULL, 0);
            const char *diff = ag_mesh_difference(a, b);
            if (*diff)
                fail_msg("%s: the split read's %s differ", path, diff);
            ag_mesh_free(a);
            ag_mesh_free(b);
            files++;
        }
        closedir(dir);
    }
    assert_true(files > 40);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mixed_file_reads_the_same_split_anywhere),
        cmocka_unit_test(test_groupless_file_reads_the_same),
        cmocka_unit_test(test_errors_are_those_of_a_read_in_turn),
        cmocka_unit_test(test_limits_are_those_of_a_read_in_turn),
        cmocka_unit_test(test_a_split_large_file_reads_the_same),
        cmocka_unit_test(test_shared_files_read_the_same),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
