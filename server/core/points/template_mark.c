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
    /* the new segmentation: the template and its copies become segments of the segment's
     * kind (planes keep the first ids), empty segments are dropped */
    ag_segment_cloud_result *out = NULL;
    int32_t *seg = NULL, *piece = NULL, *map = NULL, *pmap = NULL;
    size_t *count = NULL;
    size_t k = ntaken, old = r->nsegments, total = old + k, n = c->n;
    int plane = (size_t)segment < r->nplanes;
    size_t base = plane ? r->nplanes : old; /* where the new ids go */
    if (st == AG_OK) {
        seg = malloc((n ? n : 1) * sizeof *seg);
        piece = malloc((n ? n : 1) * sizeof *piece);
        map = malloc((total + 1) * sizeof *map);
        count = calloc(total + 1, sizeof *count);
        pmap = malloc((r->npieces + k + 1) * sizeof *pmap);
        if (!seg || !piece || !map || !count || !pmap)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (st == AG_OK) {
        for (size_t i = 0; i < n; i++) {
            int32_t s = r->segment[i];
            seg[i] = s < 0 ? -1 : (size_t)s >= base ? s + (int32_t)k : s;
            piece[i] = r->piece[i];
        }
        for (size_t j = 0; j < m; j++)
            if (group[j] >= 0) {
                seg[mem[j]] = (int32_t)(base + (size_t)group[j]);
                piece[mem[j]] = (int32_t)(r->npieces + (size_t)group[j]);
            }
        for (size_t i = 0; i < n; i++)
            if (seg[i] >= 0)
                count[seg[i]]++;
        int32_t next = 0;
        size_t nplanes = 0, planes_end = r->nplanes + (plane ? k : 0);
        for (size_t s = 0; s < total; s++) {
            map[s] = count[s] ? next++ : -1;
            if (s < planes_end && count[s])
                nplanes++;
        }
        int32_t pn = 0;
        for (size_t p = 0; p < r->npieces + k; p++)
            pmap[p] = -1;
        for (size_t i = 0; i < n; i++) {
            if (seg[i] < 0)
                continue;
            seg[i] = map[seg[i]];
            if (pmap[piece[i]] < 0)
                pmap[piece[i]] = pn++;
            piece[i] = pmap[piece[i]];
        }
        ag_segment_cloud_ids ids = {.segment = seg,
                                    .piece = piece,
                                    .nsegments = (size_t)next,
                                    .nplanes = nplanes,
                                    .npieces = (size_t)pn,
                                    .spacing = r->spacing};
        st = ag_segment_cloud_restore(c, &ids, &out, err);
    }
    if (st == AG_OK) {
        /* one new label for the template and its copies, then labels renumbered densely */
        int32_t fresh = (int32_t)out->nlabels;
        for (size_t t = 0; t < k; t++) {
            int32_t s = map[base + t];
            if (s >= 0)
                out->segments[s].label = fresh;
        }
        int32_t *dense = malloc((out->nlabels + 2) * sizeof *dense);
        if (!dense) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        } else {
            for (size_t l = 0; l <= out->nlabels; l++)
                dense[l] = -1;
            int32_t nl = 0;
            for (size_t s = 0; s < out->nsegments; s++) {
                int32_t l = out->segments[s].label;
                if (dense[l] < 0)
                    dense[l] = nl++;
                out->segments[s].label = dense[l];
            }
            out->nlabels = (size_t)nl;
            for (size_t i = 0; i < n; i++)
                out->label[i] = out->segment[i] >= 0 ? out->segments[out->segment[i]].label : -1;
            rep->label = dense[fresh];
            rep->template_segment = map[base];
            free(dense);
        }
    }
    if (st == AG_OK && k > 1 && !(rep->copy = calloc(k - 1, sizeof *rep->copy)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t copies = 0;
    for (size_t t = 1; st == AG_OK && t < k; t++) {
        int32_t s = map[base + t];
        if (s < 0) /* every point of it went to a copy before */
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
    free(u);
    free(group);
    free(matches);
    free(seg);
    free(piece);
    free(map);
    free(count);
    free(pmap);
    return st;
}
