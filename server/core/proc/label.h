/* Component labeling: components that are the same shape up to translation and a quarter
 * turn about z get one label.
 *
 * Candidates are bucketed by triangle count and height, then compared by box dimensions
 * (x/y swapped for odd quarter turns) and finally by their whole geometry: every triangle of
 * one must land on a triangle of the other within the tolerance after the rotation about the
 * box centre. That full comparison is stricter than a convex-hull comparison, and it is what
 * lets every component of a label be derived from one terminal.
 *
 * Two tolerances: components equal within `exact` are one variant (one terminal, and what
 * rules and patterns compare); variants equal within `tolerance` are one label (near-exact
 * copies, e.g. windows modelled by hand a millimetre apart). Derivation is then exact to
 * `exact` while labels still group what a person sees as the same element. */
#ifndef AG_LABEL_H
#define AG_LABEL_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"

typedef struct {
    double tolerance; /* labels: relative to the model diagonal; 0 = 1e-4 */
    double exact;     /* variants: relative to the model diagonal; 0 = 1e-7 */
    int no_rotation;  /* non-zero: do not match quarter turns */
} ag_label_options;

typedef struct {
    size_t ncomponents;
    ag_box *box;         /* per component, world */
    uint32_t *ntris;     /* per component */
    int32_t *label;      /* per component (components without triangles: -1) */
    uint8_t *rot;        /* per component: quarter turns about +z from its label's exemplar */
    int32_t *variant;    /* per component: exact class (-1 without triangles) */
    uint8_t *vrot;       /* per component: quarter turns from its variant's exemplar */
    uint32_t *tri_start; /* ncomponents + 1 offsets into tris */
    uint32_t *tris;      /* triangles grouped by component, input order */

    size_t nlabels;
    uint32_t *exemplar;  /* per label: the first component with the label */
    uint32_t *count;     /* per label: components */

    size_t nvariants;
    uint32_t *variant_exemplar; /* per variant: the first component */
    uint32_t *variant_count;    /* per variant: components */
    int32_t *variant_label;     /* per variant: its label */

    double diagonal;     /* of the model */
    double tol;          /* absolute label tolerance */
    double exact;        /* absolute variant tolerance */
} ag_labels;

ag_status ag_label_components(const ag_mesh *m, const ag_label_options *opt, ag_labels **out,
                              ag_error *err);
void ag_labels_free(ag_labels *l);

/* Rotates (x, y) by k quarter turns counter-clockwise about +z. */
void ag_label_rotate(int k, double *x, double *y);

/* Matches triangle soups (9 doubles per triangle): every triangle of b must find a distinct
 * triangle of a with the same vertices in the same cyclic order within tol. Returns the
 * largest vertex distance over the matched pairs and sets *unmatched to the number of
 * triangles of b without a partner (then the return covers the matched ones only).
 * Returns a negative value when out of memory. */
double ag_label_match_triangles(const double *a, size_t na, const double *b, size_t nb,
                                double tol, size_t *unmatched);

#endif
