/* Where a grammar statement puts what it applies (grammar.h, "Applying"): the frame that maps
 * a rule's or terminal's local box onto a box of its parent, and the cells of a subdivide or
 * repeat pattern. Derivation (grammar.c) places with these. */
#ifndef AG_GFRAME_H
#define AG_GFRAME_H

#include <stdint.h>

#include "../mesh.h"
#include "grammar.h"

/* y = M x + t: quarter turns about z and per-axis scales, composed. */
typedef struct {
    double M[3][3];
    double t[3];
} ag_gframe;

extern const ag_gframe ag_gframe_identity;

void ag_gframe_apply(const ag_gframe *f, const double x[3], double y[3]);
/* The frame that maps local box [0, S] turned by k quarter turns about its centre and scaled
 * per axis onto box B, composed after F. */
ag_gframe ag_gframe_place(const ag_gframe *F, const double S[3], int k, const ag_box *B);

/* The cells of a pattern statement (s->subdivide != 0) in box B: cell (i, j, k) has its min
 * corner at origin + i v[0] + j v[1] + k v[2] and extent size. */
typedef struct {
    double v[3][3];
    double origin[3];
    double size[3];
} ag_gframe_cells;

void ag_gframe_cells_of(const ag_gstmt *s, const ag_box *B, ag_gframe_cells *c);
ag_box ag_gframe_cell(const ag_gframe_cells *c, uint32_t i, uint32_t j, uint32_t k);

#endif
