/* Shared by the tests that read files whole (test_optable.c, test_workspace.c,
 * test_import_sandbox.c). Header-only
 * because every test file is its own binary; include it after <cmocka.h>. */
#ifndef AG_TEST_FILE_FIXTURE_H
#define AG_TEST_FILE_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>

/* The file's bytes, NUL-terminated (malloc'd), and their number in *len (may be NULL); fails
 * the test when it cannot be read. */
static inline char *read_file_bytes(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        fail_msg("cannot read %s", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    char *text = malloc((size_t)n + 1);
    assert_int_equal(fread(text, 1, (size_t)n, f), (size_t)n);
    text[n] = '\0';
    fclose(f);
    if (len)
        *len = (size_t)n;
    return text;
}

static inline char *read_text_file(const char *path)
{
    return read_file_bytes(path, NULL);
}

#ifdef AG_REPO_DIR
/* A file of tests/data by its name there. */
static inline char *read_fixture(const char *name, size_t *len)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/tests/data/%s", AG_REPO_DIR, name);
    return read_file_bytes(path, len);
}
#endif

#endif
