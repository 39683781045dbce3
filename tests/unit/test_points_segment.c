/* Segmentation of point clouds (§3.1): generated buildings with known planes (turned,
 * jittered, at UTM coordinates stored as an offset or raw, windows recessed, flush or
 * proud, noisy), the CGAL building's 19 labelled planes, ROI refinement, determinism, and
 * the hard-case fixtures. A plane counts as found when one segment (or piece) holds at least
 * half of its points and at least 80 % of that segment's points are its own, the measure of
 * ../shared/tools/scoreboard. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/points/gen_building.h"
#include "core/points/segment_cloud.h"
#include "io/cloud_import.h"

#define DATA AG_REPO_DIR "/tests/data/points/"
#define SHARED AG_REPO_DIR "/../shared/data"

typedef struct {
    uint64_t key;
} pair_t;

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* found[t] = 1 when truth plane t is found among the groups (segments or pieces). */
static int count_found(const int32_t *truth, const int32_t *group, size_t n, int ntruth,
                       unsigned char *found)
{
    uint64_t *pairs = malloc((n ? n : 1) * sizeof *pairs);
    size_t np = 0, ngroups = 0;
    size_t *tsize = calloc((size_t)ntruth + 1, sizeof *tsize);
    for (size_t i = 0; i < n; i++) {
        if (truth[i] >= 0)
            tsize[truth[i]]++;
        if (group[i] >= 0 && (size_t)group[i] + 1 > ngroups)
            ngroups = (size_t)group[i] + 1;
        if (truth[i] >= 0 && group[i] >= 0)
            pairs[np++] = (uint64_t)truth[i] << 32 | (uint32_t)group[i];
    }
    size_t *gsize = calloc(ngroups + 1, sizeof *gsize);
    for (size_t i = 0; i < n; i++)
        if (group[i] >= 0)
            gsize[group[i]]++;
    qsort(pairs, np, sizeof *pairs, cmp_u64);
    size_t *best = calloc((size_t)ntruth + 1, sizeof *best), *bestg = calloc((size_t)ntruth + 1, sizeof *bestg);
    for (size_t i = 0; i < np;) {
        size_t j = i;
        while (j < np && pairs[j] == pairs[i])
            j++;
        int t = (int)(pairs[i] >> 32);
        if (j - i > best[t]) {
            best[t] = j - i;
            bestg[t] = pairs[i] & 0xFFFFFFFFu;
        }
        i = j;
    }
    int total = 0;
    for (int t = 0; t < ntruth; t++) {
        found[t] = tsize[t] && best[t] * 2 >= tsize[t] && best[t] * 5 >= gsize[bestg[t]] * 4;
        total += found[t];
    }
    free(pairs);
    free(tsize);
    free(gsize);
    free(best);
    free(bestg);
    return total;
}

static void test_generated_buildings(void **state)
{
    (void)state;
    const struct {
        ag_gen_window_kind kind;
        double rotation, jitter, noise, depth;
        int utm, absolute;
        size_t points;
    } v[] = {
        {AG_GEN_WINDOW_RECESSED, 0, 0, 0.005, 0, 0, 0, 60000},
        {AG_GEN_WINDOW_RECESSED, 33, 0, 0.005, 0, 1, 0, 60000},
        {AG_GEN_WINDOW_RECESSED, 33, 0.15, 0.005, 0, 1, 1, 60000},
        {AG_GEN_WINDOW_FLUSH, 120, 0, 0.005, 0, 0, 0, 60000},
        {AG_GEN_WINDOW_PROUD, 250, 0.1, 0.005, 0, 1, 0, 60000},
        {AG_GEN_WINDOW_RECESSED, 71, 0, 0.02, 0, 0, 0, 60000},
        {AG_GEN_WINDOW_RECESSED, 15, 0, 0.005, 0.6, 1, 1, 150000},
        {AG_GEN_WINDOW_PROUD, 200, 0.05, 0.005, 0.6, 0, 0, 150000},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        ag_gen_building_options go = {.points = v[k].points, .window = v[k].kind,
                                      .rotation = v[k].rotation, .jitter = v[k].jitter,
                                      .noise = v[k].noise, .window_depth = v[k].depth,
                                      .absolute = v[k].absolute, .seed = 100 + k};
        if (v[k].utm) {
            go.origin[0] = 486512.25;
            go.origin[1] = 5719877.75;
            go.origin[2] = 47.5;
        }
        ag_cloud *c;
        ag_error e;
        assert_int_equal(ag_gen_building(&go, &c, &e), AG_OK);
        int nplanes = (int)ag_gen_building_planes(&go);
        int32_t *truth = c->props[0].values;
        assert_string_equal(c->props[0].name, "plane");
        /* the truth is copied: segmentation adds normals but keeps the properties */
        int32_t *t = malloc(c->n * sizeof *t);
        memcpy(t, truth, c->n * sizeof *t);
        ag_segment_cloud_result *r;
        if (ag_segment_cloud_run(c, NULL, &r, &e) != AG_OK)
            fail_msg("variant %zu: %s", k, e.text);
        unsigned char *found = calloc((size_t)nplanes, 1);
        count_found(t, r->segment, c->n, nplanes, found);
        /* walls and roofs, whatever the turn, offset, noise or windows */
        for (int p = 0; p < 6; p++)
            if (!found[p])
                fail_msg("variant %zu: wall/roof plane %d not found", k, p);
        /* glass set 0.6 m back or out is a plane of its own; each window is one piece */
        if (v[k].depth > 0.5) {
            count_found(t, r->piece, c->n, nplanes, found);
            int glass = 0, windows = 0;
            for (int p = 6; p < nplanes; p += 5) {
                windows++;
                glass += found[p];
            }
            print_message("variant %zu: %d of %d window glass pieces found\n", k, glass, windows);
            assert_true(glass >= windows - windows / 10);
        }
        /* every point's label is its segment's label */
        for (size_t i = 0; i < c->n; i++) {
            if (r->segment[i] < 0)
                assert_int_equal(r->label[i], -1);
            else
                assert_int_equal(r->label[i], r->segments[r->segment[i]].label);
        }
        /* members list exactly the points of each segment */
        size_t members = r->member_start[r->nsegments];
        size_t assigned = 0;
        for (size_t i = 0; i < c->n; i++)
            assigned += r->segment[i] >= 0;
        assert_int_equal(members, assigned);
        for (size_t s = 0; s < r->nsegments; s++)
            for (uint32_t j = r->member_start[s]; j < r->member_start[s + 1]; j++)
                assert_int_equal(r->segment[r->members[j]], (int32_t)s);
        free(found);
        free(t);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

/* The segment holding most of truth plane t, and its label. */
static int32_t main_segment(const int32_t *truth, const ag_segment_cloud_result *r, int32_t t)
{
    size_t *cnt = calloc(r->nsegments + 1, sizeof *cnt), best = 0;
    int32_t seg = -1;
    for (size_t i = 0; i < r->n; i++)
        if (truth[i] == t && r->segment[i] >= 0 && ++cnt[r->segment[i]] > best) {
            best = cnt[r->segment[i]];
            seg = r->segment[i];
        }
    free(cnt);
    return seg;
}

static void test_alike_segments_share_labels(void **state)
{
    (void)state;
    /* front and back walls carry the same windows, so do the two gable walls, the two roof
     * planes are mirror images: §3.2 gives each pair one label, and the pairs different ones */
    for (int turn = 0; turn < 2; turn++) {
        ag_gen_building_options go = {.points = 120000, .rotation = turn ? 40 : 0, .seed = 4};
        ag_cloud *c;
        assert_int_equal(ag_gen_building(&go, &c, NULL), AG_OK);
        int32_t *truth = malloc(c->n * sizeof *truth);
        memcpy(truth, c->props[0].values, c->n * sizeof *truth);
        ag_segment_cloud_result *r;
        assert_int_equal(ag_segment_cloud_run(c, NULL, &r, NULL), AG_OK);
        int32_t lab[6];
        for (int p = 0; p < 6; p++) {
            int32_t s = main_segment(truth, r, p);
            assert_true(s >= 0);
            lab[p] = r->segments[s].label;
            assert_int_equal(r->segments[s].kind, AG_SEGMENT_CLOUD_PLANE);
        }
        assert_int_equal(lab[0], lab[2]); /* front, back */
        assert_int_equal(lab[1], lab[3]); /* right, left */
        assert_int_equal(lab[4], lab[5]); /* the roof planes */
        assert_int_not_equal(lab[0], lab[1]);
        assert_int_not_equal(lab[0], lab[4]);
        assert_int_not_equal(lab[1], lab[4]);
        free(truth);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

static void test_roi_refinement(void **state)
{
    (void)state;
    /* windows 25 cm deep: at the whole building's granularity their glass stays in the wall's
     * slab; segmented again in a box around three front windows it comes out */
    ag_gen_building_options go = {.points = 200000, .cols = 6, .rows = 3, .seed = 8, .noise = 0.003};
    ag_cloud *c;
    assert_int_equal(ag_gen_building(&go, &c, NULL), AG_OK);
    int32_t *truth = malloc(c->n * sizeof *truth);
    memcpy(truth, c->props[0].values, c->n * sizeof *truth);
    ag_segment_cloud_result *r;
    ag_segment_cloud_options plain = {0};
    plain.fine_threshold = 0.012; /* no adaptive split at this noise: the glass merges */
    assert_int_equal(ag_segment_cloud_run(c, &plain, &r, NULL), AG_OK);
    int32_t *before = malloc(c->n * sizeof *before);
    memcpy(before, r->segment, c->n * sizeof *before);
    double mn[3] = {0, -1, 0}, mx[3] = {12, 0.5, 9};
    assert_int_equal(ag_segment_cloud_refine(c, r, mn, mx, &plain, NULL), AG_OK);
    int nplanes = (int)ag_gen_building_planes(&go);
    unsigned char *found = calloc((size_t)nplanes, 1);
    count_found(truth, r->piece, c->n, nplanes, found);
    /* front windows 0-2 of each row (x < 12) are inside the box */
    int glass_in = 0;
    for (int row = 0; row < 3; row++)
        for (int col = 0; col < 3; col++)
            glass_in += found[6 + 5 * (row * 6 + col)];
    print_message("glass found inside the box: %d of 9\n", glass_in);
    assert_true(glass_in >= 8);
    /* points outside the box keep their segment (renumbered consistently) */
    int32_t *map = calloc(r->nsegments + 1 + c->n, sizeof *map);
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        int inside = p[0] >= mn[0] && p[0] <= mx[0] && p[1] >= mn[1] && p[1] <= mx[1] && p[2] >= mn[2] && p[2] <= mx[2];
        if (inside || before[i] < 0)
            continue;
        assert_true(r->segment[i] >= 0);
        if (!map[before[i]])
            map[before[i]] = r->segment[i] + 1;
        assert_int_equal(map[before[i]], r->segment[i] + 1);
    }
    free(map);
    free(found);
    free(before);
    free(truth);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

static void test_deterministic(void **state)
{
    (void)state;
    ag_gen_building_options go = {.points = 50000, .rotation = 10, .seed = 3};
    ag_cloud *a, *b;
    assert_int_equal(ag_gen_building(&go, &a, NULL), AG_OK);
    assert_int_equal(ag_gen_building(&go, &b, NULL), AG_OK);
    ag_segment_cloud_result *ra, *rb;
    assert_int_equal(ag_segment_cloud_run(a, NULL, &ra, NULL), AG_OK);
    assert_int_equal(ag_segment_cloud_run(b, NULL, &rb, NULL), AG_OK);
    assert_int_equal(ra->nsegments, rb->nsegments);
    assert_memory_equal(ra->segment, rb->segment, a->n * sizeof *ra->segment);
    assert_memory_equal(ra->label, rb->label, a->n * sizeof *ra->label);
    ag_segment_cloud_free(ra);
    ag_segment_cloud_free(rb);
    ag_cloud_free(a);
    ag_cloud_free(b);
}

static ag_segment_cloud_result *segment_file(const char *name, ag_cloud **c)
{
    ag_error e;
    char path[512];
    snprintf(path, sizeof path, DATA "%s", name);
    if (ag_cloud_import_file(path, c, &e) != AG_OK)
        fail_msg("%s: %s", name, e.text);
    ag_segment_cloud_result *r;
    if (ag_segment_cloud_run(*c, NULL, &r, &e) != AG_OK)
        fail_msg("%s: %s", name, e.text);
    assert_int_equal(r->n, (*c)->n);
    return r;
}

static void test_hard_cases(void **state)
{
    (void)state;
    ag_cloud *c;
    ag_segment_cloud_result *r = segment_file("empty.ply", &c);
    assert_int_equal(r->nsegments, 0);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    r = segment_file("one_point.ply", &c);
    assert_int_equal(r->nsegments, 0);
    assert_int_equal(r->segment[0], -1);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    /* a line is no plane: at most a cluster */
    r = segment_file("collinear.xyz", &c);
    assert_int_equal(r->nplanes, 0);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    /* duplicates: the grid is one plane, the pile of 50 copies of one spot is not in it */
    r = segment_file("duplicates.ply", &c);
    assert_true(r->nplanes >= 1);
    size_t in_plane = 0;
    for (size_t i = 0; i < 2000; i++)
        in_plane += r->segment[i] >= 0 && r->segment[i] == r->segment[0] &&
                    r->segments[r->segment[0]].kind == AG_SEGMENT_CLOUD_PLANE;
    assert_true(in_plane >= 1900);
    for (size_t i = 2000; i < 2050; i++)
        assert_true(r->segment[i] != r->segment[0]);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    /* UTM coordinates with millimetre detail: two walls */
    r = segment_file("huge_coords.xyz", &c);
    int32_t *truth = malloc(c->n * sizeof *truth);
    for (size_t i = 0; i < c->n; i++)
        truth[i] = i < 5000 ? 0 : 1;
    unsigned char found[2];
    assert_int_equal(count_found(truth, r->segment, c->n, 2, found), 2);
    free(truth);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

static void test_pile_of_duplicates(void **state)
{
    (void)state;
    /* 300k copies of one spot next to a small plane: linear work, no plane in the pile */
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, 302500, NULL), AG_OK);
    for (size_t i = 0; i < 300000; i++) {
        c->xyz[3 * i] = 5;
        c->xyz[3 * i + 1] = 5;
        c->xyz[3 * i + 2] = 5;
    }
    for (size_t i = 0; i < 2500; i++) {
        double *p = c->xyz + 3 * (300000 + i);
        p[0] = (double)(i % 50) * 0.1;
        p[1] = (double)(i / 50) * 0.1;
        p[2] = 0;
    }
    ag_segment_cloud_result *r;
    assert_int_equal(ag_segment_cloud_run(c, NULL, &r, NULL), AG_OK);
    size_t plane_pts = 0;
    for (size_t i = 300000; i < c->n; i++)
        plane_pts += r->segment[i] >= 0 && r->segments[r->segment[i]].kind == AG_SEGMENT_CLOUD_PLANE;
    assert_true(plane_pts > 2400);
    for (size_t i = 0; i < 300000; i += 997)
        assert_true(r->segment[i] < 0 || r->segments[r->segment[i]].kind == AG_SEGMENT_CLOUD_CLUSTERED);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

/* A cloud written twice over (exact copies, copies 1e-9 m off, each point next to its copy)
 * segments as the cloud itself: every copy in its original's segment, the same segments and
 * labels, each segment twice its points. Buildings recessed, proud, turned and at UTM. */
static void test_copies_change_nothing(void **state)
{
    (void)state;
    const ag_gen_building_options variants[] = {
        {.points = 30000, .seed = 5},
        {.points = 30000, .window = AG_GEN_WINDOW_PROUD, .rotation = 23, .seed = 6},
        {.points = 30000, .window = AG_GEN_WINDOW_FLUSH, .origin = {500000, 5.8e6, 0}, .seed = 7},
    };
    for (size_t v = 0; v < sizeof variants / sizeof *variants; v++) {
        ag_cloud *one;
        assert_int_equal(ag_gen_building(&variants[v], &one, NULL), AG_OK);
        ag_segment_cloud_result *ro;
        assert_int_equal(ag_segment_cloud_run(one, NULL, &ro, NULL), AG_OK);
        size_t n = one->n;
        for (int how = 0; how < 3; how++) {
            ag_cloud *two = ag_cloud_create();
            assert_int_equal(ag_cloud_resize(two, 2 * n, NULL), AG_OK);
            two->offset[0] = one->offset[0];
            two->offset[1] = one->offset[1];
            two->offset[2] = one->offset[2];
            /* where point i and its copy are */
            size_t first[2] = {0, n}, step = 1;
            if (how == 2) {
                first[1] = 1;
                step = 2;
            }
            for (size_t i = 0; i < n; i++)
                for (int k = 0; k < 3; k++) {
                    double x = one->xyz[3 * i + k];
                    two->xyz[3 * (first[0] + step * i) + k] = x;
                    two->xyz[3 * (first[1] + step * i) + k] = how == 1 ? x + 1e-9 : x;
                }
            ag_segment_cloud_result *rt;
            assert_int_equal(ag_segment_cloud_run(two, NULL, &rt, NULL), AG_OK);
            assert_int_equal(rt->nsegments, ro->nsegments);
            assert_int_equal(rt->nplanes, ro->nplanes);
            assert_int_equal(rt->nlabels, ro->nlabels);
            for (size_t i = 0; i < n; i++) {
                assert_int_equal(rt->segment[first[0] + step * i], ro->segment[i]);
                assert_int_equal(rt->segment[first[1] + step * i], ro->segment[i]);
                assert_int_equal(rt->label[first[1] + step * i], ro->label[i]);
            }
            for (size_t s = 0; s < ro->nsegments; s++)
                assert_int_equal(rt->segments[s].count, 2 * ro->segments[s].count);
            assert_non_null(two->normals); /* the copies got their original's normals */
            ag_segment_cloud_free(rt);
            ag_cloud_free(two);
        }
        ag_segment_cloud_free(ro);
        ag_cloud_free(one);
    }
}

static void test_cgal_building(void **state)
{
    (void)state;
    const char *path = SHARED "/pointcloud_cgal_building/building.ply";
    if (access(path, R_OK)) {
        print_message("skipping: %s is absent\n", SHARED "/pointcloud_cgal_building");
        skip();
    }
    for (int recompute = 0; recompute < 2; recompute++) {
        ag_cloud *c;
        ag_error e;
        assert_int_equal(ag_cloud_import_file(path, &c, &e), AG_OK);
        const ag_cloud_property *si = ag_cloud_find(c, "segment_index");
        assert_non_null(si);
        int32_t *truth = malloc(c->n * sizeof *truth);
        for (size_t i = 0; i < c->n; i++)
            truth[i] = (int32_t)ag_cloud_get(si, i);
        ag_segment_cloud_options o = {.recompute_normals = recompute};
        ag_segment_cloud_result *r;
        assert_int_equal(ag_segment_cloud_run(c, &o, &r, &e), AG_OK);
        unsigned char found[19];
        int n = count_found(truth, r->segment, c->n, 19, found);
        print_message("CGAL building, %s normals: %d of 19 planes found\n",
                      recompute ? "kNN" : "the file's", n);
        if (!recompute)
            assert_true(n >= 17);
        else
            assert_true(n >= 14); /* the labels were made with the file's normals */
        free(truth);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_generated_buildings),
        cmocka_unit_test(test_alike_segments_share_labels),
        cmocka_unit_test(test_roi_refinement),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_hard_cases),
        cmocka_unit_test(test_pile_of_duplicates),
        cmocka_unit_test(test_copies_change_nothing),
        cmocka_unit_test(test_cgal_building),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
