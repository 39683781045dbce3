/* Component labeling: components that are the same surface up to translation, a turn about
 * the up axis and a reflection get one label, whatever their triangulation.
 *
 * Each component is seen in its own frame: turned about z by its orientation (the dominant
 * direction of its vertical faces, modulo 90 degrees: a window on a facade at 23 degrees is
 * seen square), centred on its box in that frame. Two whose orientations differ by a turn
 * that moves their plan corners by more than AG_PROC_LABEL_TURN_MOVE are set differently and
 * labelled apart. Candidates are bucketed by the extents of that box and compared under the
 * 4 quarter turns, then the 4 quarter turns of the mirror image: first by their triangle lists (every triangle of one lands on a triangle of the
 * other within the tolerance: copies), then, when the lists differ (another triangulation,
 * another vertex order, a copy re-triangulated after a turn), by their surfaces: every point
 * of each within the tolerance of the other, certified (surface.h). The oriented extents must
 * agree within the tolerance too, so windows a centimetre larger are another label.
 *
 * Within a label, variants are what the grammar derives from one terminal: a terminal is
 * placed on an instance's axis-aligned box with a quarter turn and scaled to it (grammar.h),
 * so a variant groups the members whose surface that placement reproduces within `share`
 * (see ag_labels.share). By default `share` is the label tolerance: near copies, copies
 * triangulated otherwise and windows on facades a fraction of a degree apart share one
 * terminal, and the fidelity measures what that costs. With exact_copies, variants are exact
 * copies (triangle lists equal within 1e-7 of the diagonal): every instance is derived as it
 * was. Mirror images share their label (mirror[c] says so) and get a variant of their own,
 * since a placement turns but never reflects. */
#ifndef AG_LABEL_H
#define AG_LABEL_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "units.h"

typedef struct {
    /* labels (and shared terminals): relative to the model diagonal; 0 = the default,
     * AG_PROC_LABEL_TOLERANCE of the diagonal but at most AG_PROC_LABEL_TOLERANCE_MAX metres
     * (in the model's unit, see units.h) */
    double tolerance;
    double metres_per_unit; /* the model's unit (units.h ag_units_named); 0 = decided from the
                             * content (metres or millimetres) */
    double exact;     /* exact copies: relative to the model diagonal; 0 = 1e-7 */
    int no_rotation;  /* non-zero: neither turns, orientations nor mirror images match */
    int exact_copies; /* non-zero: terminals are shared by exact copies only */
} ag_label_options;

typedef struct {
    size_t ncomponents;
    ag_box *box;         /* per component, world */
    uint32_t *ntris;     /* per component */
    int32_t *label;      /* per component (components without triangles: -1) */
    uint8_t *rot;        /* per component: quarter turns, in the oriented frames, from its
                            label's exemplar */
    uint8_t *mirror;     /* per component: a mirror image of its label's exemplar */
    double *turn;        /* per component: radians about +z from its label's exemplar (the
                            orientations' difference plus the quarter turns) */
    int32_t *variant;    /* per component: its terminal class (-1 without triangles) */
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
    double *variant_deviation;  /* per variant: the largest distance between a member and its
                                   placed terminal, as the labeling certified it */

    double diagonal;     /* of the model */
    ag_units units;      /* the model's length unit, as given or decided (units.h) */
    double tol;          /* absolute label tolerance */
    double exact;        /* absolute tolerance of exact copies: what the split tree, rules
                            and patterns compare with, so only shared terminals move surfaces */
    double share;        /* absolute variant tolerance: members of a variant share a terminal
                            (tol, or exact with exact_copies) */
    int exact_copies;
    size_t surface_checks; /* comparisons that went past the triangle lists */
} ag_labels;

ag_status ag_label_components(const ag_mesh *m, const ag_label_options *opt, ag_labels **out,
                              ag_error *err);
void ag_labels_free(ag_labels *l);

/* m's components grouped by their labels in L, each group named "L<label + 1>" as the
 * grammar export names its labels; components without a label in no group. In place: the
 * vertices and triangles stay as they are. AG_ERR_NOMEM when out of memory. */
ag_status ag_labels_name_groups(ag_mesh *m, const ag_labels *L);

/* Rotates (x, y) by k quarter turns counter-clockwise about +z. */
void ag_label_rotate(int k, double *x, double *y);

/* Matches triangle soups (9 doubles per triangle): every triangle of b must find a distinct
 * triangle of a with the same vertices in the same cyclic order within tol. Returns the
 * largest vertex distance over the matched pairs and sets *unmatched to the number of
 * triangles of b without a partner (then the return covers the matched ones only).
 * Returns a negative value when out of memory. */
double ag_label_match_triangles(const double *a, size_t na, const double *b, size_t nb,
                                double tol, size_t *unmatched);

/* Whether every triangle of b has a partner in a (ag_label_match_triangles), stopping at the
 * first that has none: 1 with *worst the largest vertex distance, 0 for a miss (*worst
 * untouched), -1 when out of memory. */
int ag_label_soups_match(const double *a, size_t na, const double *b, size_t nb, double tol,
                         double *worst);

/* Whether soups a and b are the same surface within tol (each within tol of the other,
 * certified; surface.h), through their triangle lists when those match. *deviation gets the
 * certified bound. Returns 1 for the same surface, 0 for not, -1 when out of memory. */
int ag_label_same_surface(const double *a, size_t na, const double *b, size_t nb, double tol,
                          double *deviation);

#endif
