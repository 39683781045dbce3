/* The point cloud tables (migration 0009): a pointcloud model's points in column chunks
 * (io/cloudblob.h encodes them), its level-of-detail order, its segmentations and the
 * segmentation of each kept model state.
 *
 * Writes run inside the caller's transaction (ag_db_begin); reads may run outside one, but a
 * reader that needs the points and the segmentation of one version reads them in one
 * (ag_pointclouds_read_begin). */
#ifndef AG_POINTCLOUDS_H
#define AG_POINTCLOUDS_H

#include <stddef.h>
#include <stdint.h>

#include "../core/points/cloud.h"
#include "../core/points/segment_cloud.h"
#include "../io/cloudblob.h"
#include "db.h"

#define AG_POINTCLOUDS_CHUNK ((size_t)1 << 20) /* points per stored chunk */

/* Column numbers of pointcloud_columns. */
enum { AG_POINTCLOUDS_COL_POSITIONS = 0, AG_POINTCLOUDS_COL_NORMALS = 1,
       AG_POINTCLOUDS_COL_ORDER = 2, AG_POINTCLOUDS_COL_PROPERTY = 3 };

typedef struct {
    char name[AG_CLOUD_NAME_MAX];
    ag_scalar_type type;
} ag_pointcloud_property;

typedef struct {
    int64_t model;
    size_t points, chunk_points;
    double offset[3], scale[3];
    ag_cloudblob_positions positions;
    int normals;
    size_t nprops;
    ag_pointcloud_property props[AG_CLOUD_MAX_PROPERTIES];
    int64_t segmentation; /* the current one; 0: not segmented */
} ag_pointcloud_info;

/* Stores c (its positions, normals, properties and the level-of-detail order lod of c->n
 * indices) as the points of model; chunk_points 0 = AG_POINTCLOUDS_CHUNK. */
ag_status ag_pointclouds_put(ag_db *db, int64_t model, const ag_cloud *c, const uint32_t *lod,
                             size_t chunk_points, ag_error *err);

/* AG_ERR_NOT_FOUND when model has no points (not a point cloud, or no such model). */
ag_status ag_pointclouds_info(ag_db *db, int64_t model, ag_pointcloud_info *info,
                              ag_error *err);

/* What ag_pointclouds_load reads. */
enum {
    AG_POINTCLOUDS_POSITIONS = 1u << 0,
    AG_POINTCLOUDS_NORMALS = 1u << 1,    /* when the cloud has them */
    AG_POINTCLOUDS_PROPERTIES = 1u << 2, /* every property, or those named in `only` */
};
/* The points as a cloud (offset and scale set). only: NULL-terminated property names to
 * read (those the cloud has), or NULL for all. */
ag_status ag_pointclouds_load(ag_db *db, const ag_pointcloud_info *info, unsigned what,
                              const char *const *only, ag_cloud **out, ag_error *err);
/* The first count entries of the level-of-detail order. */
ag_status ag_pointclouds_load_order(ag_db *db, const ag_pointcloud_info *info, size_t count,
                                    uint32_t *order, ag_error *err);
/* Adds normals to a cloud stored without (computed by its first segmentation). */
ag_status ag_pointclouds_put_normals(ag_db *db, int64_t model, const ag_cloud *c,
                                     ag_error *err);

/* A segmentation as stored. */
typedef struct {
    int64_t id;
    int64_t version; /* the model version that made it */
    size_t n;
    int32_t *segment, *label, *piece; /* n each, malloc'd */
    uint8_t *kind; /* nsegments (each id's ag_segment_cloud_kind), malloc'd; NULL for one
                    * stored before migration 0012: the ids below nplanes are planes */
    size_t nsegments, nplanes, npieces, nlabels;

    double spacing;
    char *summary_json; /* malloc'd */
} ag_pointcloud_segmentation;

void ag_pointcloud_segmentation_clear(ag_pointcloud_segmentation *s);

/* Stores r as the segmentation made by `version` and makes it the model's current one;
 * summary_json (NULL = "{}") describes it. *id (may be NULL) gets its id. */
ag_status ag_pointclouds_put_segmentation(ag_db *db, int64_t model, int64_t version,
                                          const ag_segment_cloud_result *r,
                                          const char *summary_json, int64_t *id, ag_error *err);
/* The model's current segmentation (info->segmentation); AG_ERR_NOT_FOUND when it has none.
 * ids 0 reads only the metadata (segment, label and piece stay NULL). */
ag_status ag_pointclouds_get_segmentation(ag_db *db, const ag_pointcloud_info *info, int ids,
                                          ag_pointcloud_segmentation *out, ag_error *err);
/* Drops the current segmentation (kept states keep theirs). */
ag_status ag_pointclouds_clear_segmentation(ag_db *db, int64_t model, ag_error *err);

/* Called with the model states (store/states.h): keeps the model's current segmentation as
 * that of `version` (a version kept before is left alone), and makes the segmentation kept
 * for `kept_version` current again. No-ops for models that are not point clouds. */
ag_status ag_pointclouds_states_keep(ag_db *db, int64_t model, int64_t version, ag_error *err);
ag_status ag_pointclouds_states_restore(ag_db *db, int64_t model, int64_t kept_version,
                                        ag_error *err);

/* Releases the PLY terminals of a proceduralized cloud that no kept version names: neither
 * the model's grammar nor the grammar of any of its kept states (store/states.h) holds the
 * terminal's quoted path. Terminal paths name their content, so a terminal of an earlier
 * proceduralization or edit stays exactly while a version that undo or restore can come back
 * to needs it. Inside the caller's transaction (the save that wrote the new version).
 * *released (optional): how many went. The work is bounded by the model's terminals times
 * the bytes of its kept grammars; a terminal the current grammar names is kept at the first
 * test, so only the ones it dropped are looked for in the states. */
ag_status ag_pointclouds_release_terminals(ag_db *db, int64_t model, size_t *released,
                                           ag_error *err);

/* A read of points and segmentation that sees one version: BEGIN (deferred) / COMMIT. */
ag_status ag_pointclouds_read_begin(ag_db *db, ag_error *err);
void ag_pointclouds_read_end(ag_db *db);

#endif
