/* Attachments between two adjacent split-tree boxes, the equations of a structure-preserving
 * resize.
 *
 * A box has six coordinates: a = min (0..2) and b = max (3..5). Per axis, two boxes either
 * share a coordinate (within eps: a face contact or an aligned face — a hard equality, the
 * corner attachment when it holds on every axis where they do not overlap) or overlap with a
 * positive length. Overlaps keep a ratio measured against the boxes' extents, so that the
 * overlap scales with them while each box keeps its own size where nothing else changes it:
 * a box S lying within the longer box L on that axis keeps the relative place of its centre,
 *   (a_S + b_S) / 2 - a_L = k (b_L - a_L);
 * a partial overlap keeps its share of the shorter box S (S sticking out below L, else above),
 *   b_S - a_L = k (b_S - a_S)   or   b_L - a_S = k (b_S - a_S).
 * The number of overlapping axes names the soft
 * attachment: one an edge, two a plane, three a volume (the least visible one, weighted
 * lowest). Size and position terms keep a node's extent and place where nothing else does. */
#ifndef AG_ATTACH_H
#define AG_ATTACH_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"

typedef enum {
    AG_ATTACH_GROUND = 0, /* hard: min z on the ground */
    AG_ATTACH_CORNER = 1, /* hard: a coordinate of i equals one of j */
    AG_ATTACH_EDGE = 2,   /* soft ratio, one overlapping axis */
    AG_ATTACH_PLANE = 3,  /* soft ratio, two overlapping axes */
    AG_ATTACH_VOLUME = 4, /* soft ratio, three overlapping axes */
    AG_ATTACH_SIZE = 5,   /* soft: keep b - a */
    AG_ATTACH_POSITION = 6, /* soft: keep a coordinate */
    AG_ATTACH_COUNT
} ag_attach_type;

typedef struct {
    uint8_t type;   /* ag_attach_type */
    uint8_t ci, cj; /* corner: coordinates 0..5 of box i and box j; ratio: ci = the axis */
    uint8_t swap;   /* ratio: box j is L, the longer one */
    uint8_t form;   /* ratio: 0 S within L, 1 S sticks out below L, 2 S sticks out above */
    double k;       /* ratio: the kept ratio; corner: c_i - c_j originally (within eps) */
} ag_attach;

/* Attachments between boxes i and j (at most 12) into out; returns how many: shared
 * coordinates (corner) and one ratio per overlapping axis without a shared end. */
size_t ag_attach_detect(const ag_box *bi, const ag_box *bj, double eps, ag_attach out[12]);

/* Weight of a soft attachment type (hard ones: 0, they are eliminated, not weighted). The
 * ratio between the largest and the smallest weight stays far below 1e5. */
double ag_attach_weight(int type);

const char *ag_attach_type_name(int type);

#endif
