/* Segment decomposition of a point cloud (§3.1 of "Procedural editing of building point
 * clouds") in one call: spatial index → kNN normals → a global RANSAC pass at the paper's
 * 2.5 % of the diagonal (the dominant planes) → a refinement pass inside each of them and
 * then over what is left (smaller threshold, normal-angle test, connected support) →
 * connected pieces of each plane (stray bits dropped) → Euclidean clustering (tolerance T_C)
 * of the rest →
 * labels (§3.2: same kind, box dimensions within 5 %, point counts within 10 %).
 *
 * Thresholds are fractions of the cloud's diagonal, so one set of defaults serves a
 * chimney and a church; the options' zero value means the defaults. A region of interest
 * can be segmented again at a finer granularity (ag_segment_cloud_refine), replacing only
 * the segments inside it. Segment ids are stable: a stage that reassigns points (ROI
 * refinement, template marking, repetition) leaves every segment that keeps a point its id,
 * gives new segments ids after every id there was, and leaves the id of a segment left
 * without points unused (an empty entry: count 0, label -1). Deterministic: the random
 * choices come from a seeded generator.
 * Copies of a point (closer than AG_COINCIDENT_TOLERANCE) are segmented once and take their
 * original's segment: a cloud written twice over gives the segments of the cloud itself.
 * The seconds of each stage are reported. Segments list their members (CSR) for the stages
 * that come after (consensus models, split tree). */
#ifndef AG_POINTS_SEGMENT_CLOUD_H
#define AG_POINTS_SEGMENT_CLOUD_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"
#include "cloud.h"
#include "ransac.h"

typedef enum {
    AG_SEGMENT_CLOUD_INDEX,      /* kd-tree */
    AG_SEGMENT_CLOUD_NORMALS,    /* kNN PCA normals and the neighbour graph */
    AG_SEGMENT_CLOUD_COARSE,     /* global RANSAC at the coarse threshold */
    AG_SEGMENT_CLOUD_REFINE,     /* local RANSAC with the normal test */
    AG_SEGMENT_CLOUD_COMPONENTS, /* connected components of the planes */
    AG_SEGMENT_CLOUD_CLUSTER,    /* Euclidean clustering of the rest */
    AG_SEGMENT_CLOUD_LABEL,      /* segment boxes and labels */
    AG_SEGMENT_CLOUD_STAGES
} ag_segment_cloud_stage;

const char *ag_segment_cloud_stage_name(ag_segment_cloud_stage s);

typedef struct {
    double coarse_threshold;  /* fraction of the diagonal; 0 = 0.025; < 0 skips the pass */
    double fine_threshold;    /* fraction of the diagonal; 0 = 0.01 */
    double max_angle;         /* degrees between point and plane normals; 0 = 20 */
    double cluster_tolerance; /* T_C, fraction of the diagonal; 0 = 0.01 */
    double plane_gap;         /* a plane's inliers are split into pieces where they are
                               * farther apart than this (fraction of the diagonal; 0 =
                               * 0.02; < 0: one piece per plane); pieces smaller than the
                               * plane minimum are dropped, the others stay one segment */
    size_t min_plane_points;  /* 0 = max(10, n / 10000) */
    size_t min_cluster_points;/* 0 = the plane minimum */
    unsigned k;               /* neighbours for normals and the graph; 0 = 16 */
    int recompute_normals;    /* segment with kNN normals even when the cloud has its own
                               * (by default a cloud's own normals, from the scanner or the
                               * mesh it was sampled from, are used: they are better) */
    uint64_t seed;            /* 0 = a fixed default */
    /* Called at each stage with the fraction of that stage done; non-zero cancels. */
    int (*progress)(void *user, ag_segment_cloud_stage stage, double fraction);
    void *user;
} ag_segment_cloud_options;

typedef enum {
    AG_SEGMENT_CLOUD_PLANE,
    AG_SEGMENT_CLOUD_CLUSTERED,
    AG_SEGMENT_CLOUD_ELEMENT, /* a repetition (§3.2, repeat.h): an element carved out of the
                               * segments around it, sitting in a host segment (a wall) */
} ag_segment_cloud_kind;

typedef struct {
    ag_segment_cloud_kind kind;
    size_t count;
    ag_plane plane;         /* least-squares plane (also for clusters: their flattest axis) */
    double centroid[3];
    /* The box frame: walls and roof planes have their horizontal direction, their slope line
     * and their normal; level planes the principal direction of their plan, the direction
     * across it and the normal; clusters the principal plan direction, across, vertical. */
    double axes[3][3];
    double extent[3];       /* size along each axis */
    int32_t label;          /* -1: an id left without points (count 0) */
    int32_t host;           /* elements: the segment they sit in, else -1 */
    ag_box box;             /* the node box (cloud-local, axis-aligned): the points' bounds, an
                             * element's matched box, a host's grown to hold its elements */
} ag_segment_cloud_item;

typedef struct {
    size_t n;                  /* points of the cloud */
    int32_t *segment;          /* per point: its segment, or -1 */
    int32_t *label;            /* per point: its segment's label, or -1 */
    int32_t *piece;            /* per point: the connected piece of its segment, or -1 */
    size_t npieces;
    size_t nsegments;          /* ids below it; segments[s].count 0: an id no longer used */
    ag_segment_cloud_item *segments;
    uint32_t *member_start;    /* nsegments + 1 offsets into members */
    uint32_t *members;         /* point indices of each segment, ascending */
    size_t nlabels;            /* label ids below it (one may be unused) */
    size_t ncoarse;            /* planes of the coarse pass */
    size_t nplanes, nclusters; /* segments with points of each kind, in any id order */
    size_t nelements;
    double diagonal, spacing;  /* metres */
    double coarse_threshold, fine_threshold, cluster_tolerance; /* metres, as used */
    double seconds[AG_SEGMENT_CLOUD_STAGES];     /* wall clock */
    double cpu_seconds[AG_SEGMENT_CLOUD_STAGES]; /* this thread's processor time */
} ag_segment_cloud_result;

/* Segments c. When c has no normals, the computed ones are stored in it. */
ag_status ag_segment_cloud_run(ag_cloud *c, const ag_segment_cloud_options *opt,
                               ag_segment_cloud_result **out, ag_error *err);

/* Segments the points inside the box [min, max] again, with thresholds relative to the
 * diagonal of those points, and replaces the segments they had: a segment reaching out of
 * the box keeps its id and its points outside, one wholly inside is gone (its id unused),
 * the new segments get ids from r->nsegments on. Labels are the label rule's again; a label
 * class that holds a segment labelled so before keeps that label id, the others get new
 * ones. */
ag_status ag_segment_cloud_refine(ag_cloud *c, ag_segment_cloud_result *r, const double min[3],
                                  const double max[3], const ag_segment_cloud_options *opt,
                                  ag_error *err);

/* A segmentation read back from its per-point ids (a stored one), with the segment table,
 * members and labels that ag_segment_cloud_run or _refine made, so it can be refined again
 * or handed to the stages after. segment[i] in [-1, nsegments), piece[i] in [-1, npieces);
 * kind (nsegments entries, ag_segment_cloud_kind values) gives each id's kind, or is NULL
 * for a segmentation stored before ids were stable: then the first nplanes ids are planes,
 * the rest clusters. An id no point has is an unused one. spacing as the run reported it
 * (the label rule's slack). label (may be NULL: computed by the label rule, as a run does)
 * gives each segment's label, the same for all its points, kept as it is (r->nlabels: one
 * more than the largest, or nlabels when that is more). AG_ERR_INVALID naming the first
 * point or id that does not fit. */
typedef struct {
    const int32_t *segment, *label, *piece;
    size_t nsegments, nplanes, npieces;
    double spacing;
    const uint8_t *kind; /* may be NULL (see above) */
    size_t nlabels;      /* may be 0 */
} ag_segment_cloud_ids;
ag_status ag_segment_cloud_restore(const ag_cloud *c, const ag_segment_cloud_ids *ids,
                                   ag_segment_cloud_result **out, ag_error *err);

void ag_segment_cloud_free(ag_segment_cloud_result *r);

/* What a stage that reassigns points (ROI refinement, repetition) says about each segment id
 * it uses in r->segment. */
typedef struct {
    ag_segment_cloud_kind kind;
    int32_t host;   /* elements: the id of their host (a plane or cluster id), else -1 */
    int32_t group;  /* elements of one group >= 0 share a label whatever the rule says (a
                     * template's matches); -1: labelled by the rule */
    ag_box box;     /* elements: the node box */
} ag_segment_cloud_spec;

/* After r->segment was reassigned to ids 0..nspec-1 described by spec: every id keeps its
 * number (r->nsegments becomes nspec; an id left without points stays as an unused entry),
 * and the members, descriptions, node boxes (hosts grown to hold their elements) and labels
 * are rebuilt (§3.2: within each kind, box dimensions within 5 % and point counts within
 * 10 %; a group's elements one label of their own; labels numbered planes, clusters,
 * elements, each in id order). Pieces are renumbered densely; an element is one piece. */
ag_status ag_segment_cloud_rebuild(const ag_cloud *c, ag_segment_cloud_result *r,
                                   const ag_segment_cloud_spec *spec, size_t nspec,
                                   ag_error *err);

/* Segments with points (nplanes + nclusters + nelements; nsegments counts the ids). */
size_t ag_segment_cloud_in_use(const ag_segment_cloud_result *r);

/* The spec that keeps segment it as it is through a rebuild (an element its host, its box
 * and its label's group). */
ag_segment_cloud_spec ag_segment_cloud_spec_of(const ag_segment_cloud_item *it);

/* A copy of r (every array its own). */
ag_status ag_segment_cloud_clone(const ag_segment_cloud_result *r,
                                 ag_segment_cloud_result **out, ag_error *err);

/* The label rule of §3.2 for two segments (of one kind): sorted box dimensions within 5 %


 * (plus slack metres) and point counts within 10 %. */
int ag_segment_cloud_similar(const ag_segment_cloud_item *a, const ag_segment_cloud_item *b,
                             double slack);

#endif
