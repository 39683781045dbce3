/* Repetition decomposition (§3.2): a segment (a facade) decomposed further into the
 * repeating elements it holds (its windows), which become segments of their own (elements,
 * ag_segment_cloud.h) sitting in that host segment.
 *
 * An element is a box in its host: its points are the points in the box that are not the
 * host's (the glass and reveals of a window, the wall around them staying the wall's), and
 * the host's node box grows to hold it, so that the split tree nests it under its wall.
 *
 * Template matching (a person marks a template): the template is a box around one element;
 * its host is the largest plane crossing it that is larger than the box. This is archgram's
 * one template matcher: template marking (core/points/template_mark.h) runs it inside one
 * segment (ag_repeat_in_segment). The template is
 * slid along the host frame's three axes, one at a time, in steps of 10 % of the template's
 * size on that axis (the template-to-segment size ratio's 10 % of the segment), over the
 * host's extent; from every match on again (so a grid of windows is reached row by row). At
 * each step the points in the moved box (less the host's) are compared with the template's:
 * when at least `min_explained` of them lie within the tolerance of a template point and they
 * cover at least `min_covered` of the template (an occluded copy covers less, and is still a
 * match: the paper lets a person label under-sampled instances), the position is refined by
 * climbing that score (compared on cells of the tolerance's size, steps halving) and checked
 * with exact distances; a refined match that does not overlap an earlier one is one. All matches and the template get one label, whatever their point counts.
 *
 * Automatic (no person): the elements are the pieces of a plane segment made of several
 * pieces (the panes of a row of recessed windows are one plane, in pieces) and the clusters,
 * each small next to a parallel host plane behind or in front of it (within 1.5 m): the box
 * reaches from the piece to the host plane (taking the reveals in between) and a little
 * around. Labels follow the rule (box dimensions within 5 %, point counts within 10 %).
 *
 * Both run on a segmentation and rebuild it (ag_segment_cloud_rebuild). */
#ifndef AG_REPEAT_H
#define AG_REPEAT_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"
#include "cloud.h"
#include "segment_cloud.h"

typedef struct {
    double tolerance;     /* metres within which points explain each other; 0 = 2 spacings */
    double min_explained; /* 0 = 0.85 */
    double min_covered;   /* 0 = 0.3 */
    size_t max_matches;   /* per template; 0 = 10000 */
    /* Called now and then with a rough fraction done; non-zero cancels. */
    int (*progress)(void *user, double fraction);
    void *user;
} ag_repeat_options;

typedef struct {
    ag_box box;           /* cloud-local */
    double offset[3];     /* from the template's box */
    double explained, covered;
    size_t points;
} ag_repeat_match;

typedef struct {
    int32_t host;         /* the host segment (ids after the rebuild) */
    int32_t label;        /* the matches' label */
    size_t nmatches;      /* the template included (match 0) */
    ag_repeat_match *matches;
    size_t positions;     /* positions compared */
    size_t elements;      /* automatic: elements made */
} ag_repeat_report;

void ag_repeat_report_clear(ag_repeat_report *rep);

/* Matches the template box (cloud-local coordinates) in r's segmentation of c and makes the
 * matches elements of one label. AG_ERR_INVALID (with a message naming what is missing) for
 * a box without points, without a host, or whose points are all the host's (a window flush
 * with its wall cannot be told from the wall). rep may be NULL. */
ag_status ag_repeat_template(const ag_cloud *c, ag_segment_cloud_result *r, const ag_box *tmpl,
                             const ag_repeat_options *o, ag_repeat_report *rep, ag_error *err);

/* The same matcher with the template inside one segment (template marking,
 * core/points/template_mark.h): the template is the points of `segment` in the box, slid along
 * that segment's frame, and compared with the segment's points in the moved box; nothing is
 * changed. *matches (malloc'd, the caller frees it) gets the matches, the template first;
 * *positions the positions compared. AG_ERR_INVALID for no such segment or a box with fewer
 * than 8 of its points. */
ag_status ag_repeat_in_segment(const ag_cloud *c, const ag_segment_cloud_result *r,
                               const ag_box *tmpl, int32_t segment, const ag_repeat_options *o,
                               ag_repeat_match **matches, size_t *nmatches, size_t *positions,
                               ag_error *err);

/* The automatic decomposition; rep (optional) gets the number of elements. */
ag_status ag_repeat_auto(const ag_cloud *c, ag_segment_cloud_result *r,
                         const ag_repeat_options *o, ag_repeat_report *rep, ag_error *err);

#endif
