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

#include <stddef.h>

#include "../core/extrude/style.h"
#include "../core/mesh.h"
#include "../core/status.h"

typedef struct {
    char *id;        /* feature id, else properties.id, else the 0-based index */
    double height;   /* from the height property, or 0 when absent */
    size_t nloops;
    size_t *sizes;   /* corners per loop */
    double **loops;  /* xy pairs per loop, local metres */
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

/* One footprint that failed or came out not watertight. */
typedef struct {
    char *id;
    char reason[200];
} ag_footprint_issue;

typedef struct {
    size_t footprints, succeeded;
    size_t nfailed;
    ag_footprint_issue *failed;        /* extrusion failed: nothing added to the mesh */
    size_t nnot_watertight;
    ag_footprint_issue *not_watertight; /* added, but with failing faces (listed in reason) */
    size_t triangles;
} ag_footprints_report;

void ag_footprints_report_free(ag_footprints_report *r);

/* Extrudes every footprint with the style into m: one group (named by the footprint id)
 * and one component per footprint. A footprint that fails is reported and skipped; the
 * batch goes on. Fails only on out-of-memory. */
ag_status ag_footprints_extrude(const ag_footprints *f, const ag_style *style, ag_mesh *m,
                                ag_footprints_report *report, ag_error *err);

#endif
