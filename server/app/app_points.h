/* What the REST layer reads of point cloud models, finished: the points as binary PLY and a
 * budget of them as GLB (app/app_query.h has the rest of the reads). Each is read in one
 * snapshot of the store, so points and segmentation are of one version, and comes with a
 * strong ETag of what it shows. */
#ifndef AG_APP_POINTS_H
#define AG_APP_POINTS_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "app_query.h"

#define AG_POINTS_GLB_DEFAULT_BUDGET ((size_t)1000000)

/* GET …/derived.ply: the cloud a proceduralized (and edited) cloud's grammar derives
 * (core/points/pointmodel.h: every placement's terminal points, the density kept where a
 * placement stretches), binary little-endian PLY as points.ply writes it, with normals, every
 * terminal property, int `label` (terminal) and `segment` (placement). AG_ERR_CONFLICT for a
 * model that is not a point cloud, AG_ERR_NOT_PROCEDURALIZED without a grammar. The ETag
 * names the model's grammar state and the budget; fresh as for ag_app_query_glb. A
 * derivation past AG_CLOUD_MAX_POINTS (app/cloud_state.h) is refused with AG_ERR_TOO_LARGE.
 * budget > 0 keeps at most that many points, every k-th of the derivation (placement by
 * placement, so each keeps its share; a viewer's point budget); 0 keeps them all. */
ag_status ag_app_points_derived_ply(ag_app *app, int64_t id, size_t budget,
                                    int (*fresh)(void *user, const char *etag), void *user,
                                    ag_app_bytes *out, ag_error *err);

/* GET …/points.ply: every point in input order with every property, binary little-endian,
 * float positions with a `comment offset X Y Z` line (absolute = position + offset), normals
 * when the cloud has them, and int segment, label and piece once it is segmented.
 * AG_ERR_NOT_FOUND for a model that is not a point cloud. fresh as for ag_app_query_glb. */
ag_status ag_app_points_ply(ag_app *app, int64_t id, int (*fresh)(void *user, const char *etag),
                            void *user, ag_app_bytes *out, ag_error *err);

/* GET …/points.glb?budget=N: the first min(N, points) points of the cloud's level-of-detail
 * order (an even subsample; the same N gives the same points) as glTF POINTS
 * (io/points_glb.h) with COLOR_0 from the cloud's red, green and blue, and float attributes
 * _SEGMENT and _LABEL (-1: none) once segmented and _CLASSIFICATION when the cloud has one;
 * the node's extras: {"model", "points", "shown", "budget", "offset", "segmented",
 * "segments", "labels"}. budget 0 = AG_POINTS_GLB_DEFAULT_BUDGET. */
ag_status ag_app_points_glb(ag_app *app, int64_t id, size_t budget,
                            int (*fresh)(void *user, const char *etag), void *user,
                            ag_app_bytes *out, ag_error *err);

#endif
