/* The extrude use case, over a workspace (app/workspace.h): a building description (plan JSON,
 * schema/plan.md), a list of them ({"buildings": [{"id", "plan"}]}, as GET …/plan gives for a
 * batch) or a GeoJSON FeatureCollection of footprints turned into plans by a style → every
 * building extruded on every core (app/extrude_batch.h; progress per building, stage
 * "extrude"), each under the service's budget (app/extrusion.h) and cancelled with the job:
 * a building whose result is not good (not a closed 2-manifold within reach of its
 * footprint) is retried on a simplified footprint (GeoJSON), then falls back to a flat roof,
 * then to a block; one that validation refuses is reported failed and the batch goes on →
 * saved as a new extrusion model with the report of `archgram extrude --report`
 * (ag_footprints_report_json: "footprints", "succeeded", "fallbacks": [{"id", "reason",
 * "fallback", "moved"}], "failed": [{"id", "reason"}], "not_watertight" (0),
 * "not_watertight_items", "fixed", "triangles", "events"; plus "seconds" and
 * "skipped_features"). Input that cannot be read, or a batch where nothing could be built,
 * fails the use case with the reason and saves nothing. The extrude job runs it on the
 * store. */
#ifndef AG_USECASE_EXTRUDE_H
#define AG_USECASE_EXTRUDE_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/extrude/plan.h"
#include "extrusion.h"
#include "workspace.h"

typedef struct {
    const char *data;            /* the input JSON text */
    size_t len;
    const char *name;            /* the model's name (and a single plan's building id) */
    const char *format;          /* "plan" | "buildings" | "geojson" | NULL: sniffed */
    const char *style;           /* GeoJSON: a built-in style name; NULL = hip */
    const char *height_property; /* GeoJSON: the feature property with the height, or NULL */
    int64_t seed;                /* < 0: the style's own */
    int lonlat;                  /* 1 lon/lat, -1 metres, 0 decided by the coordinates */
} ag_extrude_input;

/* One building of the batch, in mesh order. */
typedef struct {
    char *id;        /* footprint id: the mesh group's name */
    char *plan_json; /* the description as stored; NULL when none could be made */
    ag_plan *plan;   /* NULL when none could be made (reason in built) */
    ag_extrusion_built built;
} ag_extrude_building;

/* (struct ag_extrude_batch, the name workspaces know it by; ag_extrude_batch() is the
 * batch runner of app/extrude_batch.h) */
typedef struct ag_extrude_batch {
    ag_extrude_building *items;
    size_t n;
    const char *format; /* "plan" | "buildings" | "geojson" */
    json_t *meta;       /* format, and for GeoJSON style, origin, lonlat, skipped features */
    size_t skipped;
} ag_extrusion_batch;

void ag_usecase_extrude_batch_clear(ag_extrusion_batch *b);

/* *model gets the new model's id. */
ag_status ag_usecase_extrude_run(ag_workspace *ws, const ag_extrude_input *in, int64_t *model,
                                 ag_error *err);

#endif
