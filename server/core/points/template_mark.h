/* Template marking (§3.2 of "Procedural editing of building point clouds") by the label
 * rule: a person marks a template — the points of one segment inside a box — and the
 * copies of it along the segment are found and given one label with it.
 *
 * The copies are found by archgram's one template matcher (core/points/repeat.h,
 * ag_repeat_in_segment): the box slid along the segment's frame in steps of a tenth of its
 * size, the segment's points in the moved box compared with the template's by how well they
 * explain each other, each match placed where they agree best and not overlapping another.
 * A match is a copy when it also passes the label rule of the segmentation: its point count
 * within 10 % of the template's and its extents in the segment's frame, sorted, within 5 %
 * (plus two point spacings of slack) — at the match's place or moved by up to half a step
 * along the segment's plane, where it passes closest. The template and every copy become segments of their
 * own (of the segment's kind), all with one new label; what is left of the segment stays a
 * segment. Deterministic. Core: no I/O. */
#ifndef AG_POINTS_TEMPLATE_MARK_H
#define AG_POINTS_TEMPLATE_MARK_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "cloud.h"
#include "segment_cloud.h"

#define AG_TEMPLATE_MIN_POINTS 10 /* a template with fewer points is refused */

typedef struct {
    double min[3], max[3]; /* the copy's points' bounds, local coordinates */
    size_t count;
} ag_template_copy;

typedef struct {
    size_t template_points;
    size_t positions;       /* window positions tried */
    size_t copies;          /* copies found (the template not counted) */
    ag_template_copy *copy; /* copies entries, malloc'd: ag_template_mark_report_clear */
    int32_t label;          /* the label of the template and its copies */
    int32_t template_segment; /* the template's segment id in the result */
} ag_template_mark_report;

void ag_template_mark_report_clear(ag_template_mark_report *rep);

/* Marks the points of segment `segment` inside the box [min, max] (local coordinates) as a
 * template and labels its copies; r is replaced by the new segmentation (left as it was on
 * an error). Every segment keeps its id and its label, the marked one what is left of it
 * (its label too while it passes the label rule with another segment of that label, or has
 * it alone; else a new one); the template and its copies get the ids from r->nsegments on
 * and one new label (r->nlabels). AG_ERR_INVALID when there is no such segment, it has no
 * points or the box holds fewer than AG_TEMPLATE_MIN_POINTS of its points (the message says
 * how many it holds). */

ag_status ag_template_mark(const ag_cloud *c, ag_segment_cloud_result **r, int32_t segment,
                           const double min[3], const double max[3],
                           ag_template_mark_report *rep, ag_error *err);

#endif
