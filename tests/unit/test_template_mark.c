/* Template marking by the label rule (core/points/template_mark.h) on generated buildings
 * whose windows are known: the wall around one front window is marked (a box built from the
 * window's own points), and the copies found must sit on the other front windows — checked
 * against the generator's window ids, in the wall's plane, each window at most once — with
 * one new label shared by the template and its copies alone. Variants: turned, at UTM
 * coordinates (raw and as an offset), jittered windows, proud windows, noise. And the
 * refusals: no such segment, a box with too few of its points. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/points/gen_building.h"
#include "core/points/template_mark.h"
#include "segment_fixture.h"

#define FRONT_WINDOWS 18 /* 6 x 3 on the front wall: window ids 0..17 */

/* The centre of window w (the mean of its points) and the wall's frame in world axes. */
static void window_centre(const ag_cloud *c, const int32_t *window, int32_t w, double centre[3])
{
    double s[3] = {0, 0, 0};
    size_t n = 0;
    for (size_t i = 0; i < c->n; i++)
        if (window[i] == w) {
            for (int k = 0; k < 3; k++)
                s[k] += c->xyz[3 * i + k];
            n++;
        }
    assert_true(n > 0);
    for (int k = 0; k < 3; k++)
        centre[k] = s[k] / (double)n;
}

static void copies_sit_on_the_other_windows(void **state)
{
    (void)state;
    const struct {
        double rotation, jitter, noise;
        ag_gen_window_kind kind;
        int utm, absolute;
        size_t min_found;
    } v[] = {
        {0, 0, 0.005, AG_GEN_WINDOW_RECESSED, 0, 0, 16},
        {33, 0, 0.005, AG_GEN_WINDOW_RECESSED, 1, 0, 16},
        {120, 0, 0.005, AG_GEN_WINDOW_PROUD, 1, 1, 16},
        {15, 0.08, 0.005, AG_GEN_WINDOW_RECESSED, 0, 0, 14},
        {250, 0, 0.015, AG_GEN_WINDOW_RECESSED, 1, 0, 14},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        ag_gen_building_options go = {.points = 150000, .rotation = v[k].rotation,
                                      .jitter = v[k].jitter, .noise = v[k].noise,
                                      .window = v[k].kind, .absolute = v[k].absolute,
                                      .seed = 40 + k};
        if (v[k].utm) {
            go.origin[0] = 486512.25;
            go.origin[1] = 5719877.75;
            go.origin[2] = 47.5;
        }
        ag_cloud *c;
        ag_error e;
        assert_int_equal(ag_gen_building(&go, &c, &e), AG_OK);
        size_t n = c->n;
        int32_t *truth = malloc(n * sizeof *truth), *window = malloc(n * sizeof *window);
        memcpy(truth, ag_cloud_find(c, "plane")->values, n * sizeof *truth);
        memcpy(window, ag_cloud_find(c, "window")->values, n * sizeof *window);
        ag_segment_cloud_result *r;
        assert_int_equal(ag_segment_cloud_run(c, NULL, &r, &e), AG_OK);
        int32_t wall = sf_majority(c, truth, r, 0);
        assert_true(wall >= 0);
        size_t wall_points = r->member_start[wall + 1] - r->member_start[wall];
        size_t before = r->nsegments;
        /* the wall's frame: along it, up, out of it */
        double a = v[k].rotation * M_PI / 180;
        double u[3] = {cos(a), sin(a), 0}, up[3] = {0, 0, 1}, out[3] = {sin(a), -cos(a), 0};
        double centres[FRONT_WINDOWS][3];
        for (int w = 0; w < FRONT_WINDOWS; w++)
            window_centre(c, window, w, centres[w]);
        /* the box: 2.4 x 2.7 m around window 7, 0.5 m either side of the wall */
        const int marked = 7;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int corner = 0; corner < 8; corner++) {
            double su = corner & 1 ? 1.2 : -1.2, sz = corner & 2 ? 1.35 : -1.35,
                   sn = corner & 4 ? 0.5 : -0.5;
            for (int d = 0; d < 3; d++) {
                double p = centres[marked][d] + su * u[d] + sz * up[d] + sn * out[d];
                lo[d] = fmin(lo[d], p);
                hi[d] = fmax(hi[d], p);
            }
        }
        ag_template_mark_report rep;
        if (ag_template_mark(c, &r, wall, lo, hi, &rep, &e) != AG_OK)
            fail_msg("variant %zu: %s", k, e.text);
        /* every copy on a front window other than the marked one, each window once */
        int hit[FRONT_WINDOWS] = {0};
        size_t found = 0;
        for (size_t i = 0; i < rep.copies; i++) {
            double mid[3], best = INFINITY, bu = 0, bz = 0;
            int bw = -1;
            for (int d = 0; d < 3; d++)
                mid[d] = 0.5 * (rep.copy[i].min[d] + rep.copy[i].max[d]);
            for (int w = 0; w < FRONT_WINDOWS; w++) {
                double du = 0, dz = 0;
                for (int d = 0; d < 3; d++) {
                    du += (mid[d] - centres[w][d]) * u[d];
                    dz += (mid[d] - centres[w][d]) * up[d];
                }
                double dist = hypot(du, dz);
                if (dist < best) {
                    best = dist;
                    bw = w;
                    bu = du;
                    bz = dz;
                }
            }
            /* within 0.4 m of its window (their pitch: 4 x 3 m), framing the whole opening
             * (1.2 x 1.5 m): the template does, with 0.6 m to spare each way */
            if (best > 0.4 || bw == marked || hit[bw])
                fail_msg("variant %zu: copy %zu lies %.2f m (%.2f along, %.2f up) from window %d "
                         "(marked %d, seen %d)",
                         k, i, best, bu, bz, bw, marked, bw >= 0 ? hit[bw] : 0);
            for (int corner = 0; corner < 4; corner++)
                for (int d = 0; d < 3; d++) {
                    double p = centres[bw][d] + (corner & 1 ? 0.6 : -0.6) * u[d] +
                               (corner & 2 ? 0.75 : -0.75) * up[d];
                    if (p < rep.copy[i].min[d] - 0.3 || p > rep.copy[i].max[d] + 0.3)
                        fail_msg("variant %zu: copy %zu does not frame the opening of window %d",
                                 k, i, bw);
                }
            hit[bw] = 1;
            found++;
        }
        print_message("variant %zu: %zu of %d windows found from %zu positions, template of %zu "
                      "points\n",
                      k, found, FRONT_WINDOWS - 1, rep.positions, rep.template_points);
        assert_true(found >= v[k].min_found);
        /* the template and its copies: one label of their own */
        assert_int_equal(r->nsegments, before + rep.copies + 1);
        size_t with_label = 0, grouped = 0, rest = 0;
        for (size_t s = 0; s < r->nsegments; s++)
            if (r->segments[s].label == rep.label) {
                with_label++;
                grouped += r->member_start[s + 1] - r->member_start[s];
            }
        assert_int_equal(with_label, rep.copies + 1);
        assert_int_equal(r->segments[rep.template_segment].label, rep.label);
        for (size_t i = 0; i < n; i++)
            assert_int_equal(r->label[i],
                             r->segment[i] >= 0 ? r->segments[r->segment[i]].label : -1);
        /* the wall's points are all still there: the rest of the wall plus the group */
        int32_t left = sf_majority(c, truth, r, 0);
        assert_true(left >= 0 && r->segments[left].label != rep.label);
        rest = r->member_start[left + 1] - r->member_start[left];
        assert_int_equal(rest + grouped, wall_points);
        ag_template_mark_report_clear(&rep);
        ag_segment_cloud_free(r);
        free(truth);
        free(window);
        ag_cloud_free(c);
    }
}

static void bad_marks_are_refused(void **state)
{
    (void)state;
    ag_gen_building_options go = {.points = 40000, .seed = 3};
    ag_cloud *c;
    assert_int_equal(ag_gen_building(&go, &c, NULL), AG_OK);
    ag_segment_cloud_result *r;
    assert_int_equal(ag_segment_cloud_run(c, NULL, &r, NULL), AG_OK);
    size_t nseg = r->nsegments;
    ag_template_mark_report rep;
    ag_error e;
    double lo[3] = {-100, -100, -100}, hi[3] = {100, 100, 100};
    assert_int_equal(ag_template_mark(c, &r, (int32_t)nseg, lo, hi, &rep, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "segments 0 to"));
    assert_int_equal(ag_template_mark(c, &r, -1, lo, hi, &rep, &e), AG_ERR_INVALID);
    double far_lo[3] = {500, 500, 500}, far_hi[3] = {501, 501, 501};
    assert_int_equal(ag_template_mark(c, &r, 0, far_lo, far_hi, &rep, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "holds 0 points"));
    assert_int_equal(r->nsegments, nseg); /* nothing changed */
    /* a box around the whole segment: the template is all of it, no room to slide; it gets
     * the next id and segment 0, left without points, is gone (its id is not reused) */
    size_t in_use = ag_segment_cloud_in_use(r);
    assert_int_equal(ag_template_mark(c, &r, 0, lo, hi, &rep, &e), AG_OK);
    assert_int_equal(rep.copies, 0);
    assert_int_equal(rep.template_segment, (int32_t)nseg);
    assert_int_equal(r->nsegments, nseg + 1);
    assert_int_equal(ag_segment_cloud_in_use(r), in_use);
    assert_int_equal(r->segments[0].count, 0);
    assert_int_equal(r->segments[0].label, -1);
    ag_template_mark_report_clear(&rep);
    /* an id without points is refused, saying so */
    assert_int_equal(ag_template_mark(c, &r, 0, lo, hi, &rep, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "has no points"));

    ag_template_mark_report_clear(&rep);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(copies_sit_on_the_other_windows),
        cmocka_unit_test(bad_marks_are_refused),
    };
    return cmocka_run_group_tests_name("template_mark", tests, NULL, NULL);
}
