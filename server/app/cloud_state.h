/* A point cloud model as the use cases that work on it see it (app/usecase_segment.h,
 * app/usecase_mark_template.h, and the point pipeline's stages after them): its points and
 * its current segmentation; what a new cloud model is made of; and the JSON that describes
 * a cloud and a segmentation (the model's stats, the logged report). */
#ifndef AG_CLOUD_STATE_H
#define AG_CLOUD_STATE_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/points/cloud.h"
#include "../core/points/segment_cloud.h"
#include "../core/status.h"

/* Clouds the service takes (uploads) and segments: larger ones are refused with
 * AG_ERR_TOO_LARGE before they are read (a LiDAR tile is cut per building first, `archgram
 * cut`). About 60 bytes a point are held while one is stored, about 300 while one is
 * segmented. */
#define AG_CLOUD_MAX_POINTS ((size_t)20000000)
#define AG_CLOUD_MAX_SEGMENT_POINTS ((size_t)10000000)

typedef struct {
    ag_cloud *cloud;             /* positions and normals (and properties, when asked for) */
    ag_segment_cloud_result *seg; /* the current segmentation, NULL when there is none */
    int had_normals;             /* the cloud had its normals when it was read */
} ag_cloud_state;

void ag_cloud_state_clear(ag_cloud_state *st);

/* A new point cloud model. */
typedef struct {
    const ag_cloud *cloud;
    const uint32_t *lod;       /* its level-of-detail order (core/points/lod.h) */
    const void *source;        /* the file as it came, or NULL */
    size_t source_len;
    const char *source_format; /* "ply", "las", "laz", "xyz" */
} ag_cloud_new;

/* What a step that changes a segmentation did, for the log and the model's figures. */
typedef struct {
    const char *kind;     /* "segment" (the job), "segment_roi", "mark_template" */
    const json_t *report; /* what the logged op carries as its "report" (borrowed) */
} ag_segment_outcome;

/* The stats of a cloud model: {"points", "offset", "scale"?, "bounds": {"min","max"},
 * "properties": [{"name","type"}], "normals", "positions", "segmented": false}. */
json_t *ag_cloud_state_stats(const ag_cloud *c, const char *positions_encoding);
/* A segmentation's figures: {"points", "segments", "planes", "clusters", "pieces", "labels",
 * "unsegmented", "diagonal", "spacing"} and, for a run, its thresholds (metres) and
 * "seconds" per stage (with_run). */
json_t *ag_cloud_state_segmentation(const ag_segment_cloud_result *r, int with_run);
/* stats (a cloud's) with a segmentation's figures: "segmented" and each figure of seg set
 * (seg NULL: "segmented": false and the figures removed). Returns stats. */
json_t *ag_cloud_state_stats_segmented(json_t *stats, const json_t *seg);

#endif
