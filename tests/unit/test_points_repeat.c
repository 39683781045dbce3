/* Repetition decomposition (§3.2) and consensus models (§4.1) on generated buildings whose
 * windows are known (the `window` property of gen_building): a template around one window
 * finds the other windows of its facade (turned, jittered, at UTM coordinates, recessed or
 * proud), the automatic mode gives the windows of one size one label, and a consensus model
 * completes windows cut by a simulated occlusion, measured by counting the points that come
 * back in the occluded part. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/points/consensus.h"
#include "core/points/gen_building.h"
#include "core/points/repeat.h"
#include "core/points/segment_cloud.h"

static ag_cloud *building(const ag_gen_building_options *o)
{
    ag_cloud *c;
    ag_error e;
    if (ag_gen_building(o, &c, &e) != AG_OK)
        fail_msg("gen_building: %s", e.text);
    return c;
}

static const int32_t *ints(const ag_cloud *c, const char *name)
{
    const ag_cloud_property *p = ag_cloud_find(c, name);
    assert_non_null(p);
    assert_int_equal(p->type, AG_SCALAR_INT32);
    return p->values;
}

/* The bounds of window w's points, grown by pad. */
static ag_box window_box(const ag_cloud *c, int32_t w, double pad)
{
    const int32_t *win = ints(c, "window");
    ag_box b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t i = 0; i < c->n; i++)
        if (win[i] == w)
            for (int a = 0; a < 3; a++) {
                b.min[a] = fmin(b.min[a], c->xyz[3 * i + a] - pad);
                b.max[a] = fmax(b.max[a], c->xyz[3 * i + a] + pad);
            }
    return b;
}

/* The truth window most of the points in box b belong to (-1: none) and the share. */
static int32_t window_in(const ag_cloud *c, const ag_box *b, int32_t nwin, double *share)
{
    const int32_t *win = ints(c, "window");
    size_t *count = calloc((size_t)nwin + 1, sizeof *count), total = 0;
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        if (p[0] < b->min[0] || p[0] > b->max[0] || p[1] < b->min[1] || p[1] > b->max[1] ||
            p[2] < b->min[2] || p[2] > b->max[2] || win[i] < 0)
            continue;
        count[win[i]]++;
        total++;
    }
    int32_t best = -1;
    for (int32_t w = 0; w < nwin; w++)
        if (count[w] && (best < 0 || count[w] > count[best]))
            best = w;
    *share = best >= 0 ? (double)count[best] / (double)total : 0;
    free(count);
    return best;
}

static ag_segment_cloud_result *segment(ag_cloud *c)
{
    ag_segment_cloud_result *r;
    ag_error e;
    if (ag_segment_cloud_run(c, NULL, &r, &e) != AG_OK)
        fail_msg("segment: %s", e.text);
    return r;
}

typedef struct {
    const char *name;
    ag_gen_building_options o;
} variant;

static void test_template_finds_the_facade_windows(void **state)
{
    (void)state;
    const variant vs[] = {
        {"recessed", {.points = 120000, .cols = 5, .rows = 3, .seed = 1}},
        {"proud, turned 30 degrees", {.points = 120000, .cols = 5, .rows = 3, .window = AG_GEN_WINDOW_PROUD, .rotation = 30, .seed = 2}},
        {"jittered 0.2 m", {.points = 120000, .cols = 4, .rows = 3, .jitter = 0.2, .seed = 3}},
        {"UTM, turned 117 degrees", {.points = 120000, .cols = 6, .rows = 2, .rotation = 117, .origin = {431207.5, 5411732.25, 312}, .seed = 4}},
        {"raw UTM coordinates", {.points = 120000, .cols = 5, .rows = 2, .origin = {85123.75, 446321.5, 2}, .absolute = 1, .seed = 5}},
    };
    for (size_t v = 0; v < sizeof vs / sizeof *vs; v++) {
        const ag_gen_building_options *o = &vs[v].o;
        ag_cloud *c = building(o);
        ag_segment_cloud_result *r = segment(c);
        int32_t front = (int32_t)(o->cols * o->rows);
        int32_t nwin = 2 * front + 2 * 2 * (int32_t)o->rows;
        /* the template: a window in the middle of the front, a little wall around it */
        int32_t tw = front / 2;
        ag_box t = window_box(c, tw, 0.1);
        ag_repeat_report rep = {0};
        ag_error e;
        ag_status s = ag_repeat_template(c, r, &t, NULL, &rep, &e);
        if (s != AG_OK)
            fail_msg("%s: %s", vs[v].name, e.text);
        print_message("%s: %zu matches of %d front windows (%zu positions compared)\n",
                      vs[v].name, rep.nmatches, front, rep.positions);
        /* every front window once, nothing else */
        unsigned char *seen = calloc((size_t)nwin, 1);
        for (size_t m = 0; m < rep.nmatches; m++) {
            double share;
            int32_t w = window_in(c, &rep.matches[m].box, nwin, &share);
            if (w < 0 || w >= front || seen[w] || share < 0.9)
                fail_msg("%s: match %zu is window %d (share %.2f): not a new front window",
                         vs[v].name, m, w, share);
            seen[w] = 1;
        }
        assert_int_equal(rep.nmatches, (size_t)front);
        /* the windows' points carry the template's label, and only theirs among windows */
        const int32_t *win = ints(c, "window");
        size_t labelled = 0, front_pts = 0, stray = 0;
        for (size_t i = 0; i < c->n; i++) {
            if (win[i] >= 0 && win[i] < front) {
                front_pts++;
                labelled += r->label[i] == rep.label;
            } else if (win[i] >= front) {
                stray += r->label[i] == rep.label;
            }
        }
        print_message("  %zu of %zu front window points labelled, %zu other window points\n",
                      labelled, front_pts, stray);
        assert_true(labelled >= front_pts * 9 / 10);
        assert_true(stray == 0);
        free(seen);
        ag_repeat_report_clear(&rep);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

static void test_template_refusals(void **state)
{
    (void)state;
    ag_gen_building_options o = {.points = 60000, .cols = 3, .rows = 2, .seed = 7};
    ag_cloud *c = building(&o);
    ag_segment_cloud_result *r = segment(c);
    ag_error e;
    /* a box in the air holds no points */
    ag_box air = {{-50, -50, 100}, {-49, -49, 101}};
    assert_int_equal(ag_repeat_template(c, r, &air, NULL, NULL, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "point"));
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
    /* a flush window cannot be told from its wall */
    o.window = AG_GEN_WINDOW_FLUSH;
    c = building(&o);
    r = segment(c);
    ag_box t = window_box(c, 0, 0.0);
    ag_status s = ag_repeat_template(c, r, &t, NULL, NULL, &e);
    assert_int_equal(s, AG_ERR_INVALID);
    print_message("flush template: %s\n", e.text);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

/* Automatic mode on clouds with nothing that repeats (a lone plane; planes in one piece each,
 * whatever their normals say): no element, no failure (an empty unit list reached qsort as a
 * null array before, which UBSan reports). */
static void test_auto_nothing_to_repeat(void **state)
{
    (void)state;
    for (int kind = 0; kind < 2; kind++) {
        ag_cloud *c = ag_cloud_create();
        ag_error e;
        size_t n = 0, side = 60;
        assert_int_equal(ag_cloud_resize(c, kind ? 2 * side * side : side * side, &e), AG_OK);
        for (size_t i = 0; i < side; i++)
            for (size_t j = 0; j < side; j++, n++) {
                double *p = c->xyz + 3 * n;
                p[0] = 0.1 * (double)i, p[1] = 0.1 * (double)j, p[2] = 0;
                if (kind) { /* and a wall beside it */
                    p = c->xyz + 3 * (n + side * side);
                    p[0] = 0.1 * (double)i, p[1] = 8, p[2] = 0.1 + 0.1 * (double)j;
                }
            }
        ag_segment_cloud_result *r = segment(c);
        ag_repeat_report rep = {0};
        if (ag_repeat_auto(c, r, NULL, &rep, &e) != AG_OK)
            fail_msg("kind %d: %s", kind, e.text);
        for (size_t s = 0; s < r->nsegments; s++)
            assert_int_not_equal(r->segments[s].kind, AG_SEGMENT_CLOUD_ELEMENT);
        ag_repeat_report_clear(&rep);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

/* Automatic mode: the windows become elements, those of one size share a label. */
static void test_auto_elements(void **state)
{
    (void)state;
    const variant vs[] = {
        {"recessed", {.points = 150000, .cols = 5, .rows = 3, .seed = 11}},
        {"proud, turned 45 degrees, UTM", {.points = 150000, .cols = 4, .rows = 2, .window = AG_GEN_WINDOW_PROUD, .rotation = 45, .origin = {500000, 5800000, 40}, .seed = 12}},
    };
    for (size_t v = 0; v < sizeof vs / sizeof *vs; v++) {
        const ag_gen_building_options *o = &vs[v].o;
        ag_cloud *c = building(o);
        ag_segment_cloud_result *r = segment(c);
        int32_t front = (int32_t)(o->cols * o->rows);
        int32_t nwin = 2 * front + 4 * (int32_t)o->rows;
        ag_repeat_report rep = {0};
        ag_error e;
        if (ag_repeat_auto(c, r, NULL, &rep, &e) != AG_OK)
            fail_msg("%s: %s", vs[v].name, e.text);
        /* per element: the truth window it holds */
        const int32_t *win = ints(c, "window");
        int32_t *elem_win = malloc(r->nsegments * sizeof *elem_win);
        size_t elements = 0, one_window = 0;
        for (size_t s = 0; s < r->nsegments; s++) {
            elem_win[s] = -2;
            if (r->segments[s].kind != AG_SEGMENT_CLOUD_ELEMENT)
                continue;
            elements++;
            double share;
            int32_t w = window_in(c, &r->segments[s].box, nwin, &share);
            if (w >= 0 && share > 0.9) {
                elem_win[s] = w;
                one_window++;
            }
        }
        /* windows that are (mostly) one element's */
        size_t found = 0;
        int32_t front_label = -1;
        size_t front_same = 0;
        for (int32_t w = 0; w < nwin; w++) {
            size_t tot = 0, best = 0;
            int32_t bs = -1;
            size_t *cnt = calloc(r->nsegments, sizeof *cnt);
            for (size_t i = 0; i < c->n; i++)
                if (win[i] == w) {
                    tot++;
                    if (r->segment[i] >= 0 && elem_win[r->segment[i]] == w &&
                        ++cnt[r->segment[i]] > best) {
                        best = cnt[r->segment[i]];
                        bs = r->segment[i];
                    }
                }
            free(cnt);
            if (bs >= 0 && best * 2 >= tot) {
                found++;
                if (w < front) {
                    if (front_label < 0)
                        front_label = r->segments[bs].label;
                    front_same += r->segments[bs].label == front_label;
                }
            }
        }
        print_message("%s: %zu elements (%zu hold one window), %zu of %d windows found, %zu of "
                      "%d front windows share a label\n",
                      vs[v].name, elements, one_window, found, nwin, front_same, front);
        assert_true(found >= (size_t)nwin * 9 / 10);
        assert_true(front_same >= (size_t)front * 9 / 10);
        free(elem_win);
        ag_repeat_report_clear(&rep);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
    }
}

/* Consensus: windows with part of them occluded (their points removed) come back complete.
 * Measured independently: the consensus, put back at an occluded window by the registration's
 * inverse offset, has points in the occluded part at the density of the complete windows. */
static void test_consensus_completes_occluded_windows(void **state)
{
    (void)state;
    for (int turned = 0; turned < 2; turned++) {
        ag_gen_building_options o = {.points = 200000, .cols = 6, .rows = 3, .seed = 21,
                                     .rotation = turned ? 60 : 0,
                                     .origin = {turned ? 431000.0 : 0, turned ? 5400000.0 : 0, 0}};
        ag_cloud *full = building(&o);
        int32_t front = (int32_t)(o.cols * o.rows);
        const int32_t *win = ints(full, "window");
        /* occlude the left 40 % (along the facade) of every other front window: in the
         * building's own frame x runs along the front */
        double th = o.rotation * M_PI / 180, ct = cos(th), st = sin(th);
        ag_box *wb = malloc((size_t)front * sizeof *wb);
        double *x0 = malloc((size_t)front * sizeof *x0), *x1 = malloc((size_t)front * sizeof *x1);
        for (int32_t w = 0; w < front; w++) {
            x0[w] = INFINITY;
            x1[w] = -INFINITY;
            wb[w] = window_box(full, w, 0.0);
        }
        double cx = 0, cy = 0;
        for (size_t i = 0; i < full->n; i++) {
            cx += full->xyz[3 * i] / (double)full->n;
            cy += full->xyz[3 * i + 1] / (double)full->n;
        }
        /* u: the coordinate along the front (turn back by the rotation about the centre) */
#define ALONG(i) (ct * (full->xyz[3 * (i)] - cx) + st * (full->xyz[3 * (i) + 1] - cy))
        for (size_t i = 0; i < full->n; i++)
            if (win[i] >= 0 && win[i] < front) {
                x0[win[i]] = fmin(x0[win[i]], ALONG(i));
                x1[win[i]] = fmax(x1[win[i]], ALONG(i));
            }
        uint32_t *keep = malloc(full->n * sizeof *keep);
        size_t nk = 0, removed = 0;
        for (size_t i = 0; i < full->n; i++) {
            int32_t w = win[i];
            int occluded = w >= 0 && w < front && w % 2 == 1 &&
                           ALONG(i) < x0[w] + 0.4 * (x1[w] - x0[w]);
            if (occluded)
                removed++;
            else
                keep[nk++] = (uint32_t)i;
        }
        ag_cloud *c;
        assert_int_equal(ag_cloud_subset(full, keep, nk, &c, NULL), AG_OK);
        free(keep);
        ag_segment_cloud_result *r = segment(c);
        /* the members: the truth windows of the front, each its own points (the test gives
         * consensus the repetition it is about, so that the measure is consensus's alone) */
        const int32_t *cw = ints(c, "window");
        uint32_t *start = calloc((size_t)front + 1, sizeof *start);
        for (size_t i = 0; i < c->n; i++)
            if (cw[i] >= 0 && cw[i] < front)
                start[cw[i] + 1]++;
        for (int32_t w = 0; w < front; w++)
            start[w + 1] += start[w];
        uint32_t *idx = malloc(start[front] * sizeof *idx), *fill = malloc((size_t)front * sizeof *fill);
        memcpy(fill, start, (size_t)front * sizeof *fill);
        for (size_t i = 0; i < c->n; i++)
            if (cw[i] >= 0 && cw[i] < front)
                idx[fill[cw[i]]++] = (uint32_t)i;
        ag_box *boxes = malloc((size_t)front * sizeof *boxes);
        for (int32_t w = 0; w < front; w++)
            boxes[w] = window_box(c, w, 0.0);
        ag_consensus_options co = {.spacing = r->spacing};
        ag_consensus_model m;
        ag_error e;
        if (ag_consensus_build(c, idx, start, boxes, (size_t)front, NULL, &co, &m, &e) != AG_OK)
            fail_msg("consensus: %s", e.text);
        print_message("%s: %zu of %d members merged, base %zu: %zu points before, %zu after "
                      "(pooled %zu, thinning radius %.3f m)\n",
                      turned ? "turned, UTM" : "axis-aligned", m.merged, front, m.base,
                      m.points_before, m.points_after, m.pooled, m.cell);
        assert_true(m.merged >= (size_t)front * 8 / 10);
        /* the base is a complete window: consensus keeps its density (within 10 %) */
        size_t complete = 0, ncomplete = 0;
        for (int32_t w = 0; w < front; w += 2) {
            complete += start[w + 1] - start[w];
            ncomplete++;
        }
        double mean_complete = (double)complete / (double)ncomplete;
        assert_true(fabs((double)m.points_after - mean_complete) <= 0.1 * mean_complete);
        /* every occluded window, completed: the consensus mapped onto it (the inverse of its
         * registration to the base) has points in its occluded part, as many as a complete
         * window has there (the removed points counted in the full cloud) */
        for (int32_t w = 1; w < front; w += 2) {
            const ag_consensus_member *mem = &m.members[w];
            if (!mem->merged)
                continue;
            size_t there = 0, truth = 0;
            /* the occluded part of w, in the full cloud's points of w */
            for (size_t i = 0; i < full->n; i++)
                truth += win[i] == w && ALONG(i) < x0[w] + 0.4 * (x1[w] - x0[w]);
            /* consensus points (base frame) come to window w by the inverse of its
             * registration: the opposite turn about the moved pivot, less t */
            ag_register_result inv = mem->reg;
            inv.turn = (4 - mem->reg.turn) % 4;
            for (int a = 0; a < 3; a++) {
                inv.pivot[a] = mem->reg.pivot[a] + mem->reg.t[a];
                inv.t[a] = -mem->reg.t[a];
            }
            for (size_t i = 0; i < m.points->n; i++) {
                double q[3];
                ag_register_apply(&inv, m.points->xyz + 3 * i, q);
                double u = ct * (q[0] - cx) + st * (q[1] - cy);
                int in = q[2] >= wb[w].min[2] - 0.05 && q[2] <= wb[w].max[2] + 0.05 &&
                         u >= x0[w] - 0.02 && u < x0[w] + 0.4 * (x1[w] - x0[w]);
                there += in;
            }
            print_message("  window %d: %zu points of its occluded part removed, %zu back "
                          "(registration off by %.3f %.3f %.3f m)\n", w, truth, there,
                          mem->reg.t[0] - (wb[0].min[0] - wb[w].min[0]),
                          mem->reg.t[1] - (wb[0].min[1] - wb[w].min[1]),
                          mem->reg.t[2] - (wb[0].min[2] - wb[w].min[2]));
            assert_true(truth > 0);
            for (int a = 0; a < 3; a++) /* against the truth boxes' offset */
                assert_true(fabs(mem->reg.t[a] - (wb[0].min[a] - wb[w].min[a])) < 0.03);
            assert_true(there >= truth * 8 / 10 && there <= truth * 12 / 10);
        }
#undef ALONG
        ag_consensus_model_clear(&m);
        free(boxes);
        free(idx);
        free(fill);
        free(start);
        free(wb);
        free(x0);
        free(x1);
        ag_segment_cloud_free(r);
        ag_cloud_free(c);
        ag_cloud_free(full);
        (void)removed;
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_template_finds_the_facade_windows),
        cmocka_unit_test(test_template_refusals),
        cmocka_unit_test(test_auto_nothing_to_repeat),
        cmocka_unit_test(test_auto_elements),
        cmocka_unit_test(test_consensus_completes_occluded_windows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
