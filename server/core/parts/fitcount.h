/* Counts (paper §4.2, and what resize does, core/edit/resize.h step 4): a part fitted into a
 * box of another length holds more or fewer of its repeated columns, each at the part's own
 * element size and period, rather than the same columns squeezed or stretched.
 *
 * Along an axis whose length changes, the body's period is the step of its patterns along
 * that axis (the most cells). The applications then fall into columns of that period: a
 * pattern stepping by the period spans columns, an application (or a pattern) shorter than the
 * period lies in the column of its min, anything longer spans the body (a wall). The columns
 * are a lattice when at least three of them, and at least half, hold the same content and that
 * content is not thin along the axis (a row of mullions or posts is spaced out by the solve,
 * never added: AG_EDIT_THIN_RATIO as resize). The new count keeps the columns' density (the old
 * count times the stretch, rounded, fewer while they would not fit); new column j' copies old
 * column round(j' (n - 1) / (k - 1)), so both end columns stay; the block of columns keeps its
 * margins' proportion; what spans the body stretches with it. The axis is then fitted: the
 * proportions solve (fit.h) has nothing left to do on it. */
#ifndef AG_FITCOUNT_H
#define AG_FITCOUNT_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../proc/grammar.h"
#include "../status.h"

/* One application of a body: its statement (a shallow copy: names borrowed from the body; a
 * pattern's counts, steps and vectors its own) on the box of its node, in the body's frame. */
typedef struct {
    ag_gstmt s;
    ag_box box;
} ag_fit_item;

typedef struct {
    ag_fit_item *v;
    size_t n, cap;
} ag_fit_items;

ag_status ag_fit_items_push(ag_fit_items *it, const ag_fit_item *x);

/* Along axis a, the body of items (in a box of size S, min corner 0) re-laid for the length
 * `len`: on a lattice, *items holds the new columns, S[a] becomes len and *cols gets the old and
 * new column counts; otherwise nothing changes and cols is {0, 0}. New columns that would hold
 * more than AG_FIT_MAX_ELEMENTS (fit.h) nodes are refused before they are made:
 * AG_ERR_TOO_LARGE. */
ag_status ag_fit_count_axis(ag_fit_items *items, double S[3], int a, double len, double tol,
                            unsigned cols[2], ag_error *err);

#endif
