/* The building description JSON and the style JSON. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "io/plan_json.h"

static ag_status parse(const char *s, ag_plan **p, ag_error *err)
{
    return ag_plan_json_read_buffer(s, strlen(s), p, err);
}

static void test_plan_ok(void **state)
{
    (void)state;
    const char *doc =
        "{\"profiles\": {\"roof\": {\"points\": [[0,0],[0,3],[1,4]], \"tag\": \"tiles\", \"priority\": 2},"
        "                \"wall\": [[0,0],[0,1]]},"
        " \"default_profile\": \"roof\","
        " \"loops\": [{\"points\": [[0,0],[10,0],[10,6],[0,6]],"
        "              \"profiles\": [\"roof\", \"wall\", null, \"wall\"]},"
        "            [[4,2],[4,4],[6,4],[6,2]]],"
        " \"anchors\": [{\"name\": \"door\", \"edge\": 0, \"relative\": 0.5, \"height\": 1},"
        "               {\"loop\": 1, \"edge\": 2, \"absolute\": 0.25, \"height\": 3.5}],"
        " \"steps\": [{\"name\": \"bay\", \"edge\": 2, \"absolute\": 4, \"height\": 1,"
        "             \"width\": 2, \"depth\": -0.5, \"profile\": \"wall\"}],"
        " \"cap_height\": 12, \"priority\": \"min_volume\"}";
    ag_plan *p = NULL;
    ag_error err = {0};
    assert_int_equal(parse(doc, &p, &err), AG_OK);
    assert_int_equal(p->nprofiles, 2);
    int32_t roof = ag_plan_find_profile(p, "roof"), wall = ag_plan_find_profile(p, "wall");
    assert_true(roof >= 0 && wall >= 0);
    assert_string_equal(p->profiles[roof].tag, "tiles");
    assert_int_equal(p->profiles[roof].priority, 2);
    assert_int_equal(p->profiles[wall].priority, 0);
    assert_int_equal(p->profiles[roof].npoints, 3);
    assert_true(p->profiles[roof].points[2].w == 1 && p->profiles[roof].points[2].z == 4);
    assert_int_equal(p->nloops, 2);
    assert_int_equal(p->loops[0].n, 4);
    assert_int_equal(p->loops[0].profile[0], roof);
    assert_int_equal(p->loops[0].profile[1], wall);
    assert_int_equal(p->loops[0].profile[2], roof); /* null = default */
    assert_int_equal(p->loops[1].profile[3], roof);
    assert_true(p->loops[1].xy[2] == 4 && p->loops[1].xy[3] == 4);
    assert_true(p->cap_height == 12);
    assert_int_equal(p->nanchors, 2);
    assert_string_equal(p->anchors[0].name, "door");
    assert_true(!p->anchors[0].absolute && p->anchors[0].along == 0.5 && p->anchors[0].z == 1);
    assert_true(p->anchors[1].absolute && p->anchors[1].loop == 1 && p->anchors[1].edge == 2);
    assert_int_equal(p->nsteps, 1);
    assert_string_equal(p->steps[0].name, "bay");
    assert_true(p->steps[0].at.absolute && p->steps[0].at.along == 4 && p->steps[0].at.z == 1);
    assert_true(p->steps[0].width == 2 && p->steps[0].depth == -0.5);
    assert_int_equal(p->steps[0].profile, wall);
    assert_int_equal(p->priority, AG_PRIORITY_MIN_VOLUME);
    ag_plan_free(p);
}

static void test_plan_errors(void **state)
{
    (void)state;
    struct {
        const char *doc, *needle;
    } cases[] = {
        {"{", "line"},
        {"[]", "object"},
        {"{\"loops\": [[[0,0],[1,0],[0,1]]]}", "profiles"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}}", "loops"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,\"x\"]]]}", "point 2"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [{\"points\": [[0,0],[1,0],[0,1]],"
         " \"profiles\": [\"r\", \"q\", \"r\"]}]}", "profiles[1]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [{\"points\": [[0,0],[1,0],[0,1]],"
         " \"profiles\": [\"r\"]}]}", "one profile name per edge"},
        {"{\"profiles\": {\"r\": [[0,0],[0,3],[1,2]]}, \"loops\": [[[0,0],[1,0],[0,1]]]}", "monotone"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"default_profile\": \"x\", \"loops\": [[[0,0],[1,0],[0,1]]]}",
         "default_profile"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"priority\": \"most\", \"loops\": [[[0,0],[1,0],[0,1]]]}",
         "priority"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"anchors\": [{\"edge\": 0, \"relative\": 0.5, \"absolute\": 1, \"height\": 1}]}", "anchors[0]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"anchors\": [{\"edge\": 0, \"relative\": 1.5, \"height\": 1}]}", "anchor 0"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"steps\": [{\"edge\": 0, \"relative\": 0.5, \"height\": 1, \"width\": 1, \"depth\": 1,"
         " \"profile\": \"q\"}]}", "steps[0]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"steps\": [{\"edge\": 0, \"relative\": 0.5, \"height\": 1, \"width\": 0.001, \"depth\": 1,"
         " \"profile\": \"r\"}]}", "2 mm"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        ag_plan *p = NULL;
        ag_error err = {0};
        ag_status st = parse(cases[i].doc, &p, &err);
        if (st == AG_OK || !strstr(err.text, cases[i].needle))
            fail_msg("case %zu: status %d, message '%s' lacks '%s'", i, st, err.text, cases[i].needle);
        assert_null(p);
    }
}

static void test_style(void **state)
{
    (void)state;
    const char *doc =
        "{\"name\": \"row\", \"height\": 9, \"seed\": 5, \"street\": [0, -1],"
        " \"profiles\": {\"steep\": [[0.5, 1]], \"wall\": [[0, 1]]},"
        " \"rules\": [{\"orientation\": \"street\", \"profiles\": {\"steep\": 0.5, \"wall\": 0.5}},"
        "           {\"length\": [\"short\", \"medium\"], \"profiles\": \"wall\"},"
        "           {\"profiles\": \"steep\"}]}";
    ag_style s;
    ag_error err = {0};
    assert_int_equal(ag_plan_json_read_style_buffer(doc, strlen(doc), &s, &err), AG_OK);
    assert_string_equal(s.name, "row");
    assert_true(s.height == 9);
    assert_true(s.has_street && s.street_dir[1] == -1);
    assert_int_equal(s.nprofiles, 2);
    assert_int_equal(s.nrules, 3);
    assert_int_equal(s.rules[0].nchoices, 2);
    assert_true(s.rules[0].labels & AG_LABEL_STREET);
    assert_false(s.rules[0].labels & AG_LABEL_BACK);
    assert_true((s.rules[1].labels & AG_LABEL_ANY_LENGTH) == (AG_LABEL_SHORT | AG_LABEL_MEDIUM));
    const char *bad = "{\"profiles\": {\"a\": [[1,1]]}, \"rules\": [{\"length\": \"huge\", \"profiles\": \"a\"}]}";
    assert_int_equal(ag_plan_json_read_style_buffer(bad, strlen(bad), &s, &err), AG_ERR_PARSE);
    assert_non_null(strstr(err.text, "rules[0]"));
    const char *unknown = "{\"profiles\": {\"a\": [[1,1]]}, \"rules\": [{\"profiles\": \"b\"}]}";
    assert_int_equal(ag_plan_json_read_style_buffer(unknown, strlen(unknown), &s, &err), AG_ERR_PARSE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plan_ok),
        cmocka_unit_test(test_plan_errors),
        cmocka_unit_test(test_style),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
