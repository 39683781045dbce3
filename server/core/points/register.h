/* Registration of a member point set onto a base (the ICP of the consensus models, §4.1).
 *
 * The members of one label are copies of one element up to a translation and a quarter turn
 * about the vertical axis (the turns the split tree and the grammar express): the register
 * samples the turns whose box dimensions fit (x and y swapped for odd turns), and for each a
 * few starting offsets (the box centres, mins and maxes aligned, and the caller's own: a
 * template offset); from each it runs point-to-plane ICP for the translation on a subsample
 * of the member (the base's normals, a little point-to-point weight so that a flat member
 * stays determined in its plane), with a pairing distance that shrinks from a share of the
 * member's size to a few point spacings. The best run (inliers first, then the residual)
 * wins. Cost: turns x starts x iterations x samples nearest-neighbour queries on the base's
 * tree, independent of the member's size. */
#ifndef AG_REGISTER_H
#define AG_REGISTER_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../base/kdtree.h"
#include "../status.h"

/* The base: positions, unit normals (3 per point) and a tree over the positions. */
typedef struct {
    const double *xyz;
    const float *normals;
    size_t n;
    const ag_kdtree *tree;
    ag_box box;
} ag_register_base;

typedef struct {
    unsigned samples;    /* member points used; 0 = 256 */
    unsigned iterations; /* per start; 0 = 24 */
    double spacing;      /* point spacing of the data (metres, > 0): the final pairing distance
                          * is 3 spacings */
    unsigned turns;      /* bit k allows k quarter turns; 0 = those the boxes allow */
    int has_offset;      /* offset: a starting translation of the caller's (box min to box min,
                          * after the turn about the member box's centre) */
    double offset[3];
} ag_register_options;

/* base = R_turn (x - pivot) + pivot + t for member points x, pivot the member box's centre. */
typedef struct {
    int turn;
    double pivot[3];
    double t[3];
    double rms;     /* point-to-plane residual of the final pairs, metres */
    double inliers; /* share of the samples paired at the final distance */
} ag_register_result;

/* Registers the member points idx[0..m) of xyz (member box `box`). AG_ERR_INVALID for an
 * empty member or base. */
ag_status ag_register_member(const ag_register_base *base, const double *xyz,
                             const uint32_t *idx, size_t m, const ag_box *box,
                             const ag_register_options *o, ag_register_result *res,
                             ag_error *err);

/* x turned by k quarter turns about +z through pivot, plus t. */
void ag_register_apply(const ag_register_result *r, const double x[3], double y[3]);

#endif
