/* GeoJSON footprints as OGC allows them, and batches: holes touching the outer ring at a
 * point, MultiPolygon parts meeting at a corner and parts sharing edges (dissolved), ring
 * orientations fixed and reported, precise refusals; the threaded batch gives the serial
 * one's mesh and report. Buildings are judged by the independent checks. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/extrude_batch.h"
#include "core/extrude/style.h"
#include "extrude_check.h"
#include "io/footprints.h"

/* A feature collection in metres (RD-sized, so coordinates are not taken as lon/lat). */
static ag_footprints *read_doc(const char *features)
{
    char doc[8192];
    snprintf(doc, sizeof doc,
             "{\"type\": \"FeatureCollection\", \"crs\": {\"type\": \"name\", \"properties\":"
             " {\"name\": \"urn:ogc:def:crs:EPSG::28992\"}}, \"features\": [%s]}", features);
    ag_footprints *f = NULL;
    ag_error err = {0};
    if (ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err) != AG_OK)
        fail_msg("%s", err.text);
    return f;
}

static const ag_footprint_issue *issue_of(const ag_footprint_issue *v, size_t n, const char *id)
{
    for (size_t i = 0; i < n; i++)
        if (strcmp(v[i].id, id) == 0)
            return &v[i];
    return NULL;
}

/* Every building of m is a closed 2-manifold and within the footprint (walls, hip roofs:
 * nothing leans out). */
static void check_all(const ag_footprints *f, const ag_mesh *m, double reach)
{
    assert_int_equal(m->ncomponents, f->n);
    for (size_t c = 0; c < m->ncomponents; c++) {
        char why[200];
        if (!xc_closed_manifold(m, (long)c, 1e-6, why, sizeof why))
            fail_msg("%s: %s", f->items[c].id, why);
        double out = xc_outside(m, (long)c, (const double *const *)f->items[c].loops,
                                f->items[c].sizes, f->items[c].nloops, -1e-9);
        if (out > reach)
            fail_msg("%s: %.3g m outside", f->items[c].id, out);
    }
}

static void test_ogc_valid_accepted(void **state)
{
    (void)state;
    ag_footprints *f = read_doc(
        /* a hole touching the outer ring at a point (its corner on the outer edge) */
        "{\"type\": \"Feature\", \"id\": \"hole-touch\", \"properties\": {},"
        " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "  [[85000,446000],[85010,446000],[85010,446010],[85000,446010],[85000,446000]],"
        "  [[85000,446005],[85005,446006],[85005,446004],[85000,446005]]]}},"
        /* two parts of a MultiPolygon meeting at a corner */
        "{\"type\": \"Feature\", \"id\": \"parts-touch\", \"properties\": {},"
        " \"geometry\": {\"type\": \"MultiPolygon\", \"coordinates\": ["
        "  [[[85100,446000],[85110,446000],[85110,446010],[85100,446010],[85100,446000]]],"
        "  [[[85110,446010],[85120,446010],[85120,446020],[85110,446020],[85110,446010]]]]}},"
        /* a hole touching the outer ring at one of its corners */
        "{\"type\": \"Feature\", \"id\": \"corner-touch\", \"properties\": {},"
        " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "  [[85200,446000],[85212,446000],[85212,446012],[85200,446012],[85200,446000]],"
        "  [[85200,446000],[85204,446006],[85206,446004],[85200,446000]]]}}");
    assert_int_equal(f->n, 3);
    const char *styles[] = {"hip", "flat", "gable"};
    for (size_t s = 0; s < 3; s++) {
        ag_style st;
        ag_style_builtin(styles[s], &st, NULL);
        ag_mesh *m = ag_mesh_create();
        ag_footprints_report r;
        ag_error err = {0};
        assert_int_equal(ag_footprints_extrude(f, &st, m, &r, &err), AG_OK);
        if (r.nfailed)
            fail_msg("%s: %s refused: %s", styles[s], r.failed[0].id, r.failed[0].reason);
        if (r.nfallbacks)
            fail_msg("%s: %s fell back: %s", styles[s], r.fallbacks[0].id, r.fallbacks[0].reason);
        assert_int_equal(r.succeeded, 3);
        /* the touch is reported: its corner was moved a hair off */
        for (size_t i = 0; i < 3; i++) {
            const ag_footprint_issue *x = issue_of(r.fixed, r.nfixed, f->items[i].id);
            if (!x || !strstr(x->reason, "touches"))
                fail_msg("%s: %s: no touch reported (%s)", styles[s], f->items[i].id,
                         x ? x->reason : "no fixes");
        }
        check_all(f, m, 1e-3);
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
    }
    ag_footprints_free(f);
}

/* A ground surface triangulated into a MultiPolygon (CityGML): parts sharing edges, with a
 * T-junction, become one polygon with a reported fix; the building is the union's. */
static void test_shared_edges_dissolved(void **state)
{
    (void)state;
    ag_footprints *f = read_doc(
        "{\"type\": \"Feature\", \"id\": \"tin\", \"properties\": {},"
        " \"geometry\": {\"type\": \"MultiPolygon\", \"coordinates\": ["
        "  [[[85000,446000],[85010,446000],[85010,446006],[85000,446000]]],"
        "  [[[85000,446000],[85010,446006],[85000,446006],[85000,446000]]],"
        "  [[[85010,446000],[85020,446000],[85020,446006],[85010,446003],[85010,446000]]],"
        "  [[[85010,446003],[85020,446006],[85010,446006],[85010,446003]]]]}}");
    assert_int_equal(f->n, 1);
    /* one loop (the 20 x 6 rectangle, with corners where the parts met) */
    assert_int_equal(f->items[0].nloops, 1);
    assert_non_null(strstr(f->items[0].fixes, "4 parts sharing"));
    assert_non_null(strstr(f->items[0].fixes, "dissolved into 1 loop"));
    double area = 0;
    const double *xy = f->items[0].loops[0];
    size_t n = f->items[0].sizes[0];
    for (size_t i = 0, j = n - 1; i < n; j = i++)
        area += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
    assert_true(fabs(area / 2 - 120) < 1e-9);
    ag_style st;
    ag_style_builtin("hip", &st, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    ag_error err = {0};
    assert_int_equal(ag_footprints_extrude(f, &st, m, &r, &err), AG_OK);
    assert_int_equal(r.succeeded, 1);
    const ag_footprint_issue *x = issue_of(r.fixed, r.nfixed, "tin");
    assert_non_null(x);
    assert_non_null(strstr(x->reason, "dissolved"));
    check_all(f, m, 1e-6);
    /* a hip roof on the 20 x 6 rectangle: 3 m above the walls */
    assert_true(fabs(xc_top(m, 0) - st.height - 3) < 1e-9);
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

/* A MultiPolygon of n x n unit squares of two triangles each, with its feature id. */
static char *tin_doc(int n, const char *id)
{
    size_t cap = 256 + (size_t)n * n * 140, len = 0;
    char *d = malloc(cap);
    assert_non_null(d);
    len += (size_t)snprintf(d, cap, "{\"type\": \"FeatureCollection\", \"features\": [{\"type\": "
                            "\"Feature\", \"id\": \"%s\", \"properties\": {}, \"geometry\": "
                            "{\"type\": \"MultiPolygon\", \"coordinates\": [", id);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            int x = 85000 + i, y = 446000 + j;
            len += (size_t)snprintf(d + len, cap - len,
                                    "%s[[[%d,%d],[%d,%d],[%d,%d],[%d,%d]]],[[[%d,%d],[%d,%d],[%d,%d],"
                                    "[%d,%d]]]",
                                    i || j ? "," : "", x, y, x + 1, y, x + 1, y + 1, x, y, x, y,
                                    x + 1, y + 1, x, y + 1, x, y);
        }
    snprintf(d + len, cap - len, "]}}]}");
    return d;
}

/* Dissolving looks at the corners between an edge's ends only, within a budget: a 40 x 40
 * triangulated square dissolves into its outline, one of 180 x 180 (64 800 parts, past the
 * budget) is refused naming the feature instead of taking minutes. A polygon of 20 000 holes
 * keeps them all, each turned clockwise. */
static void test_large_footprints_bounded(void **state)
{
    (void)state;
    char *doc = tin_doc(40, "tin40");
    ag_footprints *f = NULL;
    ag_error err = {0};
    if (ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err) != AG_OK)
        fail_msg("%s", err.text);
    free(doc);
    assert_int_equal(f->n, 1);
    assert_int_equal(f->items[0].nloops, 1);
    assert_non_null(strstr(f->items[0].fixes, "3200 parts sharing"));
    double area = 0;
    const double *xy = f->items[0].loops[0];
    size_t n = f->items[0].sizes[0];
    for (size_t i = 0, j = n - 1; i < n; j = i++)
        area += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
    assert_true(fabs(area / 2 - 1600) < 1e-6);
    assert_int_equal(n, 4 * 40); /* the outline keeps every grid corner on it */
    ag_footprints_free(f);

    doc = tin_doc(180, "tin180");
    f = NULL;
    assert_int_equal(ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err),
                     AG_ERR_TOO_LARGE);
    assert_null(f);
    free(doc);
    assert_int_equal(err.element, 1);
    if (!strstr(err.text, "feature 0: its 64800 parts share too many corners"))
        fail_msg("%s", err.text);

    size_t holes = 20000, cap = 128 + holes * 120, len = 0;
    doc = malloc(cap);
    assert_non_null(doc);
    len += (size_t)snprintf(doc, cap, "{\"type\": \"Feature\", \"properties\": {}, "
                            "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": "
                            "[[[85000,446000],[105000,446000],[105000,446001],[85000,446001]]");
    for (size_t h = 0; h < holes; h++)
        len += (size_t)snprintf(doc + len, cap - len, ",[[%zu.25,446000.25],[%zu.75,446000.25],"
                                "[%zu.75,446000.75]]", 85000 + h, 85000 + h, 85000 + h);
    snprintf(doc + len, cap - len, "]}}");
    if (ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err) != AG_OK)
        fail_msg("%s", err.text);
    free(doc);
    assert_int_equal(f->items[0].nloops, holes + 1);
    for (size_t h = 1; h <= holes; h++) {
        const double *r = f->items[0].loops[h];
        assert_int_equal(f->items[0].sizes[h], 3);
        /* clockwise: negative signed area */
        double a2 = (r[2] - r[0]) * (r[5] - r[1]) - (r[4] - r[0]) * (r[3] - r[1]);
        assert_true(a2 < 0);
    }
    ag_footprints_free(f);
}

/* Rings in the wrong orientation are reversed and reported; a self-crossing ring is
 * refused with the edges named; a symmetric bow tie (no area) likewise. */
static void test_orientation_and_refusals(void **state)
{
    (void)state;
    ag_footprints *f = read_doc(
        "{\"type\": \"Feature\", \"id\": \"cw-outer\", \"properties\": {},"
        " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "  [[85000,446000],[85000,446010],[85010,446010],[85010,446000],[85000,446000]]]}},"
        "{\"type\": \"Feature\", \"id\": \"ccw-hole\", \"properties\": {},"
        " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "  [[85100,446000],[85110,446000],[85110,446010],[85100,446010],[85100,446000]],"
        "  [[85103,446003],[85107,446003],[85107,446007],[85103,446007],[85103,446003]]]}},"
        "{\"type\": \"Feature\", \"id\": \"bowtie\", \"properties\": {},"
        " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
        "  [[85200,446000],[85210,446000],[85200,446010],[85210,446010],[85200,446000]]]}}");
    assert_int_equal(f->n, 3);
    assert_non_null(strstr(f->items[0].fixes, "outer ring was clockwise: reversed"));
    assert_non_null(strstr(f->items[1].fixes, "hole 0 was counter-clockwise: reversed"));
    ag_style st;
    ag_style_builtin("hip", &st, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    ag_error err = {0};
    assert_int_equal(ag_footprints_extrude(f, &st, m, &r, &err), AG_OK);
    assert_int_equal(r.succeeded, 2);
    assert_int_equal(r.nfailed, 1);
    assert_string_equal(r.failed[0].id, "bowtie");
    assert_non_null(strstr(r.failed[0].reason, "edge 1 crosses edge 3"));
    assert_int_equal(r.failed[0].built, AG_BUILT_NONE);
    assert_non_null(issue_of(r.fixed, r.nfixed, "cw-outer"));
    assert_non_null(issue_of(r.fixed, r.nfixed, "ccw-hole"));
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

/* Heights as third-party files give them: a number, a number in a string (tables turned
 * into GeoJSON), and values that are no height (a word, a negative number, true), which
 * take the style's height and are reported, not silently dropped. The walls are measured
 * on the flat-roofed result. */
static void test_heights_from_properties(void **state)
{
    (void)state;
    static const char *const props[] = {"{\"height\": 12}", "{\"height\": \"9.5\"}",
                                        "{\"height\": \" 7 \"}", "{\"height\": \"tall\"}",
                                        "{\"height\": -4}", "{\"height\": true}",
                                        "{\"height\": null}", "{}"};
    const double want[] = {12, 9.5, 7, 0, 0, 0, 0, 0};
    const char *noted[] = {NULL, "read from the text", "read from the text",
                           "\"tall\" is not a height", "-4 is not a height", "not a number",
                           NULL, NULL};
    char features[4096] = "";
    for (int i = 0; i < 8; i++) {
        char one[400];
        snprintf(one, sizeof one,
                 "%s{\"type\": \"Feature\", \"id\": \"b%d\", \"properties\": %s,"
                 " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[%d,446000],"
                 "[%d,446000],[%d,446010],[%d,446010],[%d,446000]]]}}",
                 i ? "," : "", i, props[i], 85000 + 20 * i, 85010 + 20 * i, 85010 + 20 * i,
                 85000 + 20 * i, 85000 + 20 * i);
        strcat(features, one);
    }
    ag_footprints *f = read_doc(features);
    assert_int_equal(f->n, 8);
    ag_style st;
    ag_style_builtin("flat", &st, NULL);
    ag_mesh *m = ag_mesh_create();
    ag_footprints_report r;
    ag_error err = {0};
    assert_int_equal(ag_footprints_extrude(f, &st, m, &r, &err), AG_OK);
    assert_int_equal(r.succeeded, 8);
    for (int i = 0; i < 8; i++) {
        assert_true(f->items[i].height == want[i]);
        double top = xc_top(m, i);
        if (fabs(top - (want[i] > 0 ? want[i] : st.height)) > 1e-9)
            fail_msg("b%d: top at %g", i, top);
        const ag_footprint_issue *x = issue_of(r.fixed, r.nfixed, f->items[i].id);
        if (noted[i] ? !x || !strstr(x->reason, noted[i]) : x != NULL)
            fail_msg("b%d: fixes '%s'", i, x ? x->reason : "none");
    }
    ag_footprints_report_free(&r);
    ag_mesh_free(m);
    ag_footprints_free(f);
}

/* A CityJSON file is named as such, not as a malformed GeoJSON. */
static void test_cityjson_named(void **state)
{
    (void)state;
    const char *doc = "{\"type\": \"CityJSON\", \"version\": \"1.1\", \"CityObjects\": {},"
                      " \"vertices\": []}";
    ag_footprints *f = NULL;
    ag_error err = {0};
    assert_int_equal(ag_footprints_read_buffer(doc, strlen(doc), NULL, &f, &err),
                     AG_ERR_UNSUPPORTED);
    assert_null(f);
    assert_non_null(strstr(err.text, "CityJSON"));
}

/* The threaded batch is the serial one: the same triangles in the same order, the same
 * report, whatever the number of threads. */
static void test_threaded_batch_is_serial(void **state)
{
    (void)state;
    const char *path = AG_REPO_DIR "/../shared/data/footprints_denhaag_lod2/denhaag_tile01_footprints.geojson";
    ag_footprints *f = NULL;
    ag_error err = {0};
    FILE *probe = fopen(path, "rb");
    if (probe) {
        fclose(probe);
        assert_int_equal(ag_footprints_read_file(path, NULL, &f, &err), AG_OK);
    } else {
        printf("%s is absent: a generated batch instead\n", path);
        char features[8192] = "";
        size_t len = 0;
        for (int i = 0; i < 40; i++) {
            double x = 85000 + 30 * (i % 8), y = 446000 + 30 * (i / 8), w = 6 + i % 5, h = 5 + i % 3;
            len += (size_t)snprintf(features + len, sizeof features - len,
                                    "%s{\"type\": \"Feature\", \"id\": \"g%d\", \"properties\": {},"
                                    " \"geometry\": {\"type\": \"Polygon\", \"coordinates\": ["
                                    "[[%g,%g],[%g,%g],[%g,%g],[%g,%g],[%g,%g]]]}}",
                                    i ? "," : "", i, x, y, x + w, y, x + w, y + h, x, y + h, x, y);
        }
        f = read_doc(features);
    }
    ag_style st;
    ag_style_builtin("overhang", &st, NULL);
    ag_mesh *serial = ag_mesh_create();
    ag_footprints_report rs;
    assert_int_equal(ag_footprints_extrude(f, &st, serial, &rs, &err), AG_OK);
    for (size_t threads = 1; threads <= 3; threads++) {
        ag_extrude_batch_options bo = {.threads = threads};
        ag_mesh *m = ag_mesh_create();
        ag_footprints_report r;
        assert_int_equal(ag_extrude_batch(f, &st, &bo, m, &r, &err), AG_OK);
        assert_int_equal(r.succeeded, rs.succeeded);
        assert_int_equal(r.nfallbacks, rs.nfallbacks);
        assert_int_equal(r.nfailed, rs.nfailed);
        assert_int_equal(r.nfixed, rs.nfixed);
        assert_int_equal(r.triangles, rs.triangles);
        assert_int_equal(m->ntris, serial->ntris);
        assert_int_equal(m->ncomponents, serial->ncomponents);
        assert_int_equal(m->ngroups, serial->ngroups);
        assert_memory_equal(m->tri_component, serial->tri_component, m->ntris * sizeof(uint32_t));
        for (size_t t = 0; t < 3 * m->ntris; t++)
            for (int k = 0; k < 3; k++)
                if (m->pos[3 * m->tri[t] + k] != serial->pos[3 * serial->tri[t] + k])
                    fail_msg("%zu threads: triangle corner %zu differs", threads, t);
        for (size_t g = 0; g < m->ngroups; g++)
            assert_string_equal(m->group_names[g], serial->group_names[g]);
        ag_footprints_report_free(&r);
        ag_mesh_free(m);
    }
    ag_footprints_report_free(&rs);
    ag_mesh_free(serial);
    ag_footprints_free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ogc_valid_accepted),
        cmocka_unit_test(test_shared_edges_dissolved),
        cmocka_unit_test(test_large_footprints_bounded),
        cmocka_unit_test(test_orientation_and_refusals),
        cmocka_unit_test(test_heights_from_properties),
        cmocka_unit_test(test_cityjson_named),
        cmocka_unit_test(test_threaded_batch_is_serial),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
