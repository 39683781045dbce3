/* The read-only JSON document (yajl events into one node array): values of every type,
 * member order, integers told from reals, escaped strings, deep nesting, and syntax errors
 * with their line and column, never a crash. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "io/jsondoc.h"

static ag_jsondoc *parse(const char *text)
{
    ag_jsondoc *d = NULL;
    ag_error err = {0};
    ag_status st = ag_jsondoc_parse(text, strlen(text), &d, &err);
    if (st != AG_OK)
        fail_msg("%s: %s", text, err.text);
    return d;
}

static void test_values(void **state)
{
    (void)state;
    ag_jsondoc *d = parse("{\"type\": \"Feature\", \"id\": 17, \"h\": 3.5, \"e\": 1e2, \"big\": "
                          "12345678901234567890, \"t\": true, \"f\": false, \"n\": null, "
                          "\"s\": \"a\\\"b\\u00e9\\n\", \"a\": [1, [2, 3], {}], \"id\": 18}");
    uint32_t r = ag_jsondoc_root(d);
    assert_int_equal(ag_jsondoc_type(d, r), AG_JSON_OBJECT);
    assert_int_equal(ag_jsondoc_size(d, r), 11);
    assert_string_equal(ag_jsondoc_string(d, ag_jsondoc_get(d, r, "type")), "Feature");
    int64_t v = 0;
    assert_true(ag_jsondoc_integer(d, ag_jsondoc_get(d, r, "id"), &v));
    assert_int_equal(v, 17); /* the first of two equal keys */
    assert_false(ag_jsondoc_integer(d, ag_jsondoc_get(d, r, "h"), &v));
    assert_true(ag_jsondoc_number(d, ag_jsondoc_get(d, r, "h")) == 3.5);
    assert_false(ag_jsondoc_integer(d, ag_jsondoc_get(d, r, "e"), &v));
    assert_true(ag_jsondoc_number(d, ag_jsondoc_get(d, r, "e")) == 100);
    /* beyond int64: a number, not an integer */
    assert_false(ag_jsondoc_integer(d, ag_jsondoc_get(d, r, "big"), &v));
    assert_true(ag_jsondoc_number(d, ag_jsondoc_get(d, r, "big")) == 12345678901234567890.0);
    assert_int_equal(ag_jsondoc_type(d, ag_jsondoc_get(d, r, "t")), AG_JSON_TRUE);
    assert_int_equal(ag_jsondoc_type(d, ag_jsondoc_get(d, r, "f")), AG_JSON_FALSE);
    assert_int_equal(ag_jsondoc_type(d, ag_jsondoc_get(d, r, "n")), AG_JSON_NULL);
    assert_string_equal(ag_jsondoc_string(d, ag_jsondoc_get(d, r, "s")), "a\"b\xc3\xa9\n");
    assert_int_equal(ag_jsondoc_get(d, r, "missing"), AG_JSONDOC_NONE);
    uint32_t a = ag_jsondoc_get(d, r, "a");
    assert_int_equal(ag_jsondoc_size(d, a), 3);
    assert_true(ag_jsondoc_number(d, ag_jsondoc_at(d, a, 0)) == 1);
    uint32_t inner = ag_jsondoc_at(d, a, 1);
    assert_int_equal(ag_jsondoc_size(d, inner), 2);
    assert_true(ag_jsondoc_number(d, ag_jsondoc_next(d, ag_jsondoc_first(d, inner))) == 3);
    assert_int_equal(ag_jsondoc_type(d, ag_jsondoc_at(d, a, 2)), AG_JSON_OBJECT);
    assert_int_equal(ag_jsondoc_size(d, ag_jsondoc_at(d, a, 2)), 0);
    assert_int_equal(ag_jsondoc_at(d, a, 3), AG_JSONDOC_NONE);
    /* lookups on the wrong type find nothing */
    assert_int_equal(ag_jsondoc_get(d, a, "x"), AG_JSONDOC_NONE);
    assert_int_equal(ag_jsondoc_at(d, r, 0), AG_JSONDOC_NONE);
    assert_null(ag_jsondoc_string(d, a));
    assert_int_equal(ag_jsondoc_type(d, AG_JSONDOC_NONE), AG_JSON_NULL);
    ag_jsondoc_free(d);
    d = parse("  42  ");
    assert_true(ag_jsondoc_number(d, ag_jsondoc_root(d)) == 42);
    ag_jsondoc_free(d);
}

static void test_deep(void **state)
{
    (void)state;
    size_t depth = 100000;
    char *text = malloc(2 * depth + 1);
    memset(text, '[', depth);
    memset(text + depth, ']', depth);
    text[2 * depth] = '\0';
    ag_jsondoc *d = parse(text);
    uint32_t n = ag_jsondoc_root(d);
    size_t k = 0;
    while (ag_jsondoc_first(d, n) != AG_JSONDOC_NONE) {
        n = ag_jsondoc_first(d, n);
        k++;
    }
    assert_int_equal(k, depth - 1);
    ag_jsondoc_free(d);
    free(text);
}

static void test_errors(void **state)
{
    (void)state;
    const struct {
        const char *text;
        long line;
    } bad[] = {
        {"", 1},
        {"{\"a\": [1, 2,]}", 1},
        {"{\n  \"a\": 1,\n  \"b\": tru\n}", 3},
        {"{\"a\": 1} {\"b\": 2}", 1},
        {"[1, 2", 1},
        {"{\"a\" 1}", 1},
        {"\x01\x02", 1},
        {"[\"\xff\xfe\"]", 1},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_jsondoc *d = (ag_jsondoc *)1;
        ag_error err = {0};
        assert_int_equal(ag_jsondoc_parse(bad[i].text, strlen(bad[i].text), &d, &err),
                         AG_ERR_PARSE);
        assert_null(d);
        assert_int_equal(err.element, bad[i].line);
        assert_non_null(strstr(err.text, "(line "));
        assert_non_null(strstr(err.text, "column "));
    }
    /* a buffer that is not NUL-terminated is read only up to its length */
    const char text[] = {'[', '1', ']', 'x'};
    ag_jsondoc *d = NULL;
    assert_int_equal(ag_jsondoc_parse(text, 3, &d, NULL), AG_OK);
    assert_int_equal(ag_jsondoc_size(d, ag_jsondoc_root(d)), 1);
    ag_jsondoc_free(d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values),
        cmocka_unit_test(test_deep),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
