#include "proceduralize_cloud.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/clock.h"
#include "../base/kdtree.h"
#include "../proc/label.h"

static const char *const stage_names[AG_PCLOUD_STAGES] = {"segment", "repeat", "absorb",
                                                           "consensus", "tree", "grammar"};

const char *ag_proceduralize_cloud_stage_name(ag_pcloud_stage s)
{
    return (unsigned)s < AG_PCLOUD_STAGES ? stage_names[s] : "?";
}

void ag_proceduralize_cloud_free(ag_proceduralize_cloud_result *r)
{
    if (!r)
        return;
    ag_pointmodel_free(r->model);
    ag_segment_cloud_free(r->seg);
    for (size_t k = 0; k < r->ntemplates; k++)
        ag_repeat_report_clear(&r->templates[k]);
    free(r->templates);
    free(r->completion);
    free(r);
}

typedef struct {
    const ag_proceduralize_cloud_options *o;
    ag_pcloud_stage stage;
} pctx;

static int seg_progress(void *user, ag_segment_cloud_stage s, double f)
{
    const pctx *p = user;
    return p->o->progress(p->o->user, AG_PCLOUD_SEGMENT,
                          ((double)s + f) / (double)AG_SEGMENT_CLOUD_STAGES);
}

static int repeat_progress(void *user, double f)
{
    const pctx *p = user;
    return p->o->progress(p->o->user, AG_PCLOUD_REPEAT, f);
}

/* Segments that repetition carved down below min_points dissolve; then unsegmented points
 * join the segment of their nearest segmented point within tol. */
static ag_status absorb(const ag_cloud *c, ag_segment_cloud_result *r, double tol,
                        size_t min_points, size_t *absorbed, size_t *outliers, ag_error *err)
{
    *absorbed = *outliers = 0;
    int dissolved = 0;
    for (size_t i = 0; i < c->n; i++) {
        int32_t s = r->segment[i];
        if (s >= 0 && r->segments[s].kind != AG_SEGMENT_CLOUD_ELEMENT &&
            r->segments[s].count < min_points) {
            r->segment[i] = -1;
            dissolved = 1;
        }
    }
    size_t nseg = 0, nfree = 0;
    for (size_t i = 0; i < c->n; i++) {
        nseg += r->segment[i] >= 0;
        nfree += r->segment[i] < 0;
    }
    if (!nfree)
        return AG_OK;
    if (!nseg) {
        *outliers = nfree;
        return dissolved ? ag_error_set(err, AG_ERR_EMPTY, 0, "no segment is large enough")
                         : AG_OK;
    }
    uint32_t *seg = malloc(nseg * sizeof *seg);
    int32_t *to = malloc(c->n * sizeof *to);
    ag_segment_cloud_spec *spec = malloc((r->nsegments + 1) * sizeof *spec);
    if (!seg || !to || !spec) {
        free(seg);
        free(to);
        free(spec);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t k = 0;
    for (size_t i = 0; i < c->n; i++)
        if (r->segment[i] >= 0)
            seg[k++] = (uint32_t)i;
    ag_kdtree *t;
    ag_status st = ag_kdtree_build(c->xyz, seg, nseg, &t, err);
    if (st == AG_OK) {
        for (size_t i = 0; i < c->n; i++) {
            to[i] = r->segment[i];
            if (r->segment[i] >= 0)
                continue;
            uint32_t q;
            double d2;
            if (ag_kdtree_knn(t, c->xyz + 3 * i, 1, &q, &d2) && d2 <= tol * tol) {
                to[i] = r->segment[q];
                (*absorbed)++;
            } else {
                (*outliers)++;
            }
        }
        ag_kdtree_free(t);
        memcpy(r->segment, to, c->n * sizeof *to);
        for (size_t s = 0; s < r->nsegments; s++) {
            const ag_segment_cloud_item *it = &r->segments[s];
            int el = it->kind == AG_SEGMENT_CLOUD_ELEMENT;
            spec[s] = (ag_segment_cloud_spec){it->kind, el ? it->host : -1, el ? it->label : -1,
                                              el ? it->box : ag_box_empty()};
        }
        if (*absorbed || dissolved)
            st = ag_segment_cloud_rebuild(c, r, spec, r->nsegments, err);
    }
    free(seg);
    free(to);
    free(spec);
    return st;
}

/* A terminal of the points idx[0..m) of c (their node box), placed where they are. */
static ag_status singleton(ag_pointmodel *pm, const ag_cloud *c, const uint32_t *idx, size_t m,
                           const ag_box *box, double thick, ag_error *err)
{
    ag_cloud *pts;
    ag_status st = ag_cloud_subset(c, idx, m, &pts, err);
    if (st != AG_OK)
        return st;
    double origin[3];
    size_t t;
    st = ag_pointmodel_add_terminal(pm, &pts, box, thick, pm->spacing, origin, &t, err);
    ag_cloud_free(pts);
    if (st != AG_OK)
        return st;
    const double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    return ag_pointmodel_add_placement(pm, (int32_t)t, I, origin, err);
}

/* The placement map of a merged member: its points x satisfy y = R_k (x - pivot) + pivot + t in
 * the base's frame and y = p + origin in the terminal's, so x = R_-k p + R_-k (origin - pivot -
 * t) + pivot. */
static void member_map(const ag_register_result *reg, const double origin[3], double A[3][3],
                       double b[3])
{
    int k = (4 - reg->turn) & 3;
    memset(A, 0, 9 * sizeof A[0][0]);
    for (int j = 0; j < 2; j++) {
        double x = j == 0, y = j == 1;
        ag_label_rotate(k, &x, &y);
        A[0][j] = x;
        A[1][j] = y;
    }
    A[2][2] = 1;
    double v[3] = {origin[0] - reg->pivot[0] - reg->t[0], origin[1] - reg->pivot[1] - reg->t[1],
                   origin[2] - reg->pivot[2] - reg->t[2]};
    ag_label_rotate(k, &v[0], &v[1]);
    for (int a = 0; a < 3; a++)
        b[a] = v[a] + reg->pivot[a];
}

static int cancelled(const ag_proceduralize_cloud_options *o, ag_pcloud_stage s, double f)
{
    return o->progress && o->progress(o->user, s, f);
}

ag_status ag_proceduralize_cloud_run(ag_cloud *c, const ag_proceduralize_cloud_options *opt,
                                     ag_proceduralize_cloud_result **out, ag_error *err)
{
    *out = NULL;
    ag_proceduralize_cloud_options o = opt ? *opt : (ag_proceduralize_cloud_options){0};
    if (!c->n)
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the cloud has no points");
    ag_status st = ag_cloud_check_finite(c, err);
    if (st != AG_OK)
        return st;
    ag_proceduralize_cloud_result *r = calloc(1, sizeof *r);
    if (!r)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    pctx pc = {&o, AG_PCLOUD_SEGMENT};
    double t0 = ag_clock_seconds(), c0 = ag_clock_thread_cpu_seconds();
#define STAGE_END(s)                                                                        \
    do {                                                                                    \
        double t1 = ag_clock_seconds(), c1 = ag_clock_thread_cpu_seconds();                 \
        r->seconds[s] += t1 - t0;                                                           \
        r->cpu_seconds[s] += c1 - c0;                                                       \
        t0 = t1;                                                                            \
        c0 = c1;                                                                            \
    } while (0)
#define CHECK_CANCEL(s)                                                                     \
    do {                                                                                    \
        if (cancelled(&o, s, 0)) {                                                          \
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled before %s",              \
                              ag_proceduralize_cloud_stage_name(s));                        \
            goto fail;                                                                      \
        }                                                                                   \
    } while (0)

    /* §3.1 */
    CHECK_CANCEL(AG_PCLOUD_SEGMENT);
    ag_segment_cloud_options so = o.segment;
    if (o.progress) {
        so.progress = seg_progress;
        so.user = &pc;
    }
    if ((st = ag_segment_cloud_run(c, &so, &r->seg, err)) != AG_OK)
        goto fail;
    for (size_t k = 0; k < o.nrois; k++)
        if ((st = ag_segment_cloud_refine(c, r->seg, o.rois[k].min, o.rois[k].max, &so, err)))
            goto fail;
    STAGE_END(AG_PCLOUD_SEGMENT);
    ag_segment_cloud_result *sg = r->seg;
    if (!sg->nsegments) {
        st = ag_error_set(err, AG_ERR_EMPTY, 0,
                          "no plane or cluster in %zu point%s: nothing to proceduralize", c->n,
                          c->n == 1 ? "" : "s");
        goto fail;
    }

    /* §3.2: the person's templates, then the automatic elements */
    CHECK_CANCEL(AG_PCLOUD_REPEAT);
    ag_repeat_options ro = o.repeat;
    if (o.progress) {
        pc.stage = AG_PCLOUD_REPEAT;
        ro.progress = repeat_progress;
        ro.user = &pc;
    }
    if (o.ntemplates && !(r->templates = calloc(o.ntemplates, sizeof *r->templates))) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto fail;
    }
    for (size_t k = 0; k < o.ntemplates; k++) {
        if ((st = ag_repeat_template(c, sg, &o.templates[k], &ro, &r->templates[k], err))) {
            if (o.ntemplates > 1) {
                char text[sizeof err->text];
                memcpy(text, err->text, sizeof text);
                ag_error_set(err, st, err->element, "template %zu: %s", k + 1, text);
            }
            goto fail;
        }
        r->ntemplates = k + 1;
    }
    if (!o.no_auto) {
        ag_repeat_report ar;
        if ((st = ag_repeat_auto(c, sg, &ro, &ar, err)))
            goto fail;
        r->auto_elements = ar.elements;
    }
    STAGE_END(AG_PCLOUD_REPEAT);

    CHECK_CANCEL(AG_PCLOUD_ABSORB);
    if ((st = absorb(c, sg, sg->cluster_tolerance > 0 ? sg->cluster_tolerance : 2 * sg->spacing,
                     c->n / 10000 > 10 ? c->n / 10000 : 10, &r->absorbed, &r->outliers, err)))
        goto fail;
    STAGE_END(AG_PCLOUD_ABSORB);

    /* §4.1: consensus of every label of repeated elements or clusters; the rest as they are */
    CHECK_CANCEL(AG_PCLOUD_CONSENSUS);
    ag_pointmodel *pm = r->model = ag_pointmodel_create();
    if (!pm) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto fail;
    }
    memcpy(pm->offset, c->offset, sizeof pm->offset);
    memcpy(pm->scale, c->scale, sizeof pm->scale);
    pm->spacing = sg->spacing > 0 ? sg->spacing : (sg->diagonal > 0 ? 1e-3 * sg->diagonal : 0.01);
    pm->tolerance = pm->spacing;
    double thick = pm->spacing;
    ag_consensus_options co = o.consensus;
    if (!(co.spacing > 0))
        co.spacing = pm->spacing;
    {
        /* segments by label */
        size_t nl = sg->nlabels;
        uint32_t *lstart = calloc(nl + 2, sizeof *lstart);
        uint32_t *lseg = malloc((sg->nsegments + 1) * sizeof *lseg);
        uint8_t *merge = calloc(nl + 1, 1);
        if (!lstart || !lseg || !merge) {
            free(lstart);
            free(lseg);
            free(merge);
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto fail;
        }
        for (size_t s = 0; s < sg->nsegments; s++)
            if (sg->segments[s].label >= 0) /* not an id an ROI left unused */
                lstart[sg->segments[s].label + 1]++;
        for (size_t l = 0; l < nl; l++)
            lstart[l + 1] += lstart[l];
        {
            uint32_t *fill = malloc((nl + 1) * sizeof *fill);
            if (!fill) {
                free(lstart);
                free(lseg);
                free(merge);
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                goto fail;
            }
            memcpy(fill, lstart, (nl + 1) * sizeof *fill);
            for (size_t s = 0; s < sg->nsegments; s++)
                if (sg->segments[s].label >= 0)
                    lseg[fill[sg->segments[s].label]++] = (uint32_t)s;
            free(fill);
        }
        /* labels merged: two or more elements (repetitions); never planes (two walls of one
         * label have their openings in different places) nor the clusters left over (bits of
         * different things that the label rule happens to pair) */
        for (size_t l = 0; l < nl; l++) {
            size_t k = lstart[l + 1] - lstart[l];
            merge[l] = k >= 2 && sg->segments[lseg[lstart[l]]].kind == AG_SEGMENT_CLOUD_ELEMENT;
        }
        uint32_t *start = NULL, *idx = NULL;
        ag_box *boxes = NULL;
        size_t capk = 0, capi = 0, capb = 0, capc = 0;
        /* where each segment's placement went: a host's box grows to hold its elements' (a
         * consensus placement sits where registration put it, not quite on the node box) */
        ag_box *placed = malloc((sg->nsegments + 1) * sizeof *placed);
        if (!placed) {
            free(lstart);
            free(lseg);
            free(merge);
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto fail;
        }
        for (size_t q = 0; q < sg->nsegments; q++)
            placed[q] = ag_box_empty();
        /* first the consensus labels, then every other segment as it is */
        for (size_t pass = 0; pass < 2 && st == AG_OK; pass++)
        for (size_t l = 0; l < nl && st == AG_OK; l++) {
            size_t k = lstart[l + 1] - lstart[l];
            if ((pass == 0) != (merge[l] != 0))
                continue;
            if (!merge[l]) {
                for (size_t j = 0; j < k && st == AG_OK; j++) {
                    uint32_t s = lseg[lstart[l] + j];
                    ag_box box = sg->segments[s].box;
                    for (size_t e = 0; e < sg->nsegments; e++)
                        if (sg->segments[e].host == (int32_t)s && !ag_box_is_empty(&placed[e]))
                            ag_box_extend_box(&box, &placed[e]);
                    st = singleton(pm, c, sg->members + sg->member_start[s],
                                   sg->member_start[s + 1] - sg->member_start[s], &box, thick,
                                   err);
                    if (st == AG_OK)
                        placed[s] = pm->placements[pm->nplacements - 1].box;
                }
                continue;
            }
            if (cancelled(&o, AG_PCLOUD_CONSENSUS, (double)l / (double)nl)) {
                st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled");
                break;
            }
            /* the members: each segment's points and node box */
            size_t total = 0;
            for (size_t j = 0; j < k; j++) {
                uint32_t s = lseg[lstart[l] + j];
                total += sg->member_start[s + 1] - sg->member_start[s];
            }
            if (AG_ARRAY_RESERVE(start, capk, k + 1) || AG_ARRAY_RESERVE(idx, capi, total + 1) ||
                AG_ARRAY_RESERVE(boxes, capb, k + 1)) {
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                break;
            }
            size_t at = 0;
            for (size_t j = 0; j < k; j++) {
                uint32_t s = lseg[lstart[l] + j];
                start[j] = (uint32_t)at;
                size_t m = sg->member_start[s + 1] - sg->member_start[s];
                memcpy(idx + at, sg->members + sg->member_start[s], m * sizeof *idx);
                at += m;
                boxes[j] = sg->segments[s].box;
            }
            start[k] = (uint32_t)at;
            ag_consensus_model cm;
            if ((st = ag_consensus_build(c, idx, start, boxes, k, NULL, &co, &cm, err)))
                break;
            /* the terminal: the consensus within the base's node box */
            ag_box tb = boxes[cm.base];
            ag_box_extend_box(&tb, &cm.box);
            double origin[3];
            size_t t;
            ag_cloud *pts = cm.points;
            cm.points = NULL;
            st = ag_pointmodel_add_terminal(pm, &pts, &tb, thick, pm->spacing, origin, &t, err);
            ag_cloud_free(pts);
            if (st == AG_OK) {
                ag_pointmodel_terminal *T = &pm->terminals[t];
                T->members = k;
                T->merged = cm.merged;
                T->points_before = cm.points_before;
                T->mean_before = cm.mean_before;
                if (AG_ARRAY_RESERVE(r->completion, capc, r->ncompletion + 1))
                    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            }
            if (st == AG_OK) {
                r->completion[r->ncompletion++] =
                    (ag_pcloud_completion){(int32_t)l, (int32_t)t, k, cm.merged, cm.points_before,
                                           cm.mean_before, cm.points_after, cm.cell};
            }
            for (size_t j = 0; j < k && st == AG_OK; j++) {
                uint32_t s = lseg[lstart[l] + j];
                if (!cm.members[j].merged) {
                    /* not like the others after all: as it is */
                    st = singleton(pm, c, sg->members + sg->member_start[s],
                                   sg->member_start[s + 1] - sg->member_start[s],
                                   &sg->segments[s].box, thick, err);
                } else {
                    double A[3][3], b[3];
                    member_map(&cm.members[j].reg, origin, A, b);
                    st = ag_pointmodel_add_placement(pm, (int32_t)t, A, b, err);
                }
                if (st == AG_OK)
                    placed[s] = pm->placements[pm->nplacements - 1].box;
            }
            ag_consensus_model_clear(&cm);
        }
        free(start);
        free(idx);
        free(boxes);
        free(placed);
        free(lstart);
        free(lseg);
        free(merge);
        if (st != AG_OK)
            goto fail;
    }
    STAGE_END(AG_PCLOUD_CONSENSUS);

    /* §4.2-4.3 and the grammar: core/proc on the placements */
    CHECK_CANCEL(AG_PCLOUD_TREE);
    if ((st = ag_pointmodel_build(pm, err)) != AG_OK)
        goto fail;
    r->seconds[AG_PCLOUD_TREE] += pm->build_seconds[0];
    r->seconds[AG_PCLOUD_GRAMMAR] += pm->build_seconds[1];
    r->cpu_seconds[AG_PCLOUD_TREE] += pm->build_cpu_seconds[0];
    r->cpu_seconds[AG_PCLOUD_GRAMMAR] += pm->build_cpu_seconds[1];
#undef STAGE_END
#undef CHECK_CANCEL
    *out = r;
    return AG_OK;
fail:
    ag_proceduralize_cloud_free(r);
    return st;
}
