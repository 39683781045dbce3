#include "template_mark.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "repeat.h"

#define COUNT_SHARE 0.1   /* the label rule: point counts within 10 % */
#define EXTENT_SHARE 0.05 /* and extents within 5 % */
#define STEP_SHARE 0.1    /* the slide step: a tenth of the template on each axis */
#define REFINE 2          /* a copy is placed to a quarter step: 2 sub-steps either side */

void ag_template_mark_report_clear(ag_template_mark_report *rep)
{
    if (rep) {
        free(rep->copy);
        memset(rep, 0, sizeof *rep);
    }
}

static int cmp_desc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
}

static int inside(const double *p, const double lo[3], const double hi[3])
{
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] &&
           p[2] <= hi[2];
}

/* The segment's points (frame coordinates u) in box b: their count and extents, sorted. */
static size_t box_figures(const ag_cloud *c, const uint32_t *mem, size_t m, const double *u,
                          const ag_box *b, double dims[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t n = 0;
    for (size_t j = 0; j < m; j++) {
        if (!inside(c->xyz + 3 * (size_t)mem[j], b->min, b->max))
            continue;
        n++;
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], u[3 * j + k]);
            hi[k] = fmax(hi[k], u[3 * j + k]);
        }
    }
    for (int k = 0; k < 3; k++)
        dims[k] = n ? hi[k] - lo[k] : 0;
    qsort(dims, 3, sizeof dims[0], cmp_desc);
    return n;
}

/* The label rule of the segmentation: point counts within 10 %, sorted extents within 5 %
 * (plus the slack of two point spacings). */
static int same_label(size_t n, const double dims[3], size_t tn, const double tdims[3],
                      double slack)
{
    double big = (double)(n > tn ? n : tn);
    if (!n || fabs((double)n - (double)tn) > COUNT_SHARE * big)
        return 0;
    for (int k = 0; k < 3; k++)
        if (fabs(dims[k] - tdims[k]) > EXTENT_SHARE * fmax(dims[k], tdims[k]) + slack)
            return 0;
    return 1;
}

/* Where a match is a copy by the label rule: the match's box, or moved within half a step
 * along the segment's plane (the shape matcher places a box where the points agree, the label
 * rule counts what it holds: a shifted box holds a little more or less wall), the place that
 * passes closest to the template's count and extents. 0 when none passes. */
static int place_copy(const ag_cloud *c, const uint32_t *mem, size_t m, const double *u,
                      const double axes[3][3], const double step[3], const ag_box *match,
                      size_t tc, const double tdims[3], double slack, ag_box *out)
{
    double best = INFINITY;
    *out = *match;
    for (int i = -REFINE; i <= REFINE; i++)
        for (int j = -REFINE; j <= REFINE; j++) {
            ag_box b = *match;
            for (int a = 0; a < 3; a++) {
                double d = (step[0] * i * axes[0][a] + step[1] * j * axes[1][a]) / (2.0 * REFINE);
                b.min[a] += d;
                b.max[a] += d;
            }
            double dims[3];
            size_t n = box_figures(c, mem, m, u, &b, dims);
            if (!same_label(n, dims, tc, tdims, slack))
                continue;
            double big = (double)(n > tc ? n : tc);
            double score = fabs((double)n - (double)tc) / big + (abs(i) + abs(j)) * 1e-3;
            for (int k = 0; k < 3; k++)
                score += fabs(dims[k] - tdims[k]) / fmax(fmax(dims[k], tdims[k]), 1e-9);
            if (score < best) {
                best = score;
                *out = b;
            }
        }
    return best < INFINITY;
}

/* Labels after a mark (out, rebuilt from r with the template and its copies at ids old on):
 * every segment r had keeps its label; the marked one too while it still passes the label
 * rule with a segment of its label (or has it alone), else it gets one of its own; the
 * template and its copies one new label, which is returned. Label ids are never reused. */
static int32_t keep_labels(const ag_segment_cloud_result *r, ag_segment_cloud_result *out,
                           int32_t marked, size_t old)
{
    int32_t fresh = (int32_t)r->nlabels, next = fresh + 1;
    for (size_t s = 0; s < out->nsegments; s++) {
        ag_segment_cloud_item *it = &out->segments[s];
        if (!it->count)
            it->label = -1;
        else if (s >= old)
            it->label = fresh;
        else
            it->label = r->segments[s].label;
    }
    ag_segment_cloud_item *h = &out->segments[marked];
    if (h->count) {
        int alone = 1, similar = 0;
        for (size_t s = 0; s < old && !similar; s++) {
            const ag_segment_cloud_item *o = &out->segments[s];
            if ((int32_t)s == marked || !o->count || o->label != h->label)
                continue;
            alone = 0;
            similar = ag_segment_cloud_similar(h, o, 2 * out->spacing);
        }
        if (!alone && !similar)
            h->label = next++;
    }
    out->nlabels = (size_t)next;
    for (size_t i = 0; i < out->n; i++)
        out->label[i] = out->segment[i] >= 0 ? out->segments[out->segment[i]].label : -1;
    return fresh;
}

ag_status ag_template_mark(const ag_cloud *c, ag_segment_cloud_result **rp, int32_t segment,
                           const double min[3], const double max[3],
                           ag_template_mark_report *rep, ag_error *err)
{
    memset(rep, 0, sizeof *rep);
    ag_segment_cloud_result *r = *rp;
    if (segment < 0 || (size_t)segment >= r->nsegments)
    {
        if (!r->nsegments)
            return ag_error_set(err, AG_ERR_INVALID, 0, "segment %d: the cloud has no segments",
                                segment);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "segment %d: the segmentation has segments 0 to %zu", segment,
                            r->nsegments - 1);
    }
    const ag_segment_cloud_item *it = &r->segments[segment];
    if (!it->count)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "segment %d has no points: an edit before left its id unused",
                            segment);
    const uint32_t *mem = r->members + r->member_start[segment];
    size_t m = r->member_start[segment + 1] - r->member_start[segment];
    double slack = 2 * r->spacing;
    double *u = malloc((m ? m : 1) * 3 * sizeof *u);
    int32_t *group = malloc((m ? m : 1) * sizeof *group);
    ag_repeat_match *matches = NULL;
    size_t nmatches = 0;
    ag_status st = u && group ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t tc = 0;
    for (size_t j = 0; st == AG_OK && j < m; j++) {
        const double *p = c->xyz + 3 * (size_t)mem[j];
        double d[3] = {p[0] - it->centroid[0], p[1] - it->centroid[1], p[2] - it->centroid[2]};
        int in = inside(p, min, max);
        tc += in;
        group[j] = in ? 0 : -1;
        for (int k = 0; k < 3; k++)
            u[3 * j + k] = d[0] * it->axes[k][0] + d[1] * it->axes[k][1] + d[2] * it->axes[k][2];
    }
    if (st == AG_OK && tc < AG_TEMPLATE_MIN_POINTS)
        st = ag_error_set(err, AG_ERR_INVALID, (long)tc,
                          "the box holds %zu points of segment %d; a template needs at least %d",
                          tc, segment, AG_TEMPLATE_MIN_POINTS);
    /* the copies: the template matcher of repetition (core/points/repeat.h) run inside the
     * segment, its matches kept where they pass the label rule */
    ag_box box = {{min[0], min[1], min[2]}, {max[0], max[1], max[2]}};
    if (st == AG_OK)
        st = ag_repeat_in_segment(c, r, &box, segment, NULL, &matches, &nmatches,
                                  &rep->positions, err);
    rep->template_points = tc;
    double tdims[3], step[3];
    box_figures(c, mem, m, u, &box, tdims);
    for (int a = 0; a < 3; a++) { /* a tenth of the template along each of the frame's axes */
        double lo = INFINITY, hi = -INFINITY;
        for (size_t j = 0; j < m; j++)
            if (group[j] == 0) {
                lo = fmin(lo, u[3 * j + a]);
                hi = fmax(hi, u[3 * j + a]);
            }
        step[a] = tc ? STEP_SHARE * (hi - lo) : 0;
    }
    size_t ntaken = st == AG_OK ? 1 : 0; /* the template itself is group 0 */
    for (size_t i = 1; st == AG_OK && i < nmatches; i++) {
        ag_box placed;
        if (!place_copy(c, mem, m, u, it->axes, step, &matches[i].box, tc, tdims, slack, &placed))
            continue;
        int32_t gid = (int32_t)ntaken++;
        for (size_t j = 0; j < m; j++)
            if (group[j] < 0 && inside(c->xyz + 3 * (size_t)mem[j], placed.min, placed.max))
                group[j] = gid;
    }
    /* the new segmentation, made on a copy so that r stays as it was on an error: the
     * template and its copies become segments of the segment's kind with ids after every id
     * there was; every other segment keeps its id, the marked one what is left of it */
    ag_segment_cloud_result *out = NULL;
    ag_segment_cloud_spec *spec = NULL;
    size_t k = ntaken, old = r->nsegments;
    if (st == AG_OK)
        st = ag_segment_cloud_clone(r, &out, err);
    if (st == AG_OK && !(spec = malloc((old + k + 1) * sizeof *spec)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK) {
        for (size_t s = 0; s < old; s++)
            spec[s] = ag_segment_cloud_spec_of(&r->segments[s]);
        int el = it->kind == AG_SEGMENT_CLOUD_ELEMENT;
        for (size_t t = 0; t < k; t++)
            spec[old + t] = (ag_segment_cloud_spec){it->kind, el ? it->host : -1, -1,
                                                    ag_box_empty()};
        for (size_t j = 0; j < m; j++)
            if (group[j] >= 0) {
                out->segment[mem[j]] = (int32_t)(old + (size_t)group[j]);
                out->piece[mem[j]] = (int32_t)(r->npieces + (size_t)group[j]);
            }
        out->npieces = r->npieces + k;
        st = ag_segment_cloud_rebuild(c, out, spec, old + k, err);
    }
    if (st == AG_OK) {
        rep->label = keep_labels(r, out, segment, old);
        rep->template_segment = (int32_t)old;
    }
    if (st == AG_OK && k > 1 && !(rep->copy = calloc(k - 1, sizeof *rep->copy)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t copies = 0;
    for (size_t t = 1; st == AG_OK && t < k; t++) {
        size_t s = old + t;
        if (!out->segments[s].count) /* every point of it went to a copy before */
            continue;
        ag_template_copy *cp = &rep->copy[copies++];
        for (int a = 0; a < 3; a++) {
            cp->min[a] = INFINITY;
            cp->max[a] = -INFINITY;
        }
        for (uint32_t q = out->member_start[s]; q < out->member_start[s + 1]; q++) {
            const double *p = c->xyz + 3 * (size_t)out->members[q];
            for (int a = 0; a < 3; a++) {
                cp->min[a] = fmin(cp->min[a], p[a]);
                cp->max[a] = fmax(cp->max[a], p[a]);
            }
        }
        cp->count = out->member_start[s + 1] - out->member_start[s];
    }
    if (st == AG_OK) {
        rep->copies = copies;
        ag_segment_cloud_free(r);
        *rp = out;
        out = NULL;
    } else {
        ag_template_mark_report_clear(rep);
    }
    ag_segment_cloud_free(out);
    free(spec);
    free(u);
    free(group);
    free(matches);
    return st;
}
