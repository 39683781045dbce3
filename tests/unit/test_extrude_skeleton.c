/* The sweep-plane skeleton: closed-form and brute-force references for uniform 45°
 * roofs, profiles (walls, gables, outward eaves), ambiguity priorities, the named hard
 * cases in tests/data/extrude, and the shell check itself. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/extrude/extrude.h"
#include "core/extrude/predicates.h"
#include "io/plan_json.h"

static ag_plan *plan_with(const ag_profile_point *pts, size_t np, const double *xy, size_t n)
{
    ag_plan *p = ag_plan_create();
    assert_non_null(p);
    assert_int_equal(ag_plan_add_profile(p, "p", pts, np, NULL, NULL, NULL), AG_OK);
    assert_int_equal(ag_plan_add_loop(p, xy, n, NULL, NULL), AG_OK);
    return p;
}

static ag_shell *extrude(ag_plan *p, ag_extrude_result *r)
{
    ag_mesh *m = ag_mesh_create();
    ag_shell *sh = NULL;
    ag_error err = {0};
    ag_status st = ag_extrude_plan(p, m, -1, r, &sh, &err);
    if (st != AG_OK)
        print_error("extrude failed: %s\n", err.text);
    assert_int_equal(st, AG_OK);
    /* every triangle index is a valid vertex and the component exists */
    for (size_t i = 0; i < 3 * m->ntris; i++)
        assert_true(m->tri[i] < m->nverts);
    assert_int_equal(m->ncomponents, 1);
    assert_int_equal(r->triangles, m->ntris);
    ag_mesh_free(m);
    return sh;
}

static const ag_profile_point R45[] = {{0, 0}, {1, 1}};

/* Height of the 45° roof over a convex polygon at (x, y): the distance to the nearest
 * supporting line, computed directly from the input corners. */
static double convex_height(const double *xy, size_t n, double x, double y)
{
    double h = INFINITY;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        double dx = xy[2 * j] - xy[2 * i], dy = xy[2 * j + 1] - xy[2 * i + 1];
        double d = (dx * (y - xy[2 * i + 1]) - dy * (x - xy[2 * i])) / hypot(dx, dy);
        h = fmin(h, d);
    }
    return h;
}

static void check_convex(const double *xy, size_t n)
{
    ag_plan *p = plan_with(R45, 2, xy, n);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    double top = 0;
    for (size_t v = 0; v < sh->nverts; v++) {
        const double *q = &sh->pos[3 * v];
        double ref = convex_height(xy, n, q[0], q[1]);
        if (fabs(q[2] - ref) > 1e-6)
            print_error("vertex %zu at (%g, %g): z %.9f, reference %.9f\n", v, q[0], q[1], q[2], ref);
        assert_true(fabs(q[2] - ref) <= 1e-6);
        top = fmax(top, q[2]);
    }
    assert_true(fabs(r.top - top) <= 1e-6);
    ag_shell_free(sh);
    ag_plan_free(p);
}

static void test_rectangle_closed_form(void **state)
{
    (void)state;
    const double W = 10, H = 6;
    const double xy[] = {0, 0, W, 0, W, H, 0, H};
    ag_plan *p = plan_with(R45, 2, xy, 4);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.faces, 5);
    /* a hip roof: ridge from (H/2, H/2) to (W - H/2, H/2) at height H/2 */
    int ridge = 0;
    for (size_t v = 0; v < sh->nverts; v++) {
        const double *q = &sh->pos[3 * v];
        if (q[2] == 0)
            continue;
        assert_true(fabs(q[2] - H / 2) < 1e-9);
        assert_true(fabs(q[1] - H / 2) < 1e-9);
        assert_true(fabs(q[0] - H / 2) < 1e-9 || fabs(q[0] - (W - H / 2)) < 1e-9);
        ridge++;
    }
    assert_true(ridge >= 2);
    /* volume of a hip roof: H/2 * H * (3W - H) / 6 */
    assert_true(fabs(r.volume - H / 2 * H * (3 * W - H) / 6) < 1e-6);
    ag_shell_free(sh);
    ag_plan_free(p);
}

static void test_convex_brute_force(void **state)
{
    (void)state;
    const double tri[] = {0, 0, 10, 0, 3, 7};
    check_convex(tri, 3);
    const double quad[] = {0, 0, 9, 1, 11, 7, 2, 5};
    check_convex(quad, 4);
    /* random convex polygons: sorted angles on an ellipse with jitter */
    srand(7);
    for (int t = 0; t < 20; t++) {
        size_t n = 3 + (size_t)(rand() % 12);
        double xy[64];
        double a0 = 0;
        for (size_t i = 0; i < n; i++) {
            double a = a0 + 2 * M_PI * (i + 0.8 * rand() / (double)RAND_MAX) / n;
            xy[2 * i] = 12 * cos(a);
            xy[2 * i + 1] = 7 * sin(a);
        }
        check_convex(xy, n);
    }
    /* regular 200-gon: all faces meet at the centre */
    double big[400];
    for (int i = 0; i < 200; i++) {
        big[2 * i] = 20 * cos(2 * M_PI * i / 200);
        big[2 * i + 1] = 20 * sin(2 * M_PI * i / 200);
    }
    check_convex(big, 200);
}

/* Every roof vertex lies on the plane of every face that holds it, and no roof point is
 * higher than its distance to the plan boundary (a straight-skeleton property). */
static void test_nonconvex_planes(void **state)
{
    (void)state;
    const double L[] = {0, 0, 10, 0, 10, 4, 4, 4, 4, 10, 0, 10};
    const double U[] = {0, 0, 12, 0, 12, 10, 8, 10, 8, 4, 4, 4, 4, 10, 0, 10};
    const double *shapes[] = {L, U};
    size_t sizes[] = {6, 8};
    for (int s = 0; s < 2; s++) {
        const double *xy = shapes[s];
        size_t n = sizes[s];
        ag_plan *p = plan_with(R45, 2, xy, n);
        ag_extrude_result r;
        ag_shell *sh = extrude(p, &r);
        assert_int_equal(r.failing_faces, 0);
        assert_int_equal(r.faces, n + 1);
        for (size_t f = 0; f < sh->nfaces; f++) {
            const ag_shell_face *fc = &sh->faces[f];
            if (fc->kind != AG_SHELL_FACE_SIDE)
                continue;
            size_t i = (size_t)fc->edge, j = (i + 1) % n;
            double dx = xy[2 * j] - xy[2 * i], dy = xy[2 * j + 1] - xy[2 * i + 1], len = hypot(dx, dy);
            for (uint32_t l = fc->first_loop; l < fc->first_loop + (fc->nloops & 0x7fffffffu); l++)
                for (uint32_t k = sh->loop_start[l]; k < sh->loop_start[l + 1]; k++) {
                    const double *q = &sh->pos[3 * sh->idx[k]];
                    double d = (dx * (q[1] - xy[2 * i + 1]) - dy * (q[0] - xy[2 * i])) / len;
                    assert_true(fabs(d - q[2]) < 1e-6);
                    /* distance to the boundary segments */
                    double best = INFINITY;
                    for (size_t a = 0; a < n; a++) {
                        size_t b = (a + 1) % n;
                        double ex = xy[2 * b] - xy[2 * a], ey = xy[2 * b + 1] - xy[2 * a + 1];
                        double t = ((q[0] - xy[2 * a]) * ex + (q[1] - xy[2 * a + 1]) * ey) / (ex * ex + ey * ey);
                        t = fmax(0, fmin(1, t));
                        best = fmin(best, hypot(q[0] - xy[2 * a] - t * ex, q[1] - xy[2 * a + 1] - t * ey));
                    }
                    assert_true(q[2] <= best + 1e-6);
                    assert_true(ag_pred_point_in_polygon(xy, n, q[0], q[1]) || best < 1e-6);
                }
        }
        ag_shell_free(sh);
        ag_plan_free(p);
    }
}

static void test_profiles(void **state)
{
    (void)state;
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    /* walls to 3 then 45°: every wall vertex at x/y of the plan up to z = 3 */
    const ag_profile_point hip[] = {{0, 0}, {0, 3}, {1, 4}};
    ag_plan *p = plan_with(hip, 3, xy, 4);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.faces, 9);
    assert_true(fabs(r.top - 6) < 1e-9);
    assert_true(fabs(r.volume - (180 + 72)) < 1e-6);
    int walltops = 0;
    for (size_t f = 0; f < sh->nfaces; f++)
        if (sh->faces[f].kind == AG_SHELL_FACE_SIDE)
            assert_true(sh->faces[f].segment == 0 || sh->faces[f].segment == 1);
    for (size_t v = 0; v < sh->nverts; v++)
        if (fabs(sh->pos[3 * v + 2] - 3) < 1e-12)
            walltops++;
    assert_int_equal(walltops, 4);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* flat: vertical walls capped at 4 m */
    const ag_profile_point wall[] = {{0, 0}, {0, 1}};
    p = plan_with(wall, 2, xy, 4);
    p->cap_height = 4;
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.faces, 6);
    assert_true(r.stats.capped);
    assert_true(fabs(r.volume - 240) < 1e-6);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* mansard: two slopes; volume of the frustum + hip on top, by slices */
    const ag_profile_point mans[] = {{0, 0}, {0, 2}, {1, 4}, {3, 5}};
    p = plan_with(mans, 4, xy, 4);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    /* at z = 4 the plan is 8 x 4; the last slope 2 m/m closes it at 4 + 2/2 */
    assert_true(fabs(r.top - 5) < 1e-9);
    double frustum = 0;
    for (int k = 0; k < 2000; k++) {
        double z = (k + 0.5) * 2.0 / 2000, o = z / 2;
        frustum += (10 - 2 * o) * (6 - 2 * o) * 2.0 / 2000;
    }
    double expect = 10 * 6 * 2 + frustum + 1 * 4 * (3 * 8 - 4) / 6.0 * 1; /* hip of 8x4, h = 1 */
    assert_true(fabs(r.volume - expect) < 1e-3);
    ag_shell_free(sh);
    ag_plan_free(p);
}

static void test_priority(void **state)
{
    (void)state;
    /* the bottom edge is two collinear edges with different slopes */
    const double xy[] = {0, 0, 5, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point steep[] = {{0, 0}, {0.5, 1}};
    const int32_t prof[] = {1, 0, 0, 0, 0};
    for (int pr = 0; pr < 2; pr++) {
        ag_plan *p = ag_plan_create();
        ag_plan_add_profile(p, "r45", R45, 2, NULL, NULL, NULL);
        ag_plan_add_profile(p, "steep", steep, 2, NULL, NULL, NULL);
        ag_plan_add_loop(p, xy, 5, prof, NULL);
        p->priority = pr ? AG_PRIORITY_MIN_VOLUME : AG_PRIORITY_MAX_VOLUME;
        ag_extrude_result r;
        ag_shell *sh = extrude(p, &r);
        assert_int_equal(r.failing_faces, 0);
        assert_int_equal(r.stats.merges, 1);
        /* max volume: the steep plane (0.5 m/m) takes the whole bottom edge */
        assert_true(fabs(r.top - (pr ? 3.0 : 4.0)) < 1e-9);
        ag_shell_free(sh);
        ag_plan_free(p);
    }
    /* a priority tag overrides the scheme: the 45° profile is tagged higher */
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "r45", R45, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "steep", steep, 2, NULL, NULL, NULL);
    p->profiles[0].priority = 1;
    ag_plan_add_loop(p, xy, 5, prof, NULL);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_true(fabs(r.top - 3.0) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);
}

/* Per-segment priority tags: the bottom edge is two collinear edges, both vertical walls
 * to 2 m (the same plane: no merge), then 45° (A) and 0.5 m/m (B). At 2 m they must merge;
 * the tags of the segments in effect there decide, not those of the walls. */
static double segment_priority_top(int32_t a_wall, int32_t a_roof, int32_t b_roof)
{
    const double xy[] = {0, 0, 5, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point A[] = {{0, 0}, {0, 2}, {1, 3}};
    const ag_profile_point B[] = {{0, 0}, {0, 2}, {0.5, 3}};
    const int32_t prof[] = {0, 1, 0, 0, 0};
    ag_plan *p = ag_plan_create();
    assert_int_equal(ag_plan_add_profile(p, "A", A, 3, NULL, NULL, NULL), AG_OK);
    assert_int_equal(ag_plan_add_profile(p, "B", B, 3, NULL, NULL, NULL), AG_OK);
    assert_int_equal(ag_plan_add_loop(p, xy, 5, prof, NULL), AG_OK);
    assert_int_equal(ag_plan_set_segment_priority(p, 0, 0, a_wall, NULL), AG_OK);
    assert_int_equal(ag_plan_set_segment_priority(p, 0, 1, a_roof, NULL), AG_OK);
    assert_int_equal(ag_plan_set_segment_priority(p, 1, 1, b_roof, NULL), AG_OK);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.merges, 1);
    double top = r.top;
    ag_shell_free(sh);
    ag_plan_free(p);
    return top;
}

static void test_segment_priority(void **state)
{
    (void)state;
    /* equal tags: max volume, B's shallower plane takes the bottom edge; the ridge is
     * where 0.5 t = 6 - t, t = 4 above the walls */
    assert_true(fabs(segment_priority_top(0, 0, 0) - 6.0) < 1e-9);
    /* A's roof segment tagged higher: 45° everywhere, ridge at 2 + 3 */
    assert_true(fabs(segment_priority_top(0, 5, 0) - 5.0) < 1e-9);
    /* a tag on A's wall segment is not in effect at the merge */
    assert_true(fabs(segment_priority_top(9, 0, 0) - 6.0) < 1e-9);
    /* B's roof tagged below A's untagged roof */
    assert_true(fabs(segment_priority_top(0, 0, -1) - 5.0) < 1e-9);
    /* bad segment indices are refused */
    ag_plan *p = ag_plan_create();
    ag_plan_add_profile(p, "r", R45, 2, NULL, NULL, NULL);
    ag_error err = {0};
    assert_int_equal(ag_plan_set_segment_priority(p, 0, 1, 1, &err), AG_ERR_INVALID);
    assert_int_equal(ag_plan_set_segment_priority(p, 3, 0, 1, &err), AG_ERR_INVALID);
    assert_int_equal(ag_profile_priority(&p->profiles[0], 0), 0);
    ag_plan_free(p);
}

static void test_fixtures(void **state)
{
    (void)state;
    const char *names[] = {"rectangle_hip", "l_shape", "u_shape", "cross", "hole",
                           "hole_on_skeleton", "fig11_four_at_point", "fig12_five_at_point",
                           "fig12_shared_ridge", "fig15_many_edges", "fig21_ambiguous_max",
                           "fig21_ambiguous_min", "fig22_two_bays", "parallel_collinear",
                           "nearly_parallel_different_angles", "wheel16", "gable_vertical",
                           "overhang_outward", "polygon_1000", "overhang_soffit",
                           "terrace_setback", "overhang_disabled_on_gables",
                           "segment_priority", "forced_chimney", "forced_dormer",
                           "mesh_anchor", "offset_overhang", "offset_open_ended",
                           "offset_disabled_extended", "grid_terrace_meets_soffit",
                           "grid_coincident_rays", "offset_inside_cap", "offset_inside_parapet",
                           "offset_inside_l", "offset_inside_per_edge",
                           "grid_merge_before_meeting", "grid_merge_before_meeting2",
                           "grid_soffits_meet_from_outside"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[512];
        snprintf(path, sizeof path, AG_REPO_DIR "/tests/data/extrude/%s.json", names[i]);
        ag_plan *p = NULL;
        ag_error err = {0};
        if (ag_plan_json_read_file(path, &p, &err) != AG_OK)
            fail_msg("%s: %s", names[i], err.text);
        json_t *doc = json_load_file(path, 0, NULL);
        assert_non_null(doc);
        json_t *ex = json_object_get(doc, "expect");
        ag_extrude_result r;
        ag_shell *sh = extrude(p, &r);
        if (json_is_true(json_object_get(ex, "watertight")) && r.failing_faces)
            fail_msg("%s: %zu failing faces, first: %s", names[i], r.failing_faces,
                     r.problems[0].reason);
        json_t *v;
        if ((v = json_object_get(ex, "faces")) && (size_t)json_integer_value(v) != r.faces)
            fail_msg("%s: %zu faces, expected %lld", names[i], r.faces, json_integer_value(v));
        if ((v = json_object_get(ex, "top")) && fabs(json_number_value(v) - r.top) > 1e-6)
            fail_msg("%s: top %.9f, expected %.9f", names[i], r.top, json_number_value(v));
        if ((v = json_object_get(ex, "volume")) && fabs(json_number_value(v) - r.volume) > 1e-6)
            fail_msg("%s: volume %.9f, expected %.9f", names[i], r.volume, json_number_value(v));
        assert_true(r.volume > 0);
        /* anchors: where they were instanced, or null for not at all */
        const char *an;
        json_object_foreach(json_object_get(ex, "anchors"), an, v)
        {
            const ag_anchor *a = NULL;
            for (size_t k = 0; k < p->nanchors; k++)
                if (strcmp(p->anchors[k].name, an) == 0)
                    a = &p->anchors[k];
            if (!a)
                fail_msg("%s: no anchor %s", names[i], an);
            if (json_is_null(v) ? a->found : !a->found)
                fail_msg("%s: anchor %s %s", names[i], an, a->found ? "instanced" : "not instanced");
            for (size_t k = 0; !json_is_null(v) && k < 3; k++)
                if (fabs(a->pos[k] - json_number_value(json_array_get(v, k))) > 1e-6)
                    fail_msg("%s: anchor %s at %.9f in %zu", names[i], an, a->pos[k], k);
        }
        /* placed meshes: one component each, with the expected bounding box */
        json_t *boxes = json_object_get(ex, "mesh_boxes");
        if (boxes) {
            ag_mesh *mm = ag_mesh_create();
            size_t placed = 0;
            assert_int_equal(ag_extrude_place_meshes(p, mm, -1, &placed, NULL), AG_OK);
            assert_int_equal(placed, json_array_size(boxes));
            assert_int_equal(mm->ncomponents, placed);
            for (size_t c = 0; c < placed; c++) {
                double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
                for (size_t t = 0; t < mm->ntris; t++)
                    for (int k = 0; mm->tri_component[t] == c && k < 3; k++)
                        for (int d = 0; d < 3; d++) {
                            double x = mm->pos[3 * mm->tri[3 * t + k] + d];
                            lo[d] = fmin(lo[d], x);
                            hi[d] = fmax(hi[d], x);
                        }
                json_t *b = json_array_get(boxes, c);
                for (int d = 0; d < 3; d++)
                    if (fabs(lo[d] - json_number_value(json_array_get(json_array_get(b, 0), d))) > 1e-6 ||
                        fabs(hi[d] - json_number_value(json_array_get(json_array_get(b, 1), d))) > 1e-6)
                        fail_msg("%s: mesh %zu spans %.9f..%.9f in %d", names[i], c, lo[d], hi[d], d);
            }
            ag_mesh_free(mm);
        }
        json_decref(doc);
        ag_shell_free(sh);
        ag_plan_free(p);
    }
}

/* The check reports a missing face by id and reason instead of passing silently. */
static void test_check_reports_open_faces(void **state)
{
    (void)state;
    ag_shell *s = ag_shell_create();
    uint32_t v[4], f[4];
    const double P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 4; i++)
        ag_shell_add_vertex(s, P[i][0], P[i][1], P[i][2], &v[i]);
    const int T[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    for (int i = 0; i < 3; i++) { /* the fourth face is left out */
        ag_shell_face fc = {AG_SHELL_FACE_SIDE, 0, i, 0, 0, 0, 0};
        ag_shell_add_face(s, &fc, &f[i]);
        for (int k = 0; k < 3; k++)
            ag_shell_add_segment(s, f[i], v[T[i][k]], v[T[i][(k + 1) % 3]]);
    }
    assert_int_equal(ag_shell_finish(s, 1e-9), AG_OK);
    ag_shell_problem pr[4];
    size_t n = ag_shell_check(s, pr, 4);
    assert_int_equal(n, 3); /* each face borders the hole */
    assert_non_null(strstr(pr[0].reason, "no opposite edge"));
    /* with the fourth face it closes */
    ag_shell_free(s);
    s = ag_shell_create();
    for (int i = 0; i < 4; i++)
        ag_shell_add_vertex(s, P[i][0], P[i][1], P[i][2], &v[i]);
    for (int i = 0; i < 4; i++) {
        ag_shell_face fc = {AG_SHELL_FACE_SIDE, 0, i, 0, 0, 0, 0};
        ag_shell_add_face(s, &fc, &f[i]);
        for (int k = 0; k < 3; k++)
            ag_shell_add_segment(s, f[i], v[T[i][k]], v[T[i][(k + 1) % 3]]);
    }
    assert_int_equal(ag_shell_finish(s, 1e-9), AG_OK);
    assert_int_equal(ag_shell_check(s, pr, 4), 0);
    assert_true(fabs(ag_shell_volume(s) - 1.0 / 6) < 1e-12);
    ag_shell_free(s);
}

/* Two solids touching along one edge (as a terrace and a soffit can meet): the edge has
 * two half-edges each way; each must be paired with the other face of its own solid. */
static void test_check_edge_touching_solids(void **state)
{
    (void)state;
    ag_shell *s = ag_shell_create();
    /* cube A [0,1]^3 and cube B [1,2]x[1,2]x[0,1]: they share x = y = 1 */
    static const int F[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    uint32_t faces[2][6];
    for (int c = 0; c < 2; c++) {
        uint32_t v[8];
        for (int i = 0; i < 8; i++) {
            double x = (i == 1 || i == 2 || i == 5 || i == 6) ? 1 : 0;
            double y = (i == 2 || i == 3 || i == 6 || i == 7) ? 1 : 0;
            ag_shell_add_vertex(s, x + c, y + c, i >= 4, &v[i]);
        }
        for (int f = 0; f < 6; f++) {
            ag_shell_face fc = {AG_SHELL_FACE_SIDE, c, f, 0, 0, 0, 0};
            ag_shell_add_face(s, &fc, &faces[c][f]);
            for (int k = 0; k < 4; k++)
                ag_shell_add_segment(s, faces[c][f], v[F[f][k]], v[F[f][(k + 1) % 4]]);
        }
    }
    assert_int_equal(ag_shell_finish(s, 1e-9), AG_OK);
    ag_shell_problem pr[4];
    assert_int_equal(ag_shell_check(s, pr, 4), 0);
    size_t shared = 0;
    for (size_t h = 0; h < s->nhalf; h++) {
        assert_true(s->he_twin[h] != UINT32_MAX);
        /* every pair stays within one cube */
        assert_int_equal(s->faces[s->he_face[h]].loop, s->faces[s->he_face[s->he_twin[h]]].loop);
        const double *p = &s->pos[3 * s->idx[h]], *q = &s->pos[3 * s->idx[s->he_next[h]]];
        shared += p[0] == 1 && p[1] == 1 && q[0] == 1 && q[1] == 1;
    }
    assert_int_equal(shared, 4);
    assert_true(fabs(ag_shell_volume(s) - 2) < 1e-12);
    ag_shell_free(s);
}

static void test_anchors(void **state)
{
    (void)state;
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point hip[] = {{0, 0}, {0, 3}, {1, 4}};
    ag_plan *p = plan_with(hip, 3, xy, 4);
    ag_anchor a[5];
    memset(a, 0, sizeof a);
    const struct {
        int32_t edge;
        int absolute;
        double along, z;
    } spec[5] = {
        {0, 0, 0.5, 1}, /* wall, relative */
        {0, 0, 0.5, 4}, /* roof: the edge spans x 1..9 at z 4 */
        {0, 1, 2.0, 4}, /* absolute, 2 m from the corner */
        {0, 1, 0.5, 4}, /* falls off the shrunken edge */
        {1, 0, 0.5, 7}, /* above the ridge */
    };
    for (int i = 0; i < 5; i++) {
        a[i].edge = spec[i].edge;
        a[i].absolute = spec[i].absolute;
        a[i].along = spec[i].along;
        a[i].z = spec[i].z;
    }
    for (int i = 0; i < 5; i++)
        assert_int_equal(ag_plan_add_anchor(p, &a[i], NULL), AG_OK);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    const ag_anchor *h = p->anchors;
    assert_true(h[0].found);
    assert_true(fabs(h[0].pos[0] - 5) < 1e-9 && fabs(h[0].pos[1]) < 1e-9 && fabs(h[0].pos[2] - 1) < 1e-9);
    assert_true(fabs(h[0].normal[1] + 1) < 1e-9);
    assert_true(h[1].found);
    assert_true(fabs(h[1].pos[0] - 5) < 1e-9 && fabs(h[1].pos[1] - 1) < 1e-9 && fabs(h[1].pos[2] - 4) < 1e-9);
    assert_true(fabs(h[1].normal[1] + sqrt(0.5)) < 1e-9 && fabs(h[1].normal[2] - sqrt(0.5)) < 1e-9);
    assert_int_equal(sh->faces[h[1].face].edge, 0);
    assert_int_equal(sh->faces[h[1].face].segment, 1);
    assert_true(h[2].found && fabs(h[2].pos[0] - 2) < 1e-9 && fabs(h[2].pos[1] - 1) < 1e-9);
    assert_false(h[3].found);
    assert_false(h[4].found);
    assert_true(fabs(r.top - 6) < 1e-9); /* an anchor above the roof does not raise it */
    ag_shell_free(sh);
    ag_plan_free(p);
}

/* Area of the horizontal faces at height z made by plan edits (loop -1), signed by
 * facing: up positive. */
static double edit_floor_area(const ag_shell *sh, double z)
{
    double area = 0;
    for (size_t f = 0; f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        if (fc->loop != -1)
            continue;
        for (uint32_t l = fc->first_loop; l < fc->first_loop + (fc->nloops & 0x7fffffffu); l++) {
            double a = 0;
            int flat = 1;
            uint32_t b0 = sh->loop_start[l], b1 = sh->loop_start[l + 1];
            for (uint32_t k = b0; k < b1; k++) {
                const double *p = &sh->pos[3 * sh->idx[k]];
                const double *q = &sh->pos[3 * sh->idx[k + 1 < b1 ? k + 1 : b0]];
                a += p[0] * q[1] - q[0] * p[1];
                if (fabs(p[2] - z) > 1e-9)
                    flat = 0;
            }
            if (flat)
                area += a / 2;
        }
    }
    return area;
}

static void test_natural_steps(void **state)
{
    (void)state;
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point hip[] = {{0, 0}, {0, 3}, {1, 4}};
    const ag_profile_point dormer[] = {{0, 0}, {0, 1.2}, {1, 2.2}};
    for (int recess = 0; recess < 2; recess++) {
        ag_plan *p = plan_with(hip, 3, xy, 4);
        size_t dp = 0;
        assert_int_equal(ag_plan_add_profile(p, "dormer", dormer, 3, NULL, &dp, NULL), AG_OK);
        ag_plan_step st;
        memset(&st, 0, sizeof st);
        st.at.edge = 0;
        st.at.along = 0.5;
        st.at.z = 3.5;
        st.width = 2;
        st.depth = recess ? -0.8 : 1.2;
        st.profile = (int32_t)dp;
        assert_int_equal(ag_plan_add_step(p, &st, NULL), AG_OK);
        ag_extrude_result r;
        ag_shell *sh = extrude(p, &r);
        if (r.failing_faces)
            fail_msg("%s: %s", recess ? "recess" : "dormer", r.problems[0].reason);
        assert_int_equal(r.stats.steps, 1);
        /* the step's floor: width x depth at its height, facing down for a protrusion
         * and up for a recess */
        double a = edit_floor_area(sh, 3.5);
        assert_true(fabs(a - (recess ? 2 * 0.8 : -2 * 1.2)) < 1e-6);
        /* without the step: 252 m³; the dormer adds at least the part of its box that
         * stands in front of the roof plane */
        if (!recess)
            assert_true(r.volume > 252 + 2 * 1.2 * 1.2 * 0.5);
        ag_shell_free(sh);
        ag_plan_free(p);
    }
    /* an anchor above the roof: the step is not made, and said so */
    ag_plan *p = plan_with(hip, 3, xy, 4);
    size_t dp = 0;
    ag_plan_add_profile(p, "dormer", dormer, 3, NULL, &dp, NULL);
    ag_plan_step st;
    memset(&st, 0, sizeof st);
    st.at.edge = 1;
    st.at.along = 0.5;
    st.at.z = 9;
    st.width = 1;
    st.depth = 1;
    st.profile = (int32_t)dp;
    ag_plan_add_step(p, &st, NULL);
    ag_extrude_result r;
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.steps, 0);
    ag_shell_free(sh);
    ag_plan_free(p);
}

static ag_plan *forced_plan(const double *poly, size_t n, double h, int plan_frame,
                            ag_plan_step **out)
{
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point hip[] = {{0, 0}, {0, 3}, {1, 4}};
    const ag_profile_point box[] = {{0, 0}, {0, 1}, {1, 2}};
    ag_plan *p = plan_with(hip, 3, xy, 4);
    size_t bp = 0;
    assert_int_equal(ag_plan_add_profile(p, "box", box, 3, NULL, &bp, NULL), AG_OK);
    if (!poly)
        return p;
    ag_plan_step st;
    memset(&st, 0, sizeof st);
    st.at.edge = plan_frame ? -1 : 0;
    st.at.along = 0.5;
    st.at.z = h;
    st.plan_frame = plan_frame;
    st.npoints = n;
    st.points = (double *)poly;
    st.profile = (int32_t)bp;
    assert_int_equal(ag_plan_add_step(p, &st, NULL), AG_OK);
    if (out)
        *out = &p->steps[0];
    return p;
}

static void test_forced_steps(void **state)
{
    (void)state;
    ag_extrude_result r0, r;
    ag_plan *p = forced_plan(NULL, 0, 0, 0, NULL);
    ag_shell *sh = extrude(p, &r0);
    ag_shell_free(sh);
    ag_plan_free(p);
    assert_true(fabs(r0.volume - 252) < 1e-6);

    /* straddling the front slope at 3.5 m (anchor frame: 0.5 m behind the active edge,
     * 1 m in front): the floor is the part in front, 2 x 1 m, facing down */
    const double straddle[] = {-1, -0.5, 1, -0.5, 1, 1, -1, 1};
    p = forced_plan(straddle, 4, 3.5, 0, NULL);
    sh = extrude(p, &r);
    if (r.failing_faces)
        fail_msg("straddle: %s", r.problems[0].reason);
    assert_int_equal(r.stats.steps, 1);
    assert_true(fabs(edit_floor_area(sh, 3.5) + 2.0) < 1e-6);
    assert_true(r.volume > r0.volume + 2.0 * 1.0); /* at least the 1 m walls in front */
    ag_shell_free(sh);
    ag_plan_free(p);

    /* the same, clockwise: oriented before use */
    const double straddle_cw[] = {-1, 1, 1, 1, 1, -0.5, -1, -0.5};
    p = forced_plan(straddle_cw, 4, 3.5, 0, NULL);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_true(fabs(edit_floor_area(sh, 3.5) + 2.0) < 1e-6);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* plan frame, wholly inside the active plan: nothing changes, counted as skipped */
    const double inside[] = {4, 2, 6, 2, 6, 4, 4, 4};
    p = forced_plan(inside, 4, 2, 1, NULL);
    sh = extrude(p, &r);
    assert_int_equal(r.stats.steps, 0);
    assert_int_equal(r.stats.steps_skipped, 1);
    assert_true(fabs(r.volume - r0.volume) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* disjoint, outside: a separate block from 2 m; its volume is that of the same
     * square extruded on its own */
    const double island[] = {12, 0, 14, 0, 14, 2, 12, 2};
    p = forced_plan(island, 4, 2, 1, NULL);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.steps, 1);
    assert_true(fabs(edit_floor_area(sh, 2) + 4.0) < 1e-6);
    ag_shell_free(sh);
    ag_plan_free(p);
    const ag_profile_point box[] = {{0, 0}, {0, 1}, {1, 2}};
    const double sq[] = {12, 0, 14, 0, 14, 2, 12, 2};
    ag_plan *pb = plan_with(box, 3, sq, 4);
    ag_extrude_result rb;
    sh = extrude(pb, &rb);
    ag_shell_free(sh);
    ag_plan_free(pb);
    assert_true(fabs(r.volume - (r0.volume + rb.volume)) < 1e-6);

    /* swallowing the whole active plan at 3.5 m (9 x 5 there): the floor is the
     * 12 x 8 polygon minus it; the roof above is the polygon's own */
    const double big[] = {-1, -1, 11, -1, 11, 7, -1, 7};
    p = forced_plan(big, 4, 3.5, 1, NULL);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_true(fabs(edit_floor_area(sh, 3.5) + (96.0 - 45.0)) < 1e-6);
    assert_true(fabs(r.top - (3.5 + 1 + 4)) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* over a corner of the walls at 1 m: the corner ends inside, two edges are cut */
    const double corner[] = {8, -2, 12, -2, 12, 2, 8, 2};
    p = forced_plan(corner, 4, 1, 1, NULL);
    sh = extrude(p, &r);
    if (r.failing_faces)
        fail_msg("corner: %s", r.problems[0].reason);
    assert_int_equal(r.stats.steps, 1);
    assert_true(fabs(edit_floor_area(sh, 1) + 12.0) < 1e-6);
    assert_true(r.volume > r0.volume + 12.0);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* a corner exactly on the active boundary: refused, not guessed */
    const double touch[] = {5, -1, 6, 0, 5, 0.5};
    p = forced_plan(touch, 3, 1, 1, NULL);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.steps_skipped, 1);
    assert_true(fabs(r.volume - r0.volume) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* bad polygons are refused when added */
    p = forced_plan(NULL, 0, 0, 0, NULL);
    ag_plan_step st;
    memset(&st, 0, sizeof st);
    const double bow[] = {0, 0, 2, 2, 2, 0, 0, 1};
    st.at.z = 1;
    st.plan_frame = 1;
    st.points = (double *)bow;
    st.npoints = 4;
    st.profile = 1;
    ag_error err = {0};
    assert_int_equal(ag_plan_add_step(p, &st, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "cross"));
    st.npoints = 2;
    assert_int_equal(ag_plan_add_step(p, &st, &err), AG_ERR_INVALID);
    ag_plan_free(p);
}

/* Area of the horizontal faces at height z, signed by facing (up positive). */
static double flat_area(const ag_shell *sh, double z)
{
    double area = 0;
    for (size_t f = 0; f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        for (uint32_t l = fc->first_loop; l < fc->first_loop + (fc->nloops & 0x7fffffffu); l++) {
            double a = 0;
            int flat = 1;
            uint32_t b0 = sh->loop_start[l], b1 = sh->loop_start[l + 1];
            for (uint32_t k = b0; k < b1; k++) {
                const double *p = &sh->pos[3 * sh->idx[k]];
                const double *q = &sh->pos[3 * sh->idx[k + 1 < b1 ? k + 1 : b0]];
                a += p[0] * q[1] - q[0] * p[1];
                if (fabs(p[2] - z) > 1e-9)
                    flat = 0;
            }
            if (flat)
                area += a / 2;
        }
    }
    return area;
}

static ag_plan *offset_plan(double outside, int disable_gables, int side, int32_t after)
{
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point wall[] = {{0, 0}, {0, 1}}, roof[] = {{0, 0}, {1, 1}};
    ag_plan *p = plan_with(wall, 2, xy, 4);
    ag_plan_add_profile(p, "roof", roof, 2, NULL, NULL, NULL);
    ag_plan_add_profile(p, "end", wall, 2, NULL, NULL, NULL);
    ag_offset_edge ov[2] = {{0, 1, 1, 0, 0, -1, 0, 0, 0, 0, 0}, {0, 3, 1, 0, 0, -1, 0, 0, 0, 0, 0}};
    ag_plan_offset o = {3, outside, after, side ? 2 : -1, disable_gables ? 2 : 0, ov, 0, 0, 0, -1, -1};
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_OK);
    return p;
}

static void test_offset_events(void **state)
{
    (void)state;
    ag_extrude_result ra, rb;
    /* the mitre cut adds, at each of the 4 corners, the roof over the triangle between
     * the gable wall's line and the mitre: the integral of (y + 0.5) over it, 1/48 */
    ag_plan *p = offset_plan(0.5, 1, 0, 1);
    ag_shell *sh = extrude(p, &ra);
    assert_int_equal(ra.stats.offsets, 1);
    assert_int_equal(ra.stats.offset_sides, 0);
    ag_shell_free(sh);
    ag_plan_free(p);
    p = offset_plan(0.5, 1, 1, 1);
    sh = extrude(p, &rb);
    assert_int_equal(rb.failing_faces, 0);
    assert_int_equal(rb.stats.offset_sides, 4);
    assert_true(fabs(rb.volume - ra.volume - 4.0 / 48) < 1e-9);
    /* the soffit: the two eaves' strips, mitred, facing down at 3 m: 2 * 0.5 * 10.5 */
    assert_true(fabs(flat_area(sh, 3) + 10.5) < 1e-9);
    /* faces: the soffits are flat growth (segment -1) of the roof profile, then segment 0 */
    int soffits = 0, roofs = 0, sides = 0;
    for (size_t f = 0; f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        if (!(fc->nloops & 0x7fffffffu) || fc->kind != AG_SHELL_FACE_SIDE)
            continue;
        soffits += fc->profile == 1 && fc->segment == -1;
        roofs += fc->profile == 1 && fc->segment == 0;
        sides += fc->profile == 2 && fc->segment == 0;
    }
    assert_int_equal(soffits, 2);
    assert_int_equal(roofs, 2);
    assert_int_equal(sides, 4);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* inwards, every edge, walls carrying on (no profile after) and a cap at 5 m: a 1 m
     * terrace at 3 m, 60 - 32 m² facing up, and 8 x 4 above it */
    p = offset_plan(-1, 0, 0, -1);
    p->cap_height = 5;
    sh = extrude(p, &ra);
    assert_int_equal(ra.failing_faces, 0);
    assert_true(fabs(flat_area(sh, 3) - 28) < 1e-9);
    assert_true(fabs(ra.volume - (180 + 64)) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* per-edge distance and profile; anchors still find the input edge after the event */
    p = offset_plan(0.5, 1, 0, 1);
    p->offsets[0].edges[0] = (ag_offset_edge){0, 0, 0, 1, 1.0, 0, 0, 0, 0, 0, 0};
    p->offsets[0].nedges = 1;
    ag_anchor a;
    memset(&a, 0, sizeof a);
    a.edge = 0;
    a.along = 0.5;
    a.z = 3.2;
    ag_plan_add_anchor(p, &a, NULL);
    sh = extrude(p, &ra);
    assert_int_equal(ra.failing_faces, 0);
    /* edge 0 moved 1 m out and keeps a vertical wall (profile 0): the anchor is on it */
    assert_true(p->anchors[0].found);
    assert_true(fabs(p->anchors[0].pos[1] + 1.0) < 1e-9 && fabs(p->anchors[0].pos[2] - 3.2) < 1e-9);
    assert_true(fabs(p->anchors[0].normal[1] + 1) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* a forced step's profile heights count from the step and the offset interval is
     * skipped over: an island from 1 m (walls 1.5 m, then 45°), moved 0.5 m out at 2 m,
     * turns at 2.5 m and closes 1.5 m higher, at 4 m */
    {
        const double hxy[] = {0, 0, 10, 0, 10, 6, 0, 6};
        const ag_profile_point hip2[] = {{0, 0}, {0, 2}, {1, 3}};
        const ag_profile_point box[] = {{0, 0}, {0, 1.5}, {1, 2.5}};
        const double island[] = {12, 0, 14, 0, 14, 2, 12, 2};
        p = plan_with(hip2, 3, hxy, 4);
        ag_plan_add_profile(p, "box", box, 3, NULL, NULL, NULL);
        ag_plan_step st;
        memset(&st, 0, sizeof st);
        st.at.z = 1;
        st.plan_frame = 1;
        st.points = (double *)island;
        st.npoints = 4;
        st.profile = 1;
        assert_int_equal(ag_plan_add_step(p, &st, NULL), AG_OK);
        ag_plan_offset oo = {2, 0.5, -1, -1, 0, NULL, 0, 0, 0, -1, -1};
        assert_int_equal(ag_plan_add_offset(p, &oo, NULL), AG_OK);
        sh = extrude(p, &ra);
        assert_int_equal(ra.failing_faces, 0);
        double itop = 0;
        for (size_t f = 0; f < sh->nfaces; f++)
            if (sh->faces[f].loop == -1)
                for (uint32_t l = sh->faces[f].first_loop;
                     l < sh->faces[f].first_loop + (sh->faces[f].nloops & 0x7fffffffu); l++)
                    for (uint32_t k = sh->loop_start[l]; k < sh->loop_start[l + 1]; k++)
                        itop = fmax(itop, sh->pos[3 * sh->idx[k] + 2]);
        assert_true(fabs(itop - 4.0) < 1e-9);
        assert_true(fabs(ra.top - 5.5) < 1e-9); /* the main roof from 11 x 7 at 2 m */
        ag_shell_free(sh);
        ag_plan_free(p);
    }

    /* an offset at the height of a horizontal profile segment is refused */
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point ov[] = {{0, 0}, {0, 3}, {-0.5, 3}, {0.5, 4}};
    p = plan_with(ov, 4, xy, 4);
    ag_plan_offset o = {3, 0.2, -1, -1, 0, NULL, 0, 0, 0, -1, -1};
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_OK);
    ag_mesh *m = ag_mesh_create();
    ag_error err = {0};
    assert_int_equal(ag_extrude_plan(p, m, -1, &ra, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "offset 0"));
    assert_int_equal(m->ntris, 0);
    ag_mesh_free(m);
    /* bad offsets are refused when added */
    o.profile = 1;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.profile = 0; /* has a horizontal segment */
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.profile = -1;
    o.z = 0;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    ag_plan_free(p);
}

/* Newell normal of a face's first loop (area-weighted, not normalised). */
static void face_normal(const ag_shell *sh, uint32_t f, double n[3])
{
    n[0] = n[1] = n[2] = 0;
    uint32_t l = sh->faces[f].first_loop, b0 = sh->loop_start[l], b1 = sh->loop_start[l + 1];
    for (uint32_t k = b0; k < b1; k++) {
        const double *p = &sh->pos[3 * sh->idx[k]], *q = &sh->pos[3 * sh->idx[k + 1 < b1 ? k + 1 : b0]];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
}

static ag_plan *gap_plan(double from, double to, double cap)
{
    const double xy[] = {0, 0, 10, 0, 10, 6, 0, 6};
    const ag_profile_point wall[] = {{0, 0}, {0, 1}};
    ag_plan *p = plan_with(wall, 2, xy, 4);
    ag_plan_add_profile(p, "roof", R45, 2, NULL, NULL, NULL);
    ag_plan_offset o;
    memset(&o, 0, sizeof o);
    o.z = 3;
    o.profile = o.side = -1;
    o.has_gap = 1;
    o.gap_from = from;
    o.gap_to = to;
    o.inside = 0;
    o.inner = 1;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_OK);
    p->cap_height = cap;
    return p;
}

/* §4.6's inside boundary: a gap between an outer ring of walls and an inner shell. */
static void test_offset_inside(void **state)
{
    (void)state;
    ag_extrude_result r;
    ag_plan *p = gap_plan(0.5, 1.5, 4);
    ag_shell *sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.offset_gaps, 1);
    /* the gap's floor faces up at 3 m: 9 x 5 - 7 x 3, one face tagged with the inside profile */
    assert_true(fabs(flat_area(sh, 3) - 24) < 1e-9);
    int floors = 0, hips = 0, walls[4] = {0}, inner_walls[4] = {0};
    for (uint32_t f = 0; f < sh->nfaces; f++) {
        const ag_shell_face *fc = &sh->faces[f];
        if (!(fc->nloops & 0x7fffffffu))
            continue;
        if (fc->kind == AG_SHELL_FACE_CAP && fc->profile == 0) {
            floors++;
            double n[3];
            face_normal(sh, f, n);
            assert_true(n[2] > 0);
            continue;
        }
        if (fc->kind != AG_SHELL_FACE_SIDE)
            continue;
        assert_int_equal(fc->loop, 0);
        assert_true(fc->edge >= 0 && fc->edge < 4);
        if (fc->profile == 1) {
            hips++;
            continue;
        }
        walls[fc->edge]++;
        /* the ring's face towards the gap, 0.5 m in from edge 0, faces the gap (+y) */
        double n[3];
        face_normal(sh, f, n);
        const double *q = &sh->pos[3 * sh->idx[sh->loop_start[fc->first_loop]]];
        if (fc->edge == 0 && fabs(q[1] - 0.5) < 1e-9) {
            inner_walls[0]++;
            assert_true(n[1] > 0 && fabs(n[0]) < 1e-9 && fabs(n[2]) < 1e-9);
        }
    }
    assert_int_equal(floors, 1);
    assert_int_equal(hips, 4);
    for (int e = 0; e < 4; e++)
        assert_int_equal(walls[e], 2); /* the outer wall and the ring's inner face */
    assert_int_equal(inner_walls[0], 1);
    /* 180 below, the ring (60 - 45) and the hip over 7 x 3 capped 1 m up: 21 - 10 + 4/3 */
    assert_true(fabs(r.volume - (180 + 15 + 21 - 10 + 4.0 / 3)) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* a gap wider than half the plan leaves no inner shell: the floor covers the inset */
    p = gap_plan(0.5, 4, 4);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_true(fabs(flat_area(sh, 3) - 45) < 1e-9);
    assert_true(fabs(r.volume - 195) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);
    /* ... and one starting beyond it makes no gap at all */
    p = gap_plan(3.5, 4, 4);
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.offset_gaps, 0);
    assert_true(fabs(r.volume - 240) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* two gaps, one above the other: a ring inside a ring, then a block */
    p = gap_plan(0.5, 1, 6);
    ag_plan_offset o2 = p->offsets[0];
    o2.z = 4;
    o2.edges = NULL;
    o2.inner = -1;
    assert_int_equal(ag_plan_add_offset(p, &o2, NULL), AG_OK);
    p->offsets[0].inner = -1;
    sh = extrude(p, &r);
    assert_int_equal(r.failing_faces, 0);
    assert_int_equal(r.stats.offset_gaps, 2);
    /* the 0.5 m ring is too narrow for the second gap; the 8 x 4 block gets a 7 x 3 ring
     * and a 6 x 2 block: 180 + 15 * 3 + 32 + (32 - 21) * 2 + 12 * 2 */
    assert_true(fabs(r.volume - 303) < 1e-9);
    assert_true(fabs(flat_area(sh, 4) - 9) < 1e-9);
    ag_shell_free(sh);
    ag_plan_free(p);

    /* refused: a gap not 0 < from < to, no inside profile, an edge gap without the event's */
    p = gap_plan(0.5, 1.5, 0);
    ag_plan_offset o = p->offsets[0];
    o.z = 5;
    o.gap_from = 1.5;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.gap_from = 0;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.gap_from = 0.5;
    o.inside = -1;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.inside = 0;
    o.has_gap = 0;
    ag_offset_edge oe;
    memset(&oe, 0, sizeof oe);
    oe.profile = -1;
    oe.has_gap = 1;
    oe.gap_from = 0.2;
    oe.gap_to = 0.4;
    o.edges = &oe;
    o.nedges = 1;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    o.has_gap = 1;
    oe.gap_to = 0.1;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_ERR_INVALID);
    oe.gap_to = 0.4;
    assert_int_equal(ag_plan_add_offset(p, &o, NULL), AG_OK);
    ag_plan_free(p);

    /* JSON: "inside" needs a gap and knows only its own members */
    const char *bad[] = {
        "{\"profiles\": {\"w\": [[0, 0], [0, 1]]}, \"loops\": [[[0, 0], [4, 0], [4, 4], [0, 4]]],"
        " \"offsets\": [{\"height\": 1, \"inside\": {\"profile\": \"w\"}}]}",
        "{\"profiles\": {\"w\": [[0, 0], [0, 1]]}, \"loops\": [[[0, 0], [4, 0], [4, 4], [0, 4]]],"
        " \"offsets\": [{\"height\": 1, \"inside\": {\"gap\": [0.1, 0.2], \"profile\": \"w\","
        " \"wdith\": 1}}]}",
        "{\"profiles\": {\"w\": [[0, 0], [0, 1]]}, \"loops\": [[[0, 0], [4, 0], [4, 4], [0, 4]]],"
        " \"offsets\": [{\"height\": 1, \"inside\": {\"gap\": [0.2, 0.1], \"profile\": \"w\"}}]}",
        "{\"profiles\": {\"w\": [[0, 0], [0, 1]]}, \"loops\": [[[0, 0], [4, 0], [4, 4], [0, 4]]],"
        " \"offsets\": [{\"height\": 1, \"inside\": {\"gap\": [0.1, 0.2]}}]}",
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_plan *q = NULL;
        ag_error err = {0};
        assert_int_not_equal(ag_plan_json_read_buffer(bad[i], strlen(bad[i]), &q, &err), AG_OK);
        assert_null(q);
        assert_non_null(strstr(err.text, "offset"));
    }
    const char *good = "{\"profiles\": {\"w\": [[0, 0], [0, 1]], \"r\": [[0, 0], [1, 1]]},"
                       " \"loops\": [[[0, 0], [4, 0], [4, 4], [0, 4]]],"
                       " \"offsets\": [{\"height\": 1, \"inside\": {\"gap\": [0.1, 0.2],"
                       " \"profile\": \"w\", \"inner\": \"r\"}, \"edges\": [{\"edge\": 2,"
                       " \"inside\": {\"gap\": [0.1, 0.5], \"profile\": \"r\"}}]}]}";
    ag_plan *q = NULL;
    assert_int_equal(ag_plan_json_read_buffer(good, strlen(good), &q, NULL), AG_OK);
    assert_int_equal(q->noffsets, 1);
    const ag_plan_offset *g = &q->offsets[0];
    assert_true(g->has_gap && g->gap_from == 0.1 && g->gap_to == 0.2 && g->outside == 0);
    assert_int_equal(g->inside, 0);
    assert_int_equal(g->inner, 1);
    assert_int_equal(g->nedges, 1);
    assert_true(g->edges[0].has_gap && g->edges[0].gap_to == 0.5);
    assert_int_equal(g->edges[0].inside, 2); /* 1 + "r" */
    assert_int_equal(g->edges[0].inner, 0);
    assert_int_equal(g->edges[0].profile, -1);
    ag_plan_free(q);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rectangle_closed_form),
        cmocka_unit_test(test_convex_brute_force),
        cmocka_unit_test(test_nonconvex_planes),
        cmocka_unit_test(test_profiles),
        cmocka_unit_test(test_priority),
        cmocka_unit_test(test_segment_priority),
        cmocka_unit_test(test_fixtures),
        cmocka_unit_test(test_check_reports_open_faces),
        cmocka_unit_test(test_check_edge_touching_solids),
        cmocka_unit_test(test_anchors),
        cmocka_unit_test(test_natural_steps),
        cmocka_unit_test(test_forced_steps),
        cmocka_unit_test(test_offset_events),
        cmocka_unit_test(test_offset_inside),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
