/* GeoJSON building footprints → plan loops in a local metric frame.
 *
 * Reads a FeatureCollection (or one Feature) of Polygon / MultiPolygon geometries.
 * Coordinates in projected metres are kept, minus a file-wide origin (the rounded
 * centre of the bounding box) so that float output stays precise; lon/lat input
 * (a CRS84/EPSG:4326 "crs" member, or no "crs" and every coordinate within
 * ±180/±90) is projected to metres by a local equirectangular projection about the
 * centre, exact enough for building-sized shapes. Rings are oriented outer CCW, holes
 * CW; a closing duplicate corner is dropped. Features without a polygon are counted
 * in `skipped` with a reason, not fatal. */
#ifndef AG_FOOTPRINTS_H
#define AG_FOOTPRINTS_H

#include <jansson.h>
#include <stddef.h>

#include "../core/extrude/building.h"
#include "../core/extrude/style.h"
#include "../core/mesh.h"
#include "../core/status.h"

typedef struct {
    char *id;        /* feature id, else properties.id, else the 0-based index */
    double height;   /* from the height property, or 0 when absent */
    size_t nloops;
    size_t *sizes;   /* corners per loop */
    double **loops;  /* xy pairs per loop, local metres */
    char fixes[200]; /* what reading changed (rings reversed, parts dissolved), or empty */
} ag_footprint;

typedef struct {
    size_t n;
    ag_footprint *items;
    int lonlat;          /* the input was lon/lat and has been projected */
    double origin[2];    /* subtracted from projected coordinates (or lon/lat centre) */
    size_t skipped;      /* features without a usable polygon */
    char first_skip[160];
} ag_footprints;

typedef struct {
    const char *height_property; /* NULL: "height", then "building:height", "measuredHeight" */
    int lonlat;                  /* 0 auto, 1 force lon/lat, -1 force metres */
} ag_footprints_options;

ag_status ag_footprints_read_buffer(const char *data, size_t len, const ag_footprints_options *opt,
                                    ag_footprints **out, ag_error *err);
ag_status ag_footprints_read_file(const char *path, const ag_footprints_options *opt,
                                  ag_footprints **out, ag_error *err);
void ag_footprints_free(ag_footprints *f);

/* One footprint worth a line in the report. */
typedef struct {
    char *id;
    char reason[AG_ERROR_TEXT];
    ag_built built; /* what was built (fallbacks); AG_BUILT_NONE for failed */
    double moved;   /* a simplified footprint's boundary moved up to this far (m) */
} ag_footprint_issue;

typedef struct {
    size_t footprints;
    size_t succeeded;                   /* built as styled, and good */
    size_t nfallbacks;
    ag_footprint_issue *fallbacks;      /* built, but not as styled: reason and what instead */
    size_t nfailed;
    ag_footprint_issue *failed;         /* nothing built: refused by validation (the reason
                                         * names loop and edge) or not even a block */
    size_t nnot_watertight;
    ag_footprint_issue *not_watertight; /* built and kept although not good: none, since
                                         * every building is checked and falls back */
    size_t nfixed;
    ag_footprint_issue *fixed;          /* footprints validation cleaned (reason: the fixes) */
    size_t triangles;
    size_t events;                      /* events of all extrusions */
} ag_footprints_report;

void ag_footprints_report_free(ag_footprints_report *r);

/* Records footprint fp's outcome in the report (the batch runner's bookkeeping, shared
 * by the serial and the threaded batches). Returns AG_ERR_NOMEM or AG_OK. */
ag_status ag_footprints_report_add(ag_footprints_report *r, const ag_footprint *fp,
                                   const ag_building_result *b);
/* The same for a building named id whose reading made the fixes read_fixes (may be NULL or
 * ""): a building description of the service. */
ag_status ag_footprints_report_add_id(ag_footprints_report *r, const char *id,
                                      const char *read_fixes, const ag_building_result *b);

/* The report as JSON, one shape for `archgram extrude --report` and the service's job
 * result: {"footprints", "succeeded" (built as styled or described, and good),
 * "fallbacks": [{"id", "reason", "fallback": "simplified"|"flat"|"block", "moved" (m,
 * simplified only)}], "failed": [{"id", "reason"}], "not_watertight" (always 0: nothing
 * that is not good is kept), "not_watertight_items": [], "fixed": [{"id", "fixes"}],
 * "triangles", "events"}. NULL on out-of-memory. */
json_t *ag_footprints_report_json(const ag_footprints_report *r);

/* Extrudes every footprint with the style into m, one after another: one group (named
 * by the footprint id) and one component per footprint, each made good or reported
 * (ag_building_extrude: retried simplified, else a flat roof, else a block). opt may be
 * NULL. Fails only on out-of-memory or when the options' budget callback cancels. */
ag_status ag_footprints_extrude(const ag_footprints *f, const ag_style *style, ag_mesh *m,
                                ag_footprints_report *report, ag_error *err);
ag_status ag_footprints_extrude_with(const ag_footprints *f, const ag_style *style,
                                     const ag_extrude_options *opt, ag_mesh *m,
                                     ag_footprints_report *report, ag_error *err);

#endif
