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

static void test_plan_forced_and_tags(void **state)
{
    (void)state;
    const char *doc =
        "{\"profiles\": {\"roof\": {\"points\": [[0,0],[0,3],[1,4]], \"priority\": 2,"
        "                          \"segment_priority\": [7, null]},"
        "               \"box\": [[0,0],[0,1],[1,2]]},"
        " \"loops\": [[[0,0],[10,0],[10,6],[0,6]]],"
        " \"steps\": [{\"name\": \"chimney\", \"edge\": 0, \"relative\": 0.7, \"height\": 4,"
        "             \"points\": [[-0.4,-0.4],[0.4,-0.4],[0.4,0.4],[-0.4,0.4]], \"profile\": \"box\"},"
        "            {\"name\": \"annex\", \"height\": 2, \"profile\": \"box\","
        "             \"points\": [[12,0],[14,0],[14,2]]}]}";
    ag_plan *p = NULL;
    ag_error err = {0};
    if (parse(doc, &p, &err) != AG_OK)
        fail_msg("%s", err.text);
    int32_t roof = ag_plan_find_profile(p, "roof");
    assert_int_equal(ag_profile_priority(&p->profiles[roof], 0), 7);
    assert_int_equal(ag_profile_priority(&p->profiles[roof], 1), 2); /* null: the profile's */
    assert_int_equal(p->nsteps, 2);
    const ag_plan_step *c = &p->steps[0], *a = &p->steps[1];
    assert_string_equal(c->name, "chimney");
    assert_int_equal(c->npoints, 4);
    assert_false(c->plan_frame);
    assert_true(c->at.edge == 0 && c->at.along == 0.7 && c->at.z == 4);
    assert_true(c->points[0] == -0.4 && c->points[5] == 0.4);
    assert_string_equal(a->name, "annex");
    assert_true(a->plan_frame && a->npoints == 3 && a->at.z == 2 && a->points[4] == 14);
    ag_plan_free(p);
    struct {
        const char *doc, *needle;
    } bad[] = {
        {"{\"profiles\": {\"r\": {\"points\": [[0,0],[1,1]], \"segment_priority\": [1, 2]}},"
         " \"loops\": [[[0,0],[1,0],[0,1]]]}", "one integer per segment"},
        {"{\"profiles\": {\"r\": {\"points\": [[0,0],[1,1]], \"segment_priority\": [\"x\"]}},"
         " \"loops\": [[[0,0],[1,0],[0,1]]]}", "segment_priority[0]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"steps\": [{\"profile\": \"r\", \"points\": [[0,0],[1,0],[0,1]]}]}", "height"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"steps\": [{\"height\": 1, \"points\": [[0,0],[1,0],[0,1]]}]}", "profile"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"steps\": [{\"height\": 1, \"profile\": \"r\", \"points\": [[0,0],[1,0]]}]}",
         "at least 3"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]], \"t\": [[0,0],[0,1],[1,1],[1,2]]},"
         " \"loops\": [[[0,0],[1,0],[0,1]]], \"steps\": [{\"height\": 1, \"profile\": \"t\","
         " \"points\": [[0,0],[1,0],[0,1]]}]}", "horizontal"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"anchors\": [{\"edge\": 0, \"relative\": 0.5, \"height\": 1, \"mesh\": \"w\"}]}",
         "anchors[0].mesh"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"meshes\": {\"w\": \"/nonexistent/w.obj\"}}", "meshes.w"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"meshes\": {\"w\": {\"path\": \"w.obj\", \"up\": \"x\"}}}", "meshes.w"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_plan *q = NULL;
        ag_error e2 = {0};
        ag_status st = parse(bad[i].doc, &q, &e2);
        if (st == AG_OK || !strstr(e2.text, bad[i].needle))
            fail_msg("bad %zu: status %d, message '%s' lacks '%s'", i, st, e2.text, bad[i].needle);
        assert_null(q);
    }
}

static void test_plan_offsets(void **state)
{
    (void)state;
    const char *doc =
        "{\"profiles\": {\"wall\": [[0,0],[0,1]], \"roof\": [[0,0],[1,1]], \"end\": [[0,0],[0,1]]},"
        " \"loops\": [[[0,0],[10,0],[10,6],[0,6]]],"
        " \"offsets\": [{\"height\": 3, \"outside\": 0.5, \"profile\": \"roof\", \"side\": \"end\","
        "   \"edges\": [{\"edge\": 1, \"disabled\": true},"
        "             {\"loop\": 0, \"edge\": 2, \"outside\": 0.8, \"profile\": \"wall\"}]}]}";
    ag_plan *p = NULL;
    ag_error err = {0};
    if (parse(doc, &p, &err) != AG_OK)
        fail_msg("%s", err.text);
    assert_int_equal(p->noffsets, 1);
    const ag_plan_offset *o = &p->offsets[0];
    assert_true(o->z == 3 && o->outside == 0.5);
    assert_int_equal(o->profile, ag_plan_find_profile(p, "roof"));
    assert_int_equal(o->side, ag_plan_find_profile(p, "end"));
    assert_int_equal(o->nedges, 2);
    assert_true(o->edges[0].disabled && o->edges[0].edge == 1 && !o->edges[0].has_outside);
    assert_int_equal(o->edges[0].profile, -1);
    assert_true(!o->edges[1].disabled && o->edges[1].has_outside && o->edges[1].outside == 0.8);
    assert_int_equal(o->edges[1].profile, ag_plan_find_profile(p, "wall"));
    ag_plan_free(p);
    const char *bad[][2] = {
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"offsets\": [{\"outside\": 1}]}", "offsets[0]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"offsets\": [{\"height\": 1, \"outside\": 1, \"profile\": \"q\"}]}", "offsets[0]"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"offsets\": [{\"height\": 1, \"outside\": 1, \"edges\": [{\"edge\": 7}]}]}",
         "names no edge"},
        {"{\"profiles\": {\"r\": [[0,0],[1,1]]}, \"loops\": [[[0,0],[1,0],[0,1]]],"
         " \"offsets\": [{\"height\": 1, \"outside\": 1, \"edges\": [{\"edge\": 0, \"disabled\": 1}]}]}",
         "edges[0]"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_plan *q = NULL;
        ag_error e2 = {0};
        ag_status st = parse(bad[i][0], &q, &e2);
        if (st == AG_OK || !strstr(e2.text, bad[i][1]))
            fail_msg("bad %zu: status %d, message '%s' lacks '%s'", i, st, e2.text, bad[i][1]);
        assert_null(q);
    }
}

static void test_plan_meshes(void **state)
{
    (void)state;
    ag_plan *p = NULL;
    ag_error err = {0};
    if (ag_plan_json_read_file(AG_REPO_DIR "/tests/data/extrude/mesh_anchor.json", &p, &err) != AG_OK)
        fail_msg("%s", err.text);
    assert_int_equal(p->nmeshes, 1);
    assert_string_equal(p->meshes[0].name, "window");
    assert_int_equal(p->meshes[0].mesh->ntris, 12);
    /* read z-up as asked: the box stands 1.2 m tall in z */
    double zmax = 0;
    for (size_t i = 0; i < p->meshes[0].mesh->nverts; i++)
        zmax = fmax(zmax, p->meshes[0].mesh->pos[3 * i + 2]);
    assert_true(fabs(zmax - 1.2) < 1e-12);
    assert_int_equal(p->nanchors, 4);
    for (size_t i = 0; i < 4; i++)
        assert_int_equal(p->anchors[i].mesh, 1);
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
        cmocka_unit_test(test_plan_forced_and_tags),
        cmocka_unit_test(test_plan_offsets),
        cmocka_unit_test(test_plan_meshes),
        cmocka_unit_test(test_plan_errors),
        cmocka_unit_test(test_style),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
