/* A segmentation read back from its per-point ids (ag_segment_cloud_restore), as the service
 * keeps them: the same segments, kinds, members and labels as the run that made them, a ROI
 * refinement of the read-back one equal to that of the original, labels given kept (and
 * renumbered in segment order), and ids that do not fit refused naming the point. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "core/points/gen_building.h"
#include "core/points/segment_cloud.h"

static ag_segment_cloud_ids ids_of(const ag_segment_cloud_result *r, int with_labels)
{
    return (ag_segment_cloud_ids){.segment = r->segment,
                                  .label = with_labels ? r->label : NULL,
                                  .piece = r->piece,
                                  .nsegments = r->nsegments,
                                  .nplanes = r->nplanes,
                                  .npieces = r->npieces,
                                  .spacing = r->spacing};
}

static void assert_same(const ag_segment_cloud_result *a, const ag_segment_cloud_result *b)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->nsegments, b->nsegments);
    assert_int_equal(a->nplanes, b->nplanes);
    assert_int_equal(a->nclusters, b->nclusters);
    assert_int_equal(a->nlabels, b->nlabels);
    assert_memory_equal(a->segment, b->segment, a->n * sizeof *a->segment);
    assert_memory_equal(a->label, b->label, a->n * sizeof *a->label);
    assert_memory_equal(a->piece, b->piece, a->n * sizeof *a->piece);
    assert_memory_equal(a->member_start, b->member_start, (a->nsegments + 1) * sizeof(uint32_t));
    for (size_t s = 0; s < a->nsegments; s++) {
        assert_int_equal(a->segments[s].kind, b->segments[s].kind);
        assert_int_equal(a->segments[s].count, b->segments[s].count);
        assert_int_equal(a->segments[s].label, b->segments[s].label);
    }
}

static void read_back_segmentations_are_the_run(void **state)
{
    (void)state;
    for (int turn = 0; turn < 2; turn++) {
        ag_gen_building_options go = {.points = 60000, .rotation = turn ? 37 : 0, .seed = 8,
                                      .origin = {turn ? 486512.25 : 0, turn ? 5719877.75 : 0, 0}};
        ag_cloud *c;
        assert_int_equal(ag_gen_building(&go, &c, NULL), AG_OK);
        ag_segment_cloud_result *r, *back, *labelled;
        ag_error e;
        assert_int_equal(ag_segment_cloud_run(c, NULL, &r, &e), AG_OK);
        ag_segment_cloud_ids ids = ids_of(r, 0);
        assert_int_equal(ag_segment_cloud_restore(c, &ids, &back, &e), AG_OK);
        assert_same(r, back);
        ids = ids_of(r, 1);
        assert_int_equal(ag_segment_cloud_restore(c, &ids, &labelled, &e), AG_OK);
        assert_same(r, labelled);
        /* a refinement of the read-back segmentation is that of the original */
        double lo[3] = {c->xyz[0] - 3, c->xyz[1] - 3, c->xyz[2] - 3};
        double hi[3] = {c->xyz[0] + 3, c->xyz[1] + 3, c->xyz[2] + 3};
        assert_int_equal(ag_segment_cloud_refine(c, r, lo, hi, NULL, &e), AG_OK);
        assert_int_equal(ag_segment_cloud_refine(c, back, lo, hi, NULL, &e), AG_OK);
        assert_same(r, back);
        ag_segment_cloud_free(r);
        ag_segment_cloud_free(back);
        ag_segment_cloud_free(labelled);
        ag_cloud_free(c);
    }
}

static void given_labels_are_kept(void **state)
{
    (void)state;
    ag_gen_building_options go = {.points = 30000, .seed = 2};
    ag_cloud *c;
    assert_int_equal(ag_gen_building(&go, &c, NULL), AG_OK);
    ag_segment_cloud_result *r, *back;
    assert_int_equal(ag_segment_cloud_run(c, NULL, &r, NULL), AG_OK);
    assert_true(r->nsegments >= 3);
    /* every segment a label of its own but segments 1 and 2, which share one */
    int32_t *label = malloc(c->n * sizeof *label);
    for (size_t i = 0; i < c->n; i++) {
        int32_t s = r->segment[i];
        label[i] = s < 0 ? -1 : s == 2 ? 1000 + 1 : 1000 + s;
    }
    ag_segment_cloud_ids ids = ids_of(r, 0);
    ids.label = label;
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &back, NULL), AG_OK);
    /* kept as they are (label ids are stable too), not renumbered */
    assert_int_equal(back->nlabels, 1000 + r->nsegments);
    for (size_t s = 0; s < back->nsegments; s++)
        assert_int_equal(back->segments[s].label, s == 2 ? 1001 : 1000 + (int32_t)s);
    for (size_t i = 0; i < c->n; i++)
        assert_int_equal(back->label[i], r->segment[i] < 0 ? -1 : back->segments[r->segment[i]].label);
    ag_segment_cloud_free(back);
    /* a segment whose points disagree on their label */
    size_t first = r->members[r->member_start[0]], second = r->members[r->member_start[0] + 1];
    label[second] = 5;
    ag_error e;
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &back, &e), AG_ERR_INVALID);
    assert_int_equal(e.element, (long)(first > second ? first : second) + 1);
    free(label);
    ag_segment_cloud_free(r);
    ag_cloud_free(c);
}

static void ids_that_do_not_fit_are_refused(void **state)
{
    (void)state;
    ag_cloud *c = ag_cloud_create();
    assert_int_equal(ag_cloud_resize(c, 4, NULL), AG_OK);
    for (size_t i = 0; i < 12; i++)
        c->xyz[i] = (double)i;
    int32_t seg[4] = {0, 1, -1, 0}, piece[4] = {0, 1, -1, 0};
    ag_segment_cloud_ids ids = {seg, NULL, piece, 2, 1, 2, 0.1, NULL, 0};

    ag_segment_cloud_result *r;
    ag_error e;
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &r, &e), AG_OK);
    assert_int_equal(r->nplanes, 1);
    assert_int_equal(r->nclusters, 1);
    ag_segment_cloud_free(r);
    seg[3] = 2; /* past nsegments */
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &r, &e), AG_ERR_INVALID);
    assert_int_equal(e.element, 4);
    seg[3] = 0;
    piece[2] = 1; /* a piece for a point without a segment */
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &r, &e), AG_ERR_INVALID);
    assert_int_equal(e.element, 3);
    piece[2] = -1;
    ids.nplanes = 3;
    assert_int_equal(ag_segment_cloud_restore(c, &ids, &r, &e), AG_ERR_INVALID);
    ag_cloud_free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(read_back_segmentations_are_the_run),
        cmocka_unit_test(given_labels_are_kept),
        cmocka_unit_test(ids_that_do_not_fit_are_refused),
    };
    return cmocka_run_group_tests_name("segment_restore", tests, NULL, NULL);
}
