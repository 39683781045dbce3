/* Styles for batches (labels, rules, seeds) and GeoJSON footprints into a city mesh. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/extrude/extrude.h"
#include "core/extrude/style.h"
#include "io/footprints.h"

static void test_labels(void **state)
{
    (void)state;
    ag_style s;
    assert_int_equal(ag_style_builtin("hip", &s, NULL), AG_OK);
    /* 20 x 3 rectangle, CCW: bottom edge faces south and is long, right edge short */
    const double xy[] = {0, 0, 20, 0, 20, 3, 0, 3};
    const double axis[2] = {1, 0};
    uint32_t b = ag_style_edge_labels(&s, xy, 4, 0, axis), r = ag_style_edge_labels(&s, xy, 4, 1, axis);
    assert_true(b & AG_LABEL_LONG && b & AG_LABEL_SOUTH && b & AG_LABEL_ALONG);
    assert_true(r & AG_LABEL_SHORT && r & AG_LABEL_EAST && r & AG_LABEL_ACROSS);
    s.has_street = 1;
    s.street_dir[0] = 0;
    s.street_dir[1] = 1; /* street to the north */
    assert_true(ag_style_edge_labels(&s, xy, 4, 2, axis) & AG_LABEL_STREET);
    assert_true(ag_style_edge_labels(&s, xy, 4, 0, axis) & AG_LABEL_BACK);
    assert_true(ag_style_edge_labels(&s, xy, 4, 1, axis) & AG_LABEL_SIDE);
    ag_error err = {0};
    assert_int_equal(ag_style_builtin("pagoda", &s, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "pagoda"));
}

static void test_gable_assignment(void **state)
{
    (void)state;
    ag_style s;
    ag_style_builtin("gable", &s, NULL);
    const double xy[] = {0, 0, 12, 0, 12, 6, 0, 6};
    const double *loops[] = {xy};
    size_t sizes[] = {4};
    ag_plan *p = NULL;
    assert_int_equal(ag_style_apply(&s, loops, sizes, 1, 5, 0, &p, NULL), AG_OK);
    int32_t roof = ag_plan_find_profile(p, "roof45"), wall = ag_plan_find_profile(p, "gable_wall");
    assert_int_equal(p->loops[0].profile[0], roof);
    assert_int_equal(p->loops[0].profile[1], wall);
    assert_int_equal(p->loops[0].profile[2], roof);
    assert_int_equal(p->loops[0].profile[3], wall);
    /* walls to 5 m, ridge at 5 + 3 */
    ag_mesh *m = ag_mesh_create();
    ag_extrude_result r;
    assert_int_equal(ag_extrude_plan(p, m, -1, &r, NULL, NULL), AG_OK);
    assert_int_equal(r.failing_faces, 0);
    assert_true(fabs(r.top - 8) < 1e-9);
    assert_true(fabs(r.volume - (12 * 6 * 5 + 12 * 6 * 3 / 2.0)) < 1e-6);
    ag_mesh_free(m);
    ag_plan_free(p);
}

static void test_seeded_choice(void **state)
{
    (void)state;
    ag_style s;
    ag_style_builtin("hip", &s, NULL);
    /* one rule, two profiles with equal weight */
    ag_style_profile steep = {"steep", 1, {{0.5, 1}}};
    s.profiles[s.nprofiles++] = steep;
    s.rules[0].nchoices = 2;
    s.rules[0].profile[1] = 1;
    s.rules[0].weight[1] = 1;
    double xy[2 * 40];
    for (int i = 0; i < 40; i++) {
        xy[2 * i] = 20 * cos(2 * M_PI * i / 40);
        xy[2 * i + 1] = 20 * sin(2 * M_PI * i / 40);
    }
    const double *loops[] = {xy};
    size_t sizes[] = {40};
    ag_plan *a = NULL, *b = NULL, *c = NULL;
    ag_style_apply(&s, loops, sizes, 1, 0, 3, &a, NULL);
    ag_style_apply(&s, loops, sizes, 1, 0, 3, &b, NULL);
    s.seed = 99;
    ag_style_apply(&s, loops, sizes, 1, 0, 3, &c, NULL);
    int n1 = 0, diff = 0;
    for (int i = 0; i < 40; i++) {
        assert_int_equal(a->loops[0].profile[i], b->loops[0].profile[i]);
        n1 += a->loops[0].profile[i] == 1;
        diff += a->loops[0].profile[i] != c->loops[0].profile[i];
    }
    assert_true(n1 > 5 && n1 < 35); /* both profiles used */
    assert_true(diff > 0);          /* another seed, another choice */
    assert_true(a->profiles[0].points[1].z == s.height); /* default height */
    ag_plan_free(a);
    ag_plan_free(b);
    ag_plan_free(c);
}

static void test_geojson(void **state)
{
    (void)state;
    /* lon/lat: a 0.0002 x 0.0001 degree block near 52°N, clockwise outer ring, one hole,
     * a MultiPolygon with an id only in properties, and a point feature */
    const char *doc =
        "{\"type\": \"FeatureCollection\", \"features\": ["
        " {\"type\": \"Feature\", \"id\": \"a\", \"properties\": {\"height\": 7.5},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "   [[4.3000,52.0000],[4.3000,52.0001],[4.3002,52.0001],[4.3002,52.0000],[4.3000,52.0000]],"
        "   [[4.30005,52.00003],[4.30015,52.00003],[4.30015,52.00007],[4.30005,52.00007],[4.30005,52.00003]]]}},"
        " {\"type\": \"Feature\", \"properties\": {\"id\": 17},"
        "  \"geometry\": {\"type\": \"MultiPolygon\", \"coordinates\": ["
        "   [[[4.3010,52.0000],[4.3011,52.0000],[4.3011,52.0001],[4.3010,52.0001]]],"
        "   [[[4.3013,52.0000],[4.3014,52.0000],[4.3014,52.0001],[4.3013,52.0001]]]]}},"
        " {\"type\": \"Feature\", \"properties\": {},"
        "  \"geometry\": {\"type\": \"Point\", \"coordinates\": [4.3, 52.0]}},"
        " {\"type\": \"Feature\", \"properties\": {\"height\": 4},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "   [[4.3020,52.0000],[4.3021,52.0000],[4.3021,52.0001],[4.3020,52.0001]]]}}]}";
    ag_footprints *f = NULL;
    ag_error err = {0};
    assert_int_equal(ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err), AG_OK);
    assert_true(f->lonlat);
    assert_int_equal(f->n, 3);
    assert_int_equal(f->skipped, 1);
    assert_string_equal(f->items[0].id, "a");
    assert_string_equal(f->items[1].id, "17");
    assert_string_equal(f->items[2].id, "3");
    assert_true(f->items[0].height == 7.5);
    assert_true(f->items[1].height == 0);
    assert_int_equal(f->items[0].nloops, 2);
    assert_int_equal(f->items[0].sizes[0], 4); /* closing corner dropped */
    assert_int_equal(f->items[1].nloops, 2);
    /* metric size: 0.0002° of longitude at 52°N ≈ 13.7 m, 0.0001° latitude ≈ 11.1 m */
    const double *o = f->items[0].loops[0];
    double w = 0, h = 0;
    for (int i = 0; i < 4; i++) {
        w = fmax(w, fabs(o[2 * i] - o[0]));
        h = fmax(h, fabs(o[2 * i + 1] - o[1]));
    }
    double kx = 6371008.8 * cos(52.00005 * M_PI / 180) * M_PI / 180 * 0.0002;
    assert_true(fabs(w - kx) < 0.01);
    assert_true(fabs(h - 6371008.8 * M_PI / 180 * 0.0001) < 0.01);
    /* outer CCW, hole CW after reading */
    double a0 = 0, a1 = 0;
    for (int L = 0; L < 2; L++) {
        const double *xy = f->items[0].loops[L];
        size_t n = f->items[0].sizes[L];
        double a = 0;
        for (size_t i = 0, j = n - 1; i < n; j = i++)
            a += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
        if (L == 0)
            a0 = a;
        else
            a1 = a;
    }
    assert_true(a0 > 0 && a1 < 0);
    /* batch: one group and one component per footprint, named by id */
    ag_style s;
    ag_style_builtin("hip", &s, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    assert_int_equal(ag_footprints_extrude(f, &s, m, &r, &err), AG_OK);
    assert_int_equal(r.footprints, 3);
    assert_int_equal(r.succeeded, 3);
    assert_int_equal(r.nfailed, 0);
    assert_int_equal(r.nnot_watertight, 0);
    assert_int_equal(m->ncomponents, 3);
    assert_string_equal(m->group_names[m->component_group[1]], "17");
    assert_int_equal(r.triangles, m->ntris);
    /* the first footprint's walls reach its own height 7.5 */
    double zmax = 0;
    for (size_t t = 0; t < m->ntris; t++)
        if (m->tri_component[t] == 0)
            for (int k = 0; k < 3; k++)
                zmax = fmax(zmax, m->pos[3 * m->tri[3 * t + k] + 2]);
    assert_true(zmax > 7.5 && zmax < 7.5 + 6);
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

static void test_geojson_errors_and_failures(void **state)
{
    (void)state;
    ag_footprints *f = NULL;
    ag_error err = {0};
    const char *bad = "{\"type\": \"FeatureCollection\", \"features\": [{\"type\": \"Feature\","
                      " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0]]]}}]}";
    assert_int_equal(ag_footprints_read_buffer(bad, strlen(bad), NULL, &f, &err), AG_ERR_PARSE);
    assert_non_null(strstr(err.text, "feature 0"));
    assert_int_equal(ag_footprints_read_buffer("{\"type\": 3}", 11, NULL, &f, &err), AG_ERR_PARSE);
    /* metres (outside lon/lat range); a self-crossing footprint fails alone, reported */
    const char *doc =
        "{\"type\": \"FeatureCollection\", \"features\": ["
        " {\"type\": \"Feature\", \"id\": 1, \"properties\": {},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[1000,1000],[1010,1010],[1010,1000],[1000,1006]]]}},"
        " {\"type\": \"Feature\", \"id\": 2, \"properties\": {},"
        "  \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[1000,1000],[1010,1000],[1010,1006],[1000,1006]]]}}]}";
    assert_int_equal(ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err), AG_OK);
    assert_false(f->lonlat);
    ag_style s;
    ag_style_builtin("flat", &s, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    assert_int_equal(ag_footprints_extrude(f, &s, m, &r, &err), AG_OK);
    assert_int_equal(r.succeeded, 1);
    assert_int_equal(r.nfailed, 1);
    assert_string_equal(r.failed[0].id, "1");
    assert_non_null(strstr(r.failed[0].reason, "crosses"));
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

/* Real data: every Den Haag footprint extrudes watertight with the hip style. */
static void test_denhaag(void **state)
{
    (void)state;
    const char *path = AG_REPO_DIR "/../shared/data/footprints_denhaag_lod2/denhaag_tile01_footprints.geojson";
    FILE *probe = fopen(path, "rb");
    if (!probe) {
        printf("skipping: %s is absent\n", path);
        skip();
    }
    fclose(probe);
    ag_footprints *f = NULL;
    ag_error err = {0};
    assert_int_equal(ag_footprints_read_file(path, NULL, &f, &err), AG_OK);
    assert_int_equal(f->n, 1990);
    const char *styles[] = {"hip", "gable", "overhang", "flat"};
    for (int i = 0; i < 4; i++) {
        ag_style s;
        ag_style_builtin(styles[i], &s, NULL);
        ag_mesh *m = ag_mesh_create();
        ag_footprints_report r;
        assert_int_equal(ag_footprints_extrude(f, &s, m, &r, &err), AG_OK);
        if (r.nfailed || r.nnot_watertight)
            fail_msg("%s: %zu failed (%s), %zu not watertight", styles[i], r.nfailed,
                     r.nfailed ? r.failed[0].reason : "", r.nnot_watertight);
        assert_int_equal(r.succeeded, 1990);
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
    }
    ag_footprints_free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_labels),
        cmocka_unit_test(test_gable_assignment),
        cmocka_unit_test(test_seeded_choice),
        cmocka_unit_test(test_geojson),
        cmocka_unit_test(test_geojson_errors_and_failures),
        cmocka_unit_test(test_denhaag),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
