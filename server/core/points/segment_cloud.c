#include "segment_cloud.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/clock.h"
#include "../base/kdtree.h"
#include "../base/tolerance.h"
#include "cluster.h"
#include "coincident.h"
#include "group.h"
#include "normals.h"

#define DEFAULT_SEED 0x61726368677261ull /* "archgra" */
/* pieces at least this share of their plane's largest piece stay in its segment */
#define MAIN_PIECE_SHARE 0.2

static const char *const stage_names[AG_SEGMENT_CLOUD_STAGES] = {
    "index", "normals", "coarse", "refine", "components", "cluster", "label"};

const char *ag_segment_cloud_stage_name(ag_segment_cloud_stage s)
{
    return (unsigned)s < AG_SEGMENT_CLOUD_STAGES ? stage_names[s] : "?";
}

void ag_segment_cloud_free(ag_segment_cloud_result *r)
{
    if (!r)
        return;
    free(r->segment);
    free(r->label);
    free(r->piece);
    free(r->segments);
    free(r->member_start);
    free(r->members);
    free(r);
}

typedef struct {
    const ag_segment_cloud_options *o;
    ag_segment_cloud_stage stage;
} progress_ctx;

static int stage_progress(void *user, double fraction)
{
    progress_ctx *p = user;
    return p->o->progress ? p->o->progress(p->o->user, p->stage, fraction) : 0;
}

/* Members of each segment (CSR) from the per-point segment ids. */
static ag_status build_members(ag_segment_cloud_result *r, ag_error *err)
{
    free(r->member_start);
    free(r->members);
    r->member_start = NULL;
    r->members = NULL;
    ag_group g;
    ag_status st = ag_group_build(&g, r->segment, r->n, r->nsegments, err);
    if (st != AG_OK)
        return st;
    r->member_start = g.start;
    r->members = g.members;
    return AG_OK;
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* The largest principal direction of the points' covariance projected on the plane with
 * normal `normal` (unit): the in-plane axis of a flat segment. */
static void in_plane_axis(const ag_cloud *c, const uint32_t *idx, size_t m, const double mean[3],
                          const double normal[3], double axis[3])
{
    double cov[6] = {0, 0, 0, 0, 0, 0};
    for (size_t j = 0; j < m; j++) {
        const double *p = c->xyz + 3 * (size_t)idx[j];
        double d[3] = {p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]};
        double h = d[0] * normal[0] + d[1] * normal[1] + d[2] * normal[2];
        for (int a = 0; a < 3; a++)
            d[a] -= h * normal[a];
        cov[0] -= d[0] * d[0];
        cov[1] -= d[0] * d[1];
        cov[2] -= d[0] * d[2];
        cov[3] -= d[1] * d[1];
        cov[4] -= d[1] * d[2];
        cov[5] -= d[2] * d[2];
    }
    /* the smallest eigenvector of -cov is the largest of cov */
    ag_normals_smallest_eigenvector(cov, axis, NULL);
}

/* A segment's frame and extents. The frame follows the building rather than the points'
 * principal axes, which turn freely for nearly square shapes: a wall or roof plane has its
 * horizontal direction and its slope line as axes, a level plane and a cluster the vertical
 * and the principal direction of their plan, an element its host's frame. */
static void describe(const ag_cloud *c, const uint32_t *idx, size_t m, ag_segment_cloud_item *s,
                     const ag_segment_cloud_item *host)
{
    double mean[3], cov[6];
    ag_normals_covariance(c->xyz, idx, m, mean, cov);
    double small[3], ev[3];
    ag_normals_smallest_eigenvector(cov, small, ev);
    double a0[3], a1[3], a2[3];
    const double up[3] = {0, 0, 1};
    if (host) {
        memcpy(a0, host->axes[0], sizeof a0);
        memcpy(a1, host->axes[1], sizeof a1);
        memcpy(a2, host->axes[2], sizeof a2);
    } else if (s->kind == AG_SEGMENT_CLOUD_PLANE && fabs(small[2]) < 0.9) {
        /* walls and roof planes: horizontal in-plane axis, then the slope line */
        cross3(up, small, a0);
        double l = sqrt(a0[0] * a0[0] + a0[1] * a0[1] + a0[2] * a0[2]);
        for (int a = 0; a < 3; a++)
            a0[a] /= l;
        cross3(small, a0, a1);
        memcpy(a2, small, sizeof a2);
    } else if (s->kind == AG_SEGMENT_CLOUD_PLANE) {
        /* level planes: the principal direction of the plan */
        in_plane_axis(c, idx, m, mean, small, a0);
        cross3(small, a0, a1);
        memcpy(a2, small, sizeof a2);
    } else {
        /* clusters and elements without a host: vertical, and the principal plan direction */
        in_plane_axis(c, idx, m, mean, up, a0);
        cross3(up, a0, a1);
        memcpy(a2, up, sizeof a2);
    }
    memcpy(s->centroid, mean, sizeof mean);
    memcpy(s->axes[0], a0, sizeof a0);
    memcpy(s->axes[1], a1, sizeof a1);
    memcpy(s->axes[2], a2, sizeof a2);
    for (int k = 0; k < 3; k++) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t j = 0; j < m; j++) {
            const double *p = c->xyz + 3 * (size_t)idx[j];
            double v = (p[0] - mean[0]) * s->axes[k][0] + (p[1] - mean[1]) * s->axes[k][1] +
                       (p[2] - mean[2]) * s->axes[k][2];
            if (v < lo)
                lo = v;
            if (v > hi)
                hi = v;
        }
        s->extent[k] = m ? hi - lo : 0;
    }
    memcpy(s->plane.n, small, sizeof small);
    s->plane.d = -(small[0] * mean[0] + small[1] * mean[1] + small[2] * mean[2]);
    s->plane.count = m;
    s->count = m;
    s->box = ag_box_empty();
    for (size_t j = 0; j < m; j++)
        ag_box_extend_point(&s->box, c->xyz + 3 * (size_t)idx[j]);
}

static int cmp_double_desc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
}

int ag_segment_cloud_similar(const ag_segment_cloud_item *a, const ag_segment_cloud_item *b,
                             double slack)
{
    if (a->kind != b->kind)
        return 0;
    double ca = (double)a->count, cb = (double)b->count;
    if (fabs(ca - cb) > AG_POINTS_LABEL_COUNT * (ca > cb ? ca : cb))
        return 0;
    double ea[3], eb[3];
    memcpy(ea, a->extent, sizeof ea);
    memcpy(eb, b->extent, sizeof eb);
    qsort(ea, 3, sizeof ea[0], cmp_double_desc);
    qsort(eb, 3, sizeof eb[0], cmp_double_desc);
    for (int k = 0; k < 3; k++)
        if (fabs(ea[k] - eb[k]) > AG_POINTS_LABEL_DIMS * (ea[k] > eb[k] ? ea[k] : eb[k]) + slack)
            return 0;
    return 1;
}

size_t ag_segment_cloud_in_use(const ag_segment_cloud_result *r)
{
    return r->nplanes + r->nclusters + r->nelements;
}

ag_segment_cloud_spec ag_segment_cloud_spec_of(const ag_segment_cloud_item *it)
{
    /* an element keeps its host and shares a label with the elements it shared one with */
    int el = it->kind == AG_SEGMENT_CLOUD_ELEMENT;
    return (ag_segment_cloud_spec){it->kind, el ? it->host : -1, el ? it->label : -1,
                                   el ? it->box : ag_box_empty()};
}

static void *dup_of(const void *p, size_t bytes, int *nomem)
{
    void *q = malloc(bytes ? bytes : 1);
    if (!q)
        *nomem = 1;
    else if (p && bytes)
        memcpy(q, p, bytes);
    return q;
}

ag_status ag_segment_cloud_clone(const ag_segment_cloud_result *r,
                                 ag_segment_cloud_result **out, ag_error *err)
{
    *out = NULL;
    ag_segment_cloud_result *o = malloc(sizeof *o);
    if (!o)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    *o = *r;
    int nomem = 0;
    size_t nm = r->member_start ? r->member_start[r->nsegments] : 0;
    o->segment = dup_of(r->segment, r->n * sizeof *r->segment, &nomem);
    o->label = dup_of(r->label, r->n * sizeof *r->label, &nomem);
    o->piece = dup_of(r->piece, r->n * sizeof *r->piece, &nomem);
    o->segments = dup_of(r->segments, r->nsegments * sizeof *r->segments, &nomem);
    o->member_start = r->member_start ? dup_of(r->member_start,
                                               (r->nsegments + 1) * sizeof *r->member_start,
                                               &nomem)
                                      : NULL;
    o->members = r->members ? dup_of(r->members, nm * sizeof *r->members, &nomem) : NULL;
    if (nomem) {
        ag_segment_cloud_free(o);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    *out = o;
    return AG_OK;
}


ag_status ag_segment_cloud_rebuild(const ag_cloud *c, ag_segment_cloud_result *r,
                                   const ag_segment_cloud_spec *spec, size_t nspec,
                                   ag_error *err)
{
    /* every id keeps its number; the ids without points stay as unused entries */
    size_t *count = calloc(nspec + 1, sizeof *count);
    if (!count)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < r->n; i++)
        if (r->segment[i] >= 0) {
            if ((size_t)r->segment[i] >= nspec) {
                free(count);
                return ag_error_set(err, AG_ERR_INTERNAL, 0, "point %zu has segment %d of %zu",
                                    i + 1, (int)r->segment[i], nspec);
            }
            count[r->segment[i]]++;
        }
    size_t per_kind[3] = {0, 0, 0};
    for (size_t s = 0; s < nspec; s++)
        if (count[s] && (unsigned)spec[s].kind <= AG_SEGMENT_CLOUD_ELEMENT)
            per_kind[spec[s].kind]++;
    r->nsegments = nspec;
    r->nplanes = per_kind[AG_SEGMENT_CLOUD_PLANE];
    r->nclusters = per_kind[AG_SEGMENT_CLOUD_CLUSTERED];
    r->nelements = per_kind[AG_SEGMENT_CLOUD_ELEMENT];
    ag_status st = build_members(r, err);
    if (st == AG_OK) {
        free(r->segments);
        r->segments = calloc(r->nsegments ? r->nsegments : 1, sizeof *r->segments);
        if (!r->segments)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* pieces: an element is one piece; the others keep theirs, renumbered densely */
    int32_t *pmap = NULL;
    size_t np = r->npieces + r->nsegments;
    if (st == AG_OK && !(pmap = malloc((np + 1) * sizeof *pmap)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK) {
        for (size_t p = 0; p < np; p++)
            pmap[p] = -1;
        int32_t pn = 0;
        for (size_t i = 0; i < r->n; i++) {
            int32_t sg = r->segment[i];
            int32_t p = sg < 0 ? -1
                        : spec[sg].kind == AG_SEGMENT_CLOUD_ELEMENT ? (int32_t)r->npieces + sg
                                                                    : r->piece[i];
            if (p < 0 || (size_t)p >= np) {
                r->piece[i] = -1;
                continue;
            }
            if (pmap[p] < 0)
                pmap[p] = pn++;
            r->piece[i] = pmap[p];
        }
        r->npieces = (size_t)pn;
    }
    free(pmap);
    /* descriptions: hosts (planes, clusters) before the elements that use their frames */
    for (int pass = 0; st == AG_OK && pass < 2; pass++)
        for (size_t s = 0; s < r->nsegments; s++) {
            const ag_segment_cloud_spec *sp = &spec[s];
            ag_segment_cloud_item *it = &r->segments[s];
            int el = sp->kind == AG_SEGMENT_CLOUD_ELEMENT;
            if (el != pass)
                continue;
            it->kind = sp->kind;
            it->host = el && sp->host >= 0 && (size_t)sp->host < nspec && count[sp->host]
                           ? sp->host
                           : -1;
            it->label = -1;
            it->box = ag_box_empty();
            if (!count[s])
                continue; /* an unused id */
            describe(c, r->members + r->member_start[s],
                     r->member_start[s + 1] - r->member_start[s], it,
                     it->host >= 0 ? &r->segments[it->host] : NULL);
            if (el && !ag_box_is_empty(&sp->box))
                ag_box_extend_box(&it->box, &sp->box);
        }
    for (size_t s = 0; st == AG_OK && s < r->nsegments; s++)
        if (r->segments[s].host >= 0)
            ag_box_extend_box(&r->segments[r->segments[s].host].box, &r->segments[s].box);
    /* labels: a group's elements share one; the others by the rule within their kind */
    int32_t *rep = NULL, *group_label = NULL;
    int32_t max_group = -1;
    for (size_t s = 0; s < nspec; s++)
        if (spec[s].group > max_group)
            max_group = spec[s].group;
    if (st == AG_OK && (!(rep = malloc((r->nsegments + 1) * sizeof *rep)) ||
                        !(group_label = malloc(((size_t)max_group + 2) * sizeof *group_label))))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK) {
        for (int32_t g = 0; g <= max_group; g++)
            group_label[g] = -1;
        size_t nlabels = 0, nrep = 0;
        for (int kind = AG_SEGMENT_CLOUD_PLANE; kind <= AG_SEGMENT_CLOUD_ELEMENT; kind++)
            for (size_t s = 0; s < r->nsegments; s++) {
                ag_segment_cloud_item *it = &r->segments[s];
                if ((int)it->kind != kind || !count[s])
                    continue;
                int32_t g = spec[s].group;
                if (it->kind == AG_SEGMENT_CLOUD_ELEMENT && g >= 0) {
                    if (group_label[g] < 0)
                        group_label[g] = (int32_t)nlabels++;
                    it->label = group_label[g];
                    continue;
                }
                for (size_t l = 0; l < nrep; l++)
                    if (ag_segment_cloud_similar(&r->segments[rep[l]], it, 2 * r->spacing)) {
                        it->label = r->segments[rep[l]].label;
                        break;
                    }
                if (it->label < 0) {
                    rep[nrep++] = (int32_t)s;
                    it->label = (int32_t)nlabels++;
                }
            }
        r->nlabels = nlabels;
        for (size_t i = 0; i < r->n; i++)
            r->label[i] = r->segment[i] >= 0 ? r->segments[r->segment[i]].label : -1;
    }
    free(rep);
    free(group_label);
    free(count);
    return st;
}

/* Segment table, members and labels from r->segment; kind[s] gives each id's kind, or (kind
 * NULL) the nplanes first ids are planes, the rest clusters. */
static ag_status finish(const ag_cloud *c, ag_segment_cloud_result *r, const uint8_t *kind,
                        size_t nplanes, ag_error *err)
{
    size_t ns = r->nsegments;
    ag_segment_cloud_spec *spec = malloc((ns + 1) * sizeof *spec);
    if (!spec)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t s = 0; s < ns; s++)
        spec[s] = (ag_segment_cloud_spec){kind ? (ag_segment_cloud_kind)kind[s]
                                          : s < nplanes ? AG_SEGMENT_CLOUD_PLANE
                                                        : AG_SEGMENT_CLOUD_CLUSTERED,
                                          -1, -1, ag_box_empty()};
    ag_status st = ag_segment_cloud_rebuild(c, r, spec, ns, err);
    free(spec);
    return st;
}

static ag_status alloc_result(size_t n, ag_segment_cloud_result **out, ag_error *err)
{
    ag_segment_cloud_result *r = calloc(1, sizeof *r);
    if (r) {
        r->n = n;
        r->segment = malloc((n ? n : 1) * sizeof *r->segment);
        r->label = malloc((n ? n : 1) * sizeof *r->label);
        r->piece = malloc((n ? n : 1) * sizeof *r->piece);
    }
    if (!r || !r->segment || !r->label || !r->piece) {
        ag_segment_cloud_free(r);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t i = 0; i < n; i++)
        r->segment[i] = r->label[i] = r->piece[i] = -1;
    *out = r;
    return AG_OK;
}

/* Segments the distinct points of c (rep[i]: the first copy of point i, ndistinct of them)
 * and gives every copy its original's segment and piece in r (allocated for all of c). */
static ag_status segment_distinct(ag_cloud *c, const ag_segment_cloud_options *o,
                                  const uint32_t *rep, size_t ndistinct,
                                  ag_segment_cloud_result *r, ag_error *err)
{
    size_t n = c->n;
    uint32_t *keep = malloc((ndistinct ? ndistinct : 1) * sizeof *keep);
    uint32_t *at = malloc(n * sizeof *at); /* a distinct point's index in the subset */
    if (!keep || !at) {
        free(keep);
        free(at);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (rep[i] == i) {
            at[i] = (uint32_t)m;
            keep[m++] = (uint32_t)i;
        }
    ag_cloud *sub = NULL;
    ag_segment_cloud_result *rs = NULL;
    ag_status st = ag_cloud_subset(c, keep, m, &sub, err);
    if (st == AG_OK)
        st = ag_segment_cloud_run(sub, o, &rs, err);
    if (st == AG_OK && !c->normals && sub->normals) {
        st = ag_cloud_add_normals(c, err); /* the cloud keeps the normals it lacked */
        if (st == AG_OK)
            for (size_t i = 0; i < n; i++)
                memcpy(c->normals + 3 * i, sub->normals + 3 * (size_t)at[rep[i]],
                       3 * sizeof *c->normals);
    }
    if (st == AG_OK) {
        for (size_t i = 0; i < n; i++) {
            r->segment[i] = rs->segment[at[rep[i]]];
            r->piece[i] = rs->piece[at[rep[i]]];
        }
        r->npieces = rs->npieces;
        r->nsegments = rs->nsegments;
        r->ncoarse = rs->ncoarse;
        r->diagonal = rs->diagonal;
        r->spacing = rs->spacing;
        r->coarse_threshold = rs->coarse_threshold;
        r->fine_threshold = rs->fine_threshold;
        r->cluster_tolerance = rs->cluster_tolerance;
        memcpy(r->seconds, rs->seconds, sizeof r->seconds);
        memcpy(r->cpu_seconds, rs->cpu_seconds, sizeof r->cpu_seconds);
        /* the rebuild counts and labels the run's segments over every copy */
        uint8_t *kind = malloc(rs->nsegments + 1);
        if (!kind)
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        for (size_t s = 0; kind && s < rs->nsegments; s++)
            kind[s] = (uint8_t)rs->segments[s].kind;
        if (st == AG_OK)
            st = finish(c, r, kind, 0, err);
        free(kind);
    }
    ag_segment_cloud_free(rs);
    ag_cloud_free(sub);
    free(keep);
    free(at);
    return st;
}

ag_status ag_segment_cloud_run(ag_cloud *c, const ag_segment_cloud_options *opt,
                               ag_segment_cloud_result **out, ag_error *err)
{
    *out = NULL;
    ag_segment_cloud_options o = opt ? *opt : (ag_segment_cloud_options){0};
    size_t n = c->n;
    ag_segment_cloud_result *r = NULL;
    ag_status st = alloc_result(n, &r, err);
    if (st != AG_OK)
        return st;
    if (n >= UINT32_MAX / 2) {
        ag_segment_cloud_free(r);
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%zu points are too many to segment at once", n);
    }
    double coarse = o.coarse_threshold ? o.coarse_threshold : 0.025;
    double fine = o.fine_threshold > 0 ? o.fine_threshold : 0.01;
    double angle = o.max_angle > 0 ? o.max_angle : 20;
    double tol = o.cluster_tolerance > 0 ? o.cluster_tolerance : 0.01;
    size_t min_plane = o.min_plane_points ? o.min_plane_points : (n / 10000 > 10 ? n / 10000 : 10);
    size_t min_cluster = o.min_cluster_points ? o.min_cluster_points : min_plane;
    unsigned k = o.k ? o.k : 16;
    if (k < 4)
        k = 4;
    if (k > 64)
        k = 64;
    r->diagonal = ag_cloud_diagonal(c);
    *out = r;
    if (n < 3 || !(r->diagonal > 0)) {
        /* nothing to fit: a point, a duplicate pile or no points at all */
        return finish(c, r, NULL, 0, err);
    }
    r->fine_threshold = fine * r->diagonal;
    r->coarse_threshold = coarse > 0 ? coarse * r->diagonal : 0;
    progress_ctx pc = {&o, AG_SEGMENT_CLOUD_INDEX};

    double t = ag_clock_seconds(), tc = ag_clock_thread_cpu_seconds();
    ag_kdtree *tree = NULL;
    float *variation = NULL;
    uint32_t *graph = NULL, *idx = NULL;
    int32_t *plane_of = NULL;
    ag_plane_list planes = {0}, coarse_planes = {0};
    ag_cloud view = *c; /* the cloud as the segmentation sees it (its normals) */
    view.normals = NULL;
    st = ag_kdtree_build(c->xyz, NULL, n, &tree, err);
    if (st != AG_OK)
        goto done;
    {
        /* copies of a point would halve every neighbourhood and zero the spacing: the
         * distinct points are segmented and each copy takes its original's answer */
        uint32_t *rep = malloc(n * sizeof *rep);
        size_t distinct = n;
        st = rep ? ag_coincident_points(tree, c->xyz, n, AG_COINCIDENT_TOLERANCE, rep,
                                        &distinct, err)
                 : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        if (st == AG_OK && distinct < n) {
            ag_kdtree_free(tree);
            tree = NULL;
            double index_seconds = ag_clock_seconds() - t;
            double index_cpu = ag_clock_thread_cpu_seconds() - tc;
            st = segment_distinct(c, &o, rep, distinct, r, err);
            r->seconds[AG_SEGMENT_CLOUD_INDEX] += index_seconds;
            r->cpu_seconds[AG_SEGMENT_CLOUD_INDEX] += index_cpu;
        }
        free(rep);
        if (st != AG_OK || distinct < n)
            goto done;
    }
    variation = malloc(n * sizeof *variation);
    graph = malloc(n * (size_t)k * sizeof *graph);
    plane_of = malloc(n * sizeof *plane_of);
    idx = malloc(n * sizeof *idx);
    if (!variation || !graph || !plane_of || !idx) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    r->seconds[AG_SEGMENT_CLOUD_INDEX] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_INDEX] = ag_clock_thread_cpu_seconds() - tc;

    t = ag_clock_seconds();

    tc = ag_clock_thread_cpu_seconds();
    pc.stage = AG_SEGMENT_CLOUD_NORMALS;
    ag_normals_options no = {k, o.progress ? stage_progress : NULL, &pc};
    ag_normals_info info;
    st = ag_normals_compute(&view, tree, &no, variation, graph, &info, err);
    if (st != AG_OK)
        goto done;
    r->spacing = info.spacing > 0 ? info.spacing : r->diagonal * 1e-3;
    if (!c->normals) {
        c->normals = view.normals; /* the cloud keeps the normals it lacked */
    } else if (!o.recompute_normals) {
        free(view.normals);
        view.normals = c->normals;
    }
    ag_ransac_graph g = {graph, k};
    r->seconds[AG_SEGMENT_CLOUD_NORMALS] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_NORMALS] = ag_clock_thread_cpu_seconds() - tc;

    for (size_t i = 0; i < n; i++) {
        plane_of[i] = -1;
        idx[i] = (uint32_t)i;
    }
    t = ag_clock_seconds();
    tc = ag_clock_thread_cpu_seconds();
    if (coarse > 0) {
        pc.stage = AG_SEGMENT_CLOUD_COARSE;
        ag_ransac_options ro = {.threshold = r->coarse_threshold,
                                .min_points = min_plane > n / 200 ? min_plane : n / 200,
                                .seed = o.seed ? o.seed : DEFAULT_SEED,
                                .progress = o.progress ? stage_progress : NULL,
                                .user = &pc};
        st = ag_ransac_global(&view, idx, n, NULL, 0, &ro, plane_of, &planes, err);
        if (st != AG_OK)
            goto done;
        r->ncoarse = planes.n;
        coarse_planes = planes;
        memset(&planes, 0, sizeof planes);
        for (size_t i = 0; i < n; i++)
            plane_of[i] = -1;
    }
    r->seconds[AG_SEGMENT_CLOUD_COARSE] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_COARSE] = ag_clock_thread_cpu_seconds() - tc;

    t = ag_clock_seconds();

    tc = ag_clock_thread_cpu_seconds();
    pc.stage = AG_SEGMENT_CLOUD_REFINE;
    double radius = 4 * r->spacing;
    ag_ransac_options lo = {.threshold = r->fine_threshold,
                            .max_angle = angle,
                            .adaptive = 1,
                            .min_points = min_plane,
                            .radius = radius,
                            .progress = o.progress ? stage_progress : NULL,
                            .user = &pc};
    {
        /* the dominant planes at the fine threshold with the normal test, over the whole
         * cloud, best first; the coarse planes are candidates in every round, so each
         * dominant plane is refined whole rather than cut at the borders of its slab */
        ag_ransac_options go = lo;
        go.min_points = min_plane > n / 1000 ? min_plane : n / 1000;
        go.seed = (o.seed ? o.seed : DEFAULT_SEED) + 1;
        go.extra = coarse_planes.items;
        go.nextra = coarse_planes.n;
        st = ag_ransac_global(&view, idx, n, NULL, 0, &go, plane_of, &planes, err);
        if (st != AG_OK)
            goto done;
        /* then the small planes in what is left: connected support from flat seeds */
        size_t m = 0;
        for (size_t i = 0; i < n; i++)
            if (plane_of[i] < 0)
                idx[m++] = (uint32_t)i;
        st = ag_ransac_local(&view, &g, variation, idx, m, NULL, 0, &lo, plane_of, &planes, err);
        if (st != AG_OK)
            goto done;
    }
    r->seconds[AG_SEGMENT_CLOUD_REFINE] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_REFINE] = ag_clock_thread_cpu_seconds() - tc;

    t = ag_clock_seconds();

    tc = ag_clock_thread_cpu_seconds();
    size_t ncomp = 0;
    {
        /* pieces of each plane; stray pieces leave their plane (for the clustering) */
        double gap = o.plane_gap ? o.plane_gap : 0.02;
        if (gap < 0) {
            for (size_t i = 0; i < n; i++)
                r->piece[i] = plane_of[i];
            r->npieces = planes.n;
        } else {
            st = ag_cluster_pieces(c, plane_of, gap * r->diagonal, min_plane, r->piece,
                                   &r->npieces, err);
            if (st != AG_OK)
                goto done;
        }
        /* A plane's big pieces stay one segment (coplanar parts of one facade on both sides
         * of a recess); a piece much smaller than the plane's largest is a segment of its
         * own (a ledge coplanar with a far-away roof edge, bits of other surfaces). */
        size_t np = r->npieces;
        uint32_t *psize = calloc(np + 1, sizeof *psize);
        int32_t *pplane = malloc((np + 1) * sizeof *pplane);
        uint32_t *largest = calloc(planes.n + 1, sizeof *largest);
        int32_t *main_id = malloc((planes.n + 1) * sizeof *main_id);
        int32_t *pseg = malloc((np + 1) * sizeof *pseg);
        if (!psize || !pplane || !largest || !main_id || !pseg) {
            free(psize);
            free(pplane);
            free(largest);
            free(main_id);
            free(pseg);
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto done;
        }
        for (size_t i = 0; i < n; i++)
            if (plane_of[i] >= 0) {
                psize[r->piece[i]]++;
                pplane[r->piece[i]] = plane_of[i];
            }
        for (size_t p = 0; p < np; p++)
            if (psize[p] > largest[pplane[p]])
                largest[pplane[p]] = psize[p];
        for (size_t p = 0; p < planes.n; p++)
            main_id[p] = -1;
        size_t big_piece = min_plane > n / 1000 ? min_plane : n / 1000;
        for (size_t p = 0; p < np; p++) {
            int32_t pl = pplane[p];
            if (psize[p] >= MAIN_PIECE_SHARE * largest[pl] && psize[p] >= big_piece) {
                if (main_id[pl] < 0)
                    main_id[pl] = (int32_t)ncomp++;
                pseg[p] = main_id[pl];
            } else {
                pseg[p] = (int32_t)ncomp++;
            }
        }
        for (size_t i = 0; i < n; i++)
            if (plane_of[i] >= 0)
                plane_of[i] = pseg[r->piece[i]];
        free(psize);
        free(pplane);
        free(largest);
        free(main_id);
        free(pseg);
    }
    r->seconds[AG_SEGMENT_CLOUD_COMPONENTS] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_COMPONENTS] = ag_clock_thread_cpu_seconds() - tc;

    t = ag_clock_seconds();

    tc = ag_clock_thread_cpu_seconds();
    {
        size_t m = 0;
        for (size_t i = 0; i < n; i++) {
            r->segment[i] = plane_of[i];
            if (plane_of[i] < 0)
                idx[m++] = (uint32_t)i;
        }
        r->cluster_tolerance = tol * r->diagonal;
        if (r->cluster_tolerance < 2 * r->spacing)
            r->cluster_tolerance = 2 * r->spacing;
        size_t ncl = 0;
        st = ag_cluster_euclidean(c, idx, m, r->cluster_tolerance, min_cluster, (int32_t)ncomp,
                                  r->segment, &ncl, err);
        if (st != AG_OK)
            goto done;
        r->nsegments = ncomp + ncl;
        /* a cluster is one piece */
        for (size_t j = 0; j < m; j++)
            if (r->segment[idx[j]] >= 0)
                r->piece[idx[j]] = (int32_t)r->npieces + (r->segment[idx[j]] - (int32_t)ncomp);
        r->npieces += ncl;
    }
    r->seconds[AG_SEGMENT_CLOUD_CLUSTER] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_CLUSTER] = ag_clock_thread_cpu_seconds() - tc;

    t = ag_clock_seconds();

    tc = ag_clock_thread_cpu_seconds();
    st = finish(c, r, NULL, ncomp, err); /* the ncomp planes first, then the clusters */

    r->seconds[AG_SEGMENT_CLOUD_LABEL] = ag_clock_seconds() - t;
    r->cpu_seconds[AG_SEGMENT_CLOUD_LABEL] = ag_clock_thread_cpu_seconds() - tc;

done:
    if (view.normals && view.normals != c->normals)
        free(view.normals);
    ag_kdtree_free(tree);
    free(variation);
    free(graph);
    free(plane_of);
    free(idx);
    ag_plane_list_free(&planes);
    ag_plane_list_free(&coarse_planes);
    if (st != AG_OK) {
        ag_segment_cloud_free(r);
        *out = NULL;
    }
    return st;
}

/* After a rebuild numbered the label rule's classes afresh: a class takes the label id that
 * its first segment of the old ones (ids below old, old_label[s] their labels before) had,
 * unless a class before took it; the other classes get ids from old_nlabels on. */
static ag_status keep_label_ids(ag_segment_cloud_result *r, const int32_t *old_label,
                                size_t old, size_t old_nlabels, ag_error *err)
{
    size_t nl = r->nlabels;
    int32_t *to = malloc((nl + 1) * sizeof *to);
    uint8_t *taken = calloc(old_nlabels + 1, 1);
    if (!to || !taken) {
        free(to);
        free(taken);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t l = 0; l < nl; l++)
        to[l] = -1;
    for (size_t s = 0; s < old && s < r->nsegments; s++) {
        int32_t l = r->segments[s].label, was = old_label[s];
        if (l < 0 || to[l] >= 0 || was < 0 || (size_t)was >= old_nlabels || taken[was])
            continue;
        to[l] = was;
        taken[was] = 1;
    }
    int32_t next = (int32_t)old_nlabels;
    for (size_t l = 0; l < nl; l++)
        if (to[l] < 0)
            to[l] = next++;
    for (size_t s = 0; s < r->nsegments; s++)
        if (r->segments[s].label >= 0)
            r->segments[s].label = to[r->segments[s].label];
    for (size_t i = 0; i < r->n; i++)
        r->label[i] = r->segment[i] >= 0 ? r->segments[r->segment[i]].label : -1;
    r->nlabels = (size_t)next;
    free(to);
    free(taken);
    return AG_OK;
}

ag_status ag_segment_cloud_refine(ag_cloud *c, ag_segment_cloud_result *r, const double min[3],
                                  const double max[3], const ag_segment_cloud_options *opt,
                                  ag_error *err)
{
    if (r->n != c->n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the segmentation is of another cloud");
    uint32_t *inside = malloc((c->n ? c->n : 1) * sizeof *inside);
    if (!inside)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t m = 0;
    for (size_t i = 0; i < c->n; i++) {
        const double *p = c->xyz + 3 * i;
        if (p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1] &&
            p[2] >= min[2] && p[2] <= max[2])
            inside[m++] = (uint32_t)i;
    }
    ag_cloud *sub = NULL;
    ag_segment_cloud_result *rs = NULL;
    ag_status st = ag_cloud_subset(c, inside, m, &sub, err);
    if (st == AG_OK) {
        ag_segment_cloud_options o = opt ? *opt : (ag_segment_cloud_options){0};
        o.recompute_normals = 0; /* the whole cloud's normals, computed with more context */
        st = ag_segment_cloud_run(sub, &o, &rs, err);
    }
    if (st != AG_OK) {
        ag_cloud_free(sub);
        free(inside);
        return st;
    }
    /* old segments keep their ids (minus the points inside), new ones follow */
    size_t old = r->nsegments, nnew = rs->nsegments, old_nlabels = r->nlabels;
    ag_segment_cloud_spec *spec = malloc((old + nnew + 1) * sizeof *spec);
    int32_t *old_label = malloc((old + 1) * sizeof *old_label);
    if (!spec || !old_label) {
        free(spec);
        free(old_label);
        ag_cloud_free(sub);
        free(inside);
        ag_segment_cloud_free(rs);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t s = 0; s < old; s++)
        old_label[s] = r->segments[s].label;
    for (size_t s = 0; s < old; s++)
        spec[s] = ag_segment_cloud_spec_of(&r->segments[s]);
    for (size_t s = 0; s < nnew; s++)
        spec[old + s] = (ag_segment_cloud_spec){rs->segments[s].kind, -1, -1, ag_box_empty()};
    for (size_t j = 0; j < m; j++) {
        r->segment[inside[j]] = rs->segment[j] >= 0 ? (int32_t)(old + (size_t)rs->segment[j]) : -1;
        r->piece[inside[j]] = rs->piece[j] >= 0 ? (int32_t)r->npieces + rs->piece[j] : -1;
    }
    r->npieces += rs->npieces;
    free(inside);
    ag_cloud_free(sub);
    ag_segment_cloud_free(rs);
    st = ag_segment_cloud_rebuild(c, r, spec, old + nnew, err);
    if (st == AG_OK)
        st = keep_label_ids(r, old_label, old, old_nlabels, err);
    free(spec);
    free(old_label);
    return st;
}

ag_status ag_segment_cloud_restore(const ag_cloud *c, const ag_segment_cloud_ids *ids,
                                   ag_segment_cloud_result **out, ag_error *err)
{
    *out = NULL;
    size_t n = c->n;
    if (ids->nplanes > ids->nsegments || ids->nsegments >= INT32_MAX ||
        ids->npieces >= INT32_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%zu planes among %zu segments and %zu pieces cannot be",
                            ids->nplanes, ids->nsegments, ids->npieces);
    for (size_t s = 0; ids->kind && s < ids->nsegments; s++)
        if (ids->kind[s] > AG_SEGMENT_CLOUD_ELEMENT)
            return ag_error_set(err, AG_ERR_INVALID, (long)s + 1, "segment %zu has kind %u", s,
                                (unsigned)ids->kind[s]);
    for (size_t i = 0; i < n; i++) {
        int32_t s = ids->segment[i], p = ids->piece[i];

        if (s < -1 || s >= (int32_t)ids->nsegments || p < -1 || p >= (int32_t)ids->npieces ||
            (s < 0) != (p < 0))
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "point %zu has segment %d and piece %d (of %zu and %zu)", i + 1,
                                s, p, ids->nsegments, ids->npieces);
    }
    ag_segment_cloud_result *r = NULL;
    ag_status st = alloc_result(n, &r, err);
    if (st != AG_OK)
        return st;
    memcpy(r->segment, ids->segment, n * sizeof *r->segment);
    memcpy(r->piece, ids->piece, n * sizeof *r->piece);
    r->nsegments = ids->nsegments;
    r->npieces = ids->npieces;
    r->spacing = ids->spacing;
    r->diagonal = ag_cloud_diagonal(c);
    st = finish(c, r, ids->kind, ids->nplanes, err);
    if (st == AG_OK && ids->label) {
        /* the labels given, checked against their segments, kept as they are */
        size_t bound = ids->nlabels ? ids->nlabels : n, nlabels = ids->nlabels;
        for (size_t s = 0; s < r->nsegments; s++)
            r->segments[s].label = -1;
        for (size_t i = 0; st == AG_OK && i < n; i++) {
            int32_t s = r->segment[i], l = ids->label[i];
            if ((s < 0) != (l < 0) || (l >= 0 && (size_t)l >= bound) ||
                (s >= 0 && r->segments[s].label >= 0 && r->segments[s].label != l))
                st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                  "point %zu has label %d, which its segment %d does not have",
                                  i + 1, l, s);
            else if (s >= 0) {
                r->segments[s].label = l;
                if ((size_t)l + 1 > nlabels)
                    nlabels = (size_t)l + 1;
            }
        }
        if (st == AG_OK) {
            r->nlabels = nlabels;
            for (size_t i = 0; i < n; i++)
                r->label[i] = ids->label[i];
        }
    }
    if (st != AG_OK) {
        ag_segment_cloud_free(r);
        return st;
    }
    *out = r;
    return AG_OK;
}
