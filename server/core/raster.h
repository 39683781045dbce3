/* A small software rasterizer for thumbnails (the parts library's pictures): a mesh drawn
 * orthographically, flat shaded, with a depth buffer, into an RGBA image.
 *
 * Written here rather than taken from a library: Debian has no small C rasterizer without a
 * GPU context (OSMesa drags in Mesa), and a thumbnail needs nothing but triangles, a depth
 * test and one light. The view looks along `dir` (towards the scene) with `up` as the
 * image's up direction; the mesh's bounds are fitted into the image with a margin, keeping
 * its proportions. Triangles are shaded by |n . l| with the light coming from over the
 * viewer's left shoulder, both faces alike. Pixels sample 2 x 2 points each, so edges are
 * smoothed. */
#ifndef AG_RASTER_H
#define AG_RASTER_H

#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "status.h"

#define AG_RASTER_MAX_SIDE 1024

typedef struct {
    unsigned width, height;
    uint8_t *rgba; /* width * height * 4, rows top to bottom; malloc'd */
} ag_raster_image;

typedef struct {
    double dir[3];           /* view direction, towards the scene (need not be unit) */
    double up[3];            /* the image's up; not parallel to dir */
    uint8_t background[4];   /* RGBA of empty pixels (alpha 0 gives a transparent picture) */
    double margin;           /* fraction of the image left free on each side (0..0.4) */
    /* per group of the mesh, its RGB (ngroups entries); NULL, or a component without group:
     * `colour` */
    const uint8_t (*group_rgb)[3];
    size_t ngroups;
    uint8_t colour[3];
} ag_raster_view;

/* Draws m into a new width x height image (1..AG_RASTER_MAX_SIDE each). An empty mesh gives
 * the background alone. AG_ERR_INVALID for a bad size or a degenerate view. */
ag_status ag_raster_mesh(const ag_mesh *m, const ag_raster_view *view, unsigned width,
                         unsigned height, ag_raster_image *out, ag_error *err);
void ag_raster_image_clear(ag_raster_image *img);

/* Where a world point lands in the image ag_raster_mesh(m, view, ...) draws: pixel x, y
 * (x to the right, y down, continuous coordinates). For tests and for overlays. */
void ag_raster_project(const ag_mesh *m, const ag_raster_view *view, unsigned width,
                       unsigned height, const double p[3], double *x, double *y);

#endif
