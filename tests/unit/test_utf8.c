/* UTF-8 in messages: ag_error texts cut between characters at every cut position of 1- to
 * 4-byte characters; strict validation (overlong forms, surrogates, past U+10FFFF, stray and
 * missing continuation bytes); repair of input quoted in a detail; and problems that are always
 * valid JSON, down to the fallback written without allocating. Every check uses jansson's own
 * validation as the independent judge. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/problem.h"
#include "core/status.h"
#include "core/utf8.h"

/* jansson's verdict: the bytes are valid UTF-8 */
static int jansson_valid(const char *s, size_t len)
{
    json_t *v = json_stringn(s, len);
    json_decref(v);
    return v != NULL;
}

static void error_texts_are_cut_between_characters(void **state)
{
    (void)state;
    const char *chars[] = {"a", "\xc3\xa9", "\xe2\x82\xac", "\xf0\x9d\x84\x9e"};
    for (size_t c = 0; c < 4; c++)
        for (size_t pad = 0; pad < 5; pad++) {
            char arg[1400] = "";
            memset(arg, 'x', pad);
            arg[pad] = '\0';
            for (int k = 0; k < 300; k++)
                strcat(arg, chars[c]);
            ag_error err;
            ag_error_set(&err, AG_ERR_INVALID, 0, "member \"%s\"", arg);
            size_t n = strlen(err.text);
            assert_true(n < AG_ERROR_TEXT);
            assert_true(n >= AG_ERROR_TEXT - 4); /* at most a character short */
            assert_true(jansson_valid(err.text, n));
            assert_int_equal(ag_utf8_valid_prefix(err.text, n), n);
            /* what is kept is the start of the whole text */
            char whole[2048];
            snprintf(whole, sizeof whole, "member \"%s\"", arg);
            assert_memory_equal(err.text, whole, n);
        }
}

static void validation_is_strict(void **state)
{
    (void)state;
    static const struct {
        const char *s;
        int valid;
    } cases[] = {
        {"plain", 1},
        {"\xc3\xa9t\xc3\xa9", 1},
        {"\xf4\x8f\xbf\xbf", 1},  /* U+10FFFF */
        {"\xef\xbf\xbd", 1},      /* U+FFFD */
        {"\xc0\xaf", 0},          /* overlong '/' */
        {"\xe0\x80\xaf", 0},      /* overlong */
        {"\xf0\x80\x80\xaf", 0},  /* overlong */
        {"\xed\xa0\x80", 0},      /* a surrogate */
        {"\xf4\x90\x80\x80", 0},  /* past U+10FFFF */
        {"\xf5\x80\x80\x80", 0},
        {"\x80", 0},              /* a stray continuation */
        {"\xc3", 0},              /* cut short */
        {"\xe2\x82", 0},
        {"\xff", 0},
        {"a\xc3(", 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t n = strlen(cases[i].s);
        assert_int_equal(ag_utf8_valid_prefix(cases[i].s, n) == n, cases[i].valid);
        assert_int_equal(jansson_valid(cases[i].s, n), cases[i].valid);
    }
    /* every 1- and 2-byte sequence agrees with jansson */
    for (unsigned a = 0; a < 256; a++)
        for (unsigned b = 0; b < 256; b++) {
            char s[2] = {(char)a, (char)b};
            if (!a)
                continue;
            size_t n = b ? 2 : 1;
            assert_int_equal(ag_utf8_valid_prefix(s, n) == n, jansson_valid(s, n));
        }
}

static void repair_replaces_bad_bytes_and_fits(void **state)
{
    (void)state;
    char out[64];
    const char *in = "ok\xff\xc3(\xe2\x82\xac";
    size_t n = ag_utf8_repair(in, strlen(in), out, sizeof out);
    assert_string_equal(out, "ok\xef\xbf\xbd\xef\xbf\xbd(\xe2\x82\xac");
    assert_int_equal(n, strlen(out));
    /* too small a buffer: cut on a boundary, still valid */
    char small[6];
    n = ag_utf8_repair("\xe2\x82\xac\xe2\x82\xac\xe2\x82\xac", 9, small, sizeof small);
    assert_int_equal(n, 3);
    assert_true(jansson_valid(small, n));
}

static void problems_are_always_valid_json(void **state)
{
    (void)state;
    ag_error err;
    err.code = AG_ERR_PARSE;
    err.element = 12;
    /* bytes of a file quoted raw, invalid UTF-8 included */
    memcpy(err.text, "line 12: \xff\xfe bad \xc3", 16);
    err.text[16] = '\0';
    char *text = ag_problem_text(AG_ERR_PARSE, &err);
    assert_non_null(text);
    json_t *p = json_loads(text, 0, NULL);
    assert_non_null(p);
    assert_string_equal(json_string_value(json_object_get(p, "type")), "urn:archgram:problem:parse");
    assert_int_equal(json_integer_value(json_object_get(p, "line")), 12);
    assert_non_null(strstr(json_string_value(json_object_get(p, "detail")), "bad"));
    json_decref(p);
    free(text);
    /* the fallback of every status parses and carries its status */
    for (int s = 0; s >= -60; s--) {
        if (strcmp(ag_status_name((ag_status)s), "AG_ERR_INTERNAL") == 0 && s != AG_ERR_INTERNAL)
            continue; /* no such status */
        char buf[AG_PROBLEM_FALLBACK_MAX];
        size_t n = ag_problem_fallback((ag_status)s, buf, sizeof buf);
        assert_true(n > 0 && n < sizeof buf);
        json_t *f = json_loadb(buf, n, 0, NULL);
        assert_non_null(f);
        assert_int_equal(json_integer_value(json_object_get(f, "status")),
                         ag_status_http((ag_status)s));
        json_decref(f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(error_texts_are_cut_between_characters),
        cmocka_unit_test(validation_is_strict),
        cmocka_unit_test(repair_replaces_bad_bytes_and_fits),
        cmocka_unit_test(problems_are_always_valid_json),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
