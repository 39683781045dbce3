/* Shared by the tests that read files whole (test_optable.c, test_workspace.c). Header-only
 * because every test file is its own binary; include it after <cmocka.h>. */
#ifndef AG_TEST_FILE_FIXTURE_H
#define AG_TEST_FILE_FIXTURE_H

#include <stdio.h>
#include <stdlib.h>

/* The file's bytes, NUL-terminated (malloc'd); fails the test when it cannot be read. */
static inline char *read_text_file(const char *path)
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
    return text;
}

#endif
