/* Generated buildings whose structure is known, for tests and benchmarks.
 *
 * A rectangular block: a wall slab per facade, a roof slab, and a grid of identical windows
 * set into each wall. The front facade faces -y; the right, back and left facades carry the
 * same window turned by 90, 180 and 270 degrees about z. A window is a set of boxes (frame,
 * off-centre mullion, glass set back, sill) so that it is not symmetric under any turn.
 * One group per wall, per window, for the roof and for the annex (a small non-repeating
 * lean-to behind the block). */
#ifndef AG_GEN_FACADE_H
#define AG_GEN_FACADE_H

#include "mesh.h"
#include "status.h"

typedef struct {
    unsigned cols, rows;       /* windows per row / rows on the front and back; 0 = 6 x 4 */
    unsigned side_cols;        /* windows per row on the left/right facades; 0 = none */
    int back;                  /* windows on the back facade too */
    int left;                  /* windows on the left facade too (needs side_cols) */
    int annex;                 /* add the non-repeating annex */
    unsigned bars;             /* extra horizontal glazing bars per window (more triangles) */
    int no_groups;             /* no groups: components are then connected pieces */
    double step_x, step_z;     /* window spacing; 0 = 2.5 and 3.2 metres */
} ag_gen_facade_options;

ag_status ag_gen_facade(const ag_gen_facade_options *opt, ag_mesh **out, ag_error *err);

/* Triangles of one window for the given options (for sizing benchmarks). */
size_t ag_gen_facade_window_triangles(const ag_gen_facade_options *opt);

#endif
