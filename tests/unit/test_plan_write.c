/* ag_plan → building description JSON: parse → write → parse gives an equal plan for every
 * fixture and for a plan using every member the reader knows, and writing is idempotent. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/plan_json.h"
#include "io/plan_write.h"

/* --- field-by-field comparison; *why gets the first difference ----------------------- */

#define DIFF(cond, ...)                                                                        \
    do {                                                                                       \
        if (cond) {                                                                            \
            snprintf(why, nwhy, __VA_ARGS__);                                                  \
            return 1;                                                                          \
        }                                                                                      \
    } while (0)

static int str_differ(const char *a, const char *b)
{
    if (!a || !b)
        return a != b;
    return strcmp(a, b) != 0;
}

static int anchor_diff(const ag_anchor *a, const ag_anchor *b, const char *what, char *why,
                       size_t nwhy)
{
    DIFF(strcmp(a->name, b->name), "%s: name %s / %s", what, a->name, b->name);
    DIFF(a->loop != b->loop || a->edge != b->edge, "%s: loop/edge", what);
    DIFF(a->absolute != b->absolute, "%s: absolute", what);
    DIFF(a->along != b->along, "%s: along %.17g / %.17g", what, a->along, b->along);
    DIFF(a->z != b->z, "%s: height %.17g / %.17g", what, a->z, b->z);
    DIFF(a->mesh != b->mesh, "%s: mesh %d / %d", what, (int)a->mesh, (int)b->mesh);
    DIFF(a->found != b->found || a->face != b->face, "%s: found/face", what);
    for (int k = 0; k < 3; k++)
        DIFF(a->pos[k] != b->pos[k] || a->normal[k] != b->normal[k] ||
                 a->tangent[k] != b->tangent[k],
             "%s: pos/normal/tangent", what);
    return 0;
}

static int mesh_diff(const ag_mesh *a, const ag_mesh *b, char *why, size_t nwhy, size_t i)
{
    DIFF(!a || !b, "mesh %zu: missing", i);
    DIFF(a->nverts != b->nverts || a->ntris != b->ntris, "mesh %zu: sizes", i);
    DIFF(memcmp(a->pos, b->pos, 3 * a->nverts * sizeof *a->pos) != 0, "mesh %zu: vertices", i);
    DIFF(memcmp(a->tri, b->tri, 3 * a->ntris * sizeof *a->tri) != 0, "mesh %zu: triangles", i);
    return 0;
}

static int plan_diff(const ag_plan *a, const ag_plan *b, char *why, size_t nwhy)
{
    char what[64];
    DIFF(a->nprofiles != b->nprofiles, "nprofiles %zu / %zu", a->nprofiles, b->nprofiles);
    for (size_t i = 0; i < a->nprofiles; i++) {
        const ag_profile *x = &a->profiles[i], *y = &b->profiles[i];
        DIFF(str_differ(x->name, y->name), "profile %zu: name", i);
        DIFF(x->npoints != y->npoints, "profile %s: npoints", x->name);
        for (size_t k = 0; k < x->npoints; k++)
            DIFF(x->points[k].w != y->points[k].w || x->points[k].z != y->points[k].z,
                 "profile %s: point %zu", x->name, k);
        DIFF(str_differ(x->tag, y->tag), "profile %s: tag", x->name);
        DIFF(x->priority != y->priority, "profile %s: priority %d / %d", x->name,
             (int)x->priority, (int)y->priority);
        DIFF(!x->seg_priority != !y->seg_priority, "profile %s: segment_priority present",
             x->name);
        for (size_t k = 0; x->seg_priority && k + 1 < x->npoints; k++)
            DIFF(x->seg_priority[k] != y->seg_priority[k], "profile %s: segment_priority[%zu]",
                 x->name, k);
    }
    DIFF(a->nloops != b->nloops, "nloops %zu / %zu", a->nloops, b->nloops);
    for (size_t L = 0; L < a->nloops; L++) {
        const ag_plan_loop *x = &a->loops[L], *y = &b->loops[L];
        DIFF(x->n != y->n, "loop %zu: corners", L);
        DIFF(memcmp(x->xy, y->xy, 2 * x->n * sizeof *x->xy) != 0, "loop %zu: coordinates", L);
        for (size_t i = 0; i < x->n; i++)
            DIFF((x->profile ? x->profile[i] : 0) != (y->profile ? y->profile[i] : 0),
                 "loop %zu edge %zu: profile", L, i);
    }
    DIFF(a->cap_height != b->cap_height, "cap_height %.17g / %.17g", a->cap_height,
         b->cap_height);
    DIFF(a->priority != b->priority, "priority scheme");
    DIFF(a->nmeshes != b->nmeshes, "nmeshes %zu / %zu", a->nmeshes, b->nmeshes);
    for (size_t i = 0; i < a->nmeshes; i++) {
        DIFF(strcmp(a->meshes[i].name, b->meshes[i].name), "mesh %zu: name", i);
        if (mesh_diff(a->meshes[i].mesh, b->meshes[i].mesh, why, nwhy, i))
            return 1;
    }
    DIFF(a->nanchors != b->nanchors, "nanchors %zu / %zu", a->nanchors, b->nanchors);
    for (size_t i = 0; i < a->nanchors; i++) {
        snprintf(what, sizeof what, "anchor %zu", i);
        if (anchor_diff(&a->anchors[i], &b->anchors[i], what, why, nwhy))
            return 1;
    }
    DIFF(a->nsteps != b->nsteps, "nsteps %zu / %zu", a->nsteps, b->nsteps);
    for (size_t i = 0; i < a->nsteps; i++) {
        const ag_plan_step *x = &a->steps[i], *y = &b->steps[i];
        snprintf(what, sizeof what, "step %zu", i);
        DIFF(strcmp(x->name, y->name), "%s: name", what);
        if (anchor_diff(&x->at, &y->at, what, why, nwhy))
            return 1;
        DIFF(x->width != y->width || x->depth != y->depth, "%s: width/depth", what);
        DIFF(x->profile != y->profile, "%s: profile", what);
        DIFF(x->npoints != y->npoints, "%s: npoints", what);
        DIFF(x->npoints && memcmp(x->points, y->points, 2 * x->npoints * sizeof *x->points),
             "%s: points", what);
        DIFF(x->plan_frame != y->plan_frame, "%s: plan_frame", what);
    }
    DIFF(a->noffsets != b->noffsets, "noffsets %zu / %zu", a->noffsets, b->noffsets);
    for (size_t i = 0; i < a->noffsets; i++) {
        const ag_plan_offset *x = &a->offsets[i], *y = &b->offsets[i];
        DIFF(x->z != y->z || x->outside != y->outside, "offset %zu: height/outside", i);
        DIFF(x->profile != y->profile || x->side != y->side, "offset %zu: profile/side", i);
        DIFF(x->has_gap != y->has_gap || x->gap_from != y->gap_from || x->gap_to != y->gap_to ||
                 x->inside != y->inside || x->inner != y->inner,
             "offset %zu: inside", i);
        DIFF(x->nedges != y->nedges, "offset %zu: nedges", i);
        for (size_t k = 0; k < x->nedges; k++) {
            const ag_offset_edge *e = &x->edges[k], *f = &y->edges[k];
            DIFF(e->loop != f->loop || e->edge != f->edge, "offset %zu edge %zu: loop/edge", i,
                 k);
            DIFF(e->disabled != f->disabled, "offset %zu edge %zu: disabled", i, k);
            DIFF(e->has_outside != f->has_outside || e->outside != f->outside,
                 "offset %zu edge %zu: outside", i, k);
            DIFF(e->profile != f->profile, "offset %zu edge %zu: profile", i, k);
            DIFF(e->has_gap != f->has_gap || e->gap_from != f->gap_from ||
                     e->gap_to != f->gap_to || e->inside != f->inside || e->inner != f->inner,
                 "offset %zu edge %zu: inside", i, k);
        }
    }
    return 0;
}

/* --- helpers ---------------------------------------------------------------------------- */

static char *write_text(const ag_plan *p, const ag_plan_write_options *opt)
{
    json_t *doc = NULL;
    ag_error err = {0};
    ag_status st = ag_plan_write_json_opts(p, opt, &doc, &err);
    if (st != AG_OK)
        print_error("write: %s\n", err.text);
    assert_int_equal(st, AG_OK);
    char *text = json_dumps(doc, JSON_INDENT(1));
    json_decref(doc);
    assert_non_null(text);
    return text;
}

static ag_plan *read_text(const char *text)
{
    ag_plan *p = NULL;
    ag_error err = {0};
    ag_status st = ag_plan_json_read_buffer_in(text, strlen(text), AG_REPO_DIR "/tests/data/extrude", &p, &err);
    if (st != AG_OK)
        print_error("read back: %s\n%s\n", err.text, text);
    assert_int_equal(st, AG_OK);
    return p;
}

/* parse → write → parse equals the first parse; write → parse → write gives the same text */
static void check_roundtrip(const ag_plan *p, const ag_plan_write_options *opt, const char *name)
{
    char *t1 = write_text(p, opt);
    ag_plan *q = read_text(t1);
    char why[256] = "";
    int d = plan_diff(p, q, why, sizeof why);
    if (d)
        print_error("%s: written and read back, the plans differ: %s\n", name, why);
    assert_int_equal(d, 0);
    char *t2 = write_text(q, opt);
    if (strcmp(t1, t2) != 0)
        print_error("%s: writing is not idempotent\n%s\n---\n%s\n", name, t1, t2);
    assert_string_equal(t1, t2);
    free(t1);
    free(t2);
    ag_plan_free(q);
}

/* The mesh files of a fixture, as absolute paths (the text is read back without a folder). */
typedef struct {
    size_t n;
    ag_plan_mesh_file files[8];
    char paths[8][1024];
} mesh_files;

static void fixture_meshes(const char *dir, const char *file, const ag_plan *p, mesh_files *m)
{
    memset(m, 0, sizeof *m);
    json_t *root = json_load_file(file, 0, NULL);
    assert_non_null(root);
    json_t *ms = json_object_get(root, "meshes");
    assert_true(p->nmeshes <= 8);
    for (size_t i = 0; i < p->nmeshes; i++) {
        json_t *v = json_object_get(ms, p->meshes[i].name);
        json_t *pv = json_is_object(v) ? json_object_get(v, "path") : v;
        const char *up = json_is_object(v) ? json_string_value(json_object_get(v, "up")) : NULL;
        assert_non_null(json_string_value(pv));
        snprintf(m->paths[i], sizeof m->paths[i], "%s/%s", dir, json_string_value(pv));
        m->files[i].path = m->paths[i];
        m->files[i].up = up && strcmp(up, "z") == 0 ? AG_UP_Z : AG_UP_Y;
    }
    m->n = p->nmeshes;
    json_decref(root);
}

static size_t roundtrip_file(const char *dir, const char *file)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    ag_plan *p = NULL;
    ag_error err = {0};
    ag_status st = ag_plan_json_read_file(path, &p, &err);
    if (st != AG_OK)
        print_error("%s: %s\n", path, err.text);
    assert_int_equal(st, AG_OK);
    mesh_files m;
    fixture_meshes(dir, path, p, &m);
    ag_plan_write_options opt = {.mesh_files = m.n ? m.files : NULL};
    check_roundtrip(p, &opt, path);
    ag_plan_free(p);
    return 1;
}

static size_t roundtrip_dir(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t len = strlen(e->d_name);
        if (len > 5 && strcmp(e->d_name + len - 5, ".json") == 0)
            n += roundtrip_file(dir, e->d_name);
    }
    closedir(d);
    return n;
}

/* --- tests ------------------------------------------------------------------------------ */

static void test_fixtures_roundtrip(void **state)
{
    (void)state;
    size_t n = roundtrip_dir(AG_REPO_DIR "/tests/data/extrude");
    n += roundtrip_dir(AG_REPO_DIR "/tests/data/extrude_service");
    n += roundtrip_file(AG_REPO_DIR "/tests/data/extrude_web", "house_plan.json");
    assert_true(n >= 33); /* the glob found the fixtures */
}

#define WINDOW AG_REPO_DIR "/tests/data/extrude/window.obj"

/* Every member the reader knows, each with a value other than its default. */
static const char *const full_doc =
    "{\"profiles\": {"
    "  \"roof\": {\"points\": [[0,0],[0,3],[1,4]], \"tag\": \"tiles\", \"priority\": 2,"
    "            \"segment_priority\": [null, 7]},"
    "  \"wall\": [[0,0],[0,1]],"
    "  \"steep\": {\"points\": [[0,0],[0.1,0.30000000000000004]], \"priority\": -3}},"
    " \"default_profile\": \"wall\","
    " \"loops\": [{\"points\": [[0,0],[10,0],[10,6],[0,6]],"
    "              \"profiles\": [\"roof\", \"steep\", null, \"wall\"]},"
    "            [[4,2],[4,4],[6,4],[6,2]]],"
    " \"meshes\": {\"win\": \"" WINDOW "\", \"box\": {\"path\": \"" WINDOW "\", \"up\": \"z\"}},"
    " \"anchors\": [{\"name\": \"door\", \"edge\": 0, \"relative\": 0.5, \"height\": 1,"
    "                \"mesh\": \"win\"},"
    "               {\"loop\": 1, \"edge\": 2, \"absolute\": 0.25, \"height\": 3.5, \"mesh\": \"box\"},"
    "               {\"edge\": 1, \"relative\": 0.125, \"height\": 0}],"
    " \"steps\": [{\"name\": \"bay\", \"edge\": 2, \"absolute\": 4, \"height\": 1,"
    "             \"width\": 2, \"depth\": -0.5, \"profile\": \"wall\"},"
    "            {\"name\": \"chimney\", \"loop\": 0, \"edge\": 0, \"relative\": 0.7, \"height\": 4,"
    "             \"profile\": \"roof\", \"points\": [[-0.4,-0.4],[0.4,-0.4],[0.4,0.4],[-0.4,0.4]]},"
    "            {\"name\": \"annex\", \"height\": 2, \"profile\": \"wall\","
    "             \"points\": [[12,0],[14,0],[14,2]]}],"
    " \"offsets\": [{\"height\": 3, \"outside\": 0.5, \"profile\": \"steep\", \"side\": \"wall\","
    "               \"inside\": {\"gap\": [0.5, 1.5], \"profile\": \"wall\", \"inner\": \"steep\"},"
    "               \"edges\": [{\"edge\": 1, \"disabled\": true},"
    "                         {\"loop\": 1, \"edge\": 3, \"outside\": -0.25, \"profile\": \"wall\"},"
    "                         {\"edge\": 0, \"outside\": 0.8,"
    "                          \"inside\": {\"gap\": [0.25, 1], \"profile\": \"roof\"}}]},"
    "              {\"height\": 5, \"outside\": -1}],"
    " \"cap_height\": 12.5, \"priority\": \"min_volume\"}";

static const ag_plan_mesh_file full_meshes[2] = {{WINDOW, AG_UP_Y}, {WINDOW, AG_UP_Z}};

static void test_every_member_roundtrips(void **state)
{
    (void)state;
    ag_plan *p = read_text(full_doc);
    /* the document holds what it should, so the round trip below tests every member */
    assert_int_equal(p->nprofiles, 3);
    assert_non_null(p->profiles[0].seg_priority);
    assert_int_equal(p->profiles[0].seg_priority[0], 2);
    assert_int_equal(p->nmeshes, 2);
    assert_int_equal(p->anchors[1].mesh, 2);
    assert_int_equal(p->nsteps, 3);
    assert_true(p->steps[1].npoints == 4 && !p->steps[1].plan_frame);
    assert_true(p->steps[2].npoints == 3 && p->steps[2].plan_frame);
    assert_int_equal(p->noffsets, 2);
    assert_int_equal(p->offsets[0].nedges, 3);
    assert_true(p->offsets[0].edges[1].has_outside && p->offsets[0].edges[1].loop == 1);
    assert_int_equal(p->offsets[1].profile, -1);
    assert_true(p->offsets[0].has_gap && p->offsets[0].inner >= 0);
    assert_true(p->offsets[0].edges[2].has_gap && p->offsets[0].edges[2].inside > 0);
    ag_plan_write_options opt = {.mesh_files = full_meshes};
    check_roundtrip(p, &opt, "full document");

    /* the written document names the members as schema/plan.md does */
    json_t *doc = NULL;
    assert_int_equal(ag_plan_write_json_opts(p, &opt, &doc, NULL), AG_OK);
    json_t *pr = json_object_get(json_object_get(doc, "profiles"), "roof");
    assert_int_equal(json_array_size(json_object_get(pr, "segment_priority")), 2);
    assert_string_equal(json_string_value(json_object_get(
                            json_object_get(json_object_get(doc, "meshes"), "box"), "up")),
                        "z");
    assert_string_equal(json_string_value(json_object_get(json_object_get(doc, "meshes"), "win")),
                        WINDOW);
    json_t *annex = json_array_get(json_object_get(doc, "steps"), 2);
    assert_null(json_object_get(annex, "edge"));
    assert_null(json_object_get(annex, "width"));
    json_t *off = json_array_get(json_object_get(doc, "offsets"), 1);
    assert_null(json_object_get(off, "profile"));
    assert_null(json_object_get(off, "side"));
    assert_null(json_object_get(off, "edges"));
    json_decref(doc);
    ag_plan_free(p);
}

/* The comparison is not blind: each member changed on its own is told apart. */
static void test_comparison_sees_each_member(void **state)
{
    (void)state;
    ag_plan *a = read_text(full_doc);
    char why[256];
    assert_int_equal(plan_diff(a, a, why, sizeof why), 0);
#define MUTATE(stmt)                                                                           \
    do {                                                                                       \
        ag_plan *b = read_text(full_doc);                                                      \
        stmt;                                                                                  \
        assert_int_equal(plan_diff(a, b, why, sizeof why), 1);                                 \
        ag_plan_free(b);                                                                       \
    } while (0)
    MUTATE(b->profiles[0].seg_priority[1] = 8);
    MUTATE(b->profiles[2].priority = 0);
    MUTATE(b->profiles[0].tag[0] = 'x');
    MUTATE(b->profiles[2].points[1].z = 0.3);
    MUTATE(b->loops[0].profile[1] = 0);
    MUTATE(b->meshes[1].mesh->pos[0] += 1);
    MUTATE(b->anchors[0].mesh = 0);
    MUTATE(b->anchors[1].absolute = 0);
    MUTATE(b->steps[1].points[0] = 0);
    MUTATE(b->steps[2].plan_frame = 0);
    MUTATE(b->steps[0].depth = 0.5);
    MUTATE(b->offsets[0].side = -1);
    MUTATE(b->offsets[0].edges[0].disabled = 0);
    MUTATE(b->offsets[0].edges[1].has_outside = 0);
    MUTATE(b->offsets[0].edges[1].profile = -1);
    MUTATE(b->offsets[0].gap_to = 2);
    MUTATE(b->offsets[0].inner = -1);
    MUTATE(b->offsets[0].edges[2].has_gap = 0);
    MUTATE(b->offsets[0].edges[2].inside = 0);
    MUTATE(b->cap_height = 0);
    MUTATE(b->priority = AG_PRIORITY_MAX_VOLUME);
#undef MUTATE
    ag_plan_free(a);
}

static void expect_invalid(const ag_plan *p, const ag_plan_write_options *opt, const char *text)
{
    json_t *doc = (json_t *)1;
    ag_error err = {0};
    assert_int_equal(ag_plan_write_json_opts(p, opt, &doc, &err), AG_ERR_INVALID);
    assert_null(doc);
    if (!strstr(err.text, text))
        print_error("error text: %s\n", err.text);
    assert_non_null(strstr(err.text, text));
}

static void test_refuses_what_it_cannot_write(void **state)
{
    (void)state;
    ag_plan *p = read_text(full_doc);
    /* a plan keeps a mesh's geometry but not its file */
    expect_invalid(p, NULL, "mesh win has no file");
    ag_plan_mesh_file one[2] = {{WINDOW, AG_UP_Y}, {NULL, AG_UP_Z}};
    ag_plan_write_options opt = {.mesh_files = one};
    expect_invalid(p, &opt, "mesh box has no file");
    opt.mesh_files = full_meshes;

    double keep = p->loops[1].xy[3];
    p->loops[1].xy[3] = NAN;
    expect_invalid(p, &opt, "loop 1 is not a finite number");
    p->loops[1].xy[3] = keep;

    p->anchors[2].mesh = 3;
    expect_invalid(p, &opt, "anchor 2 names no mesh");
    p->anchors[2].mesh = 0;

    p->offsets[0].edges[2].profile = 3;
    expect_invalid(p, &opt, "offset 0 edge 2 names no profile");
    p->offsets[0].edges[2].profile = -1;

    p->steps[0].width = INFINITY;
    expect_invalid(p, &opt, "step 0 is not a finite number");
    p->steps[0].width = 2;

    char *name = p->profiles[2].name;
    p->profiles[2].name = p->profiles[0].name;
    expect_invalid(p, &opt, "two profiles are named \"roof\"");
    p->profiles[2].name = name;

    char bad[] = "st\xff";
    char *tag = p->profiles[0].tag;
    p->profiles[0].tag = bad;
    expect_invalid(p, &opt, "profile 0 is not valid UTF-8");
    p->profiles[0].tag = tag;

    /* put back as it was: it writes again */
    json_t *doc = NULL;
    assert_int_equal(ag_plan_write_json_opts(p, &opt, &doc, NULL), AG_OK);
    json_decref(doc);
    ag_plan_free(p);
}

/* Without meshes the options are not needed (the daemon's batch plans). */
static void test_plain_plan_without_options(void **state)
{
    (void)state;
    ag_plan *p = read_text("{\"profiles\": {\"hip\": [[0,0],[0,3],[1,4]]},"
                           " \"loops\": [[[0,0],[10,0],[10,6],[0,6]]]}");
    json_t *doc = NULL;
    assert_int_equal(ag_plan_write_json(p, &doc, NULL), AG_OK);
    char *t = json_dumps(doc, JSON_COMPACT);
    ag_plan *q = read_text(t);
    char why[256];
    assert_int_equal(plan_diff(p, q, why, sizeof why), 0);
    assert_null(json_object_get(doc, "cap_height"));
    assert_string_equal(json_string_value(json_object_get(doc, "priority")), "max_volume");
    free(t);
    json_decref(doc);
    ag_plan_free(q);
    ag_plan_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fixtures_roundtrip),
        cmocka_unit_test(test_every_member_roundtrips),
        cmocka_unit_test(test_comparison_sees_each_member),
        cmocka_unit_test(test_refuses_what_it_cannot_write),
        cmocka_unit_test(test_plain_plan_without_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
