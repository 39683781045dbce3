/* The tolerances and thresholds of core, in one place, each with what it means and why it has
 * its value.
 *
 * Lengths are metres. A value marked "relative" is a fraction of the model's bounding-box
 * diagonal (so a 1 km site and a 10 cm part keep the same relative precision); where a model
 * has no diagonal (a single point) the code takes 1 m instead. Limits on work (counts, cells,
 * triangles) are not here: they stand next to the code they bound. */
#ifndef AG_TOLERANCE_H
#define AG_TOLERANCE_H

/* ---- proceduralization (core/proc) ------------------------------------------------------ */

/* Segment: vertices within this (relative) are one point when finding connected pieces, so
 * files that repeat vertices per polygon still connect. Far below any modelled detail, and
 * above the rounding of coordinates that were stored with UTM-sized offsets. */
#define AG_PROC_WELD 1e-9
/* Segment, planar fallback: neighbouring triangles whose normals differ by less than this
 * many degrees grow one region (a single-piece mesh split into its flat faces). */
#define AG_PROC_PLANAR_DEGREES 1.0
/* Segment, planar fallback: a triangle with a vertex farther than this (relative) from the
 * region's seed plane starts a region of its own: a region is one plane, not one direction. */
#define AG_PROC_PLANE_DISTANCE 1e-4
/* Segment: piece box sizes are rounded to steps of this (relative) to find twins, identical
 * loose parts (columns, tiles) that tell a group of loose parts from one object. */
#define AG_PROC_TWIN_STEP 1e-6
/* Segment: a group with at least this many pieces may be split into them. */
#define AG_PROC_SPLIT_MIN_PIECES 4

/* Label: variants (shapes equal within this, relative) are one label. 1e-4 of a 30 m
 * building is 3 mm: near-exact copies a person sees as one element (windows modelled by hand
 * a millimetre apart) share a label. */
#define AG_PROC_LABEL_TOLERANCE 1e-4
/* Label: components equal within this (relative) are one variant, i.e. one terminal; it is
 * the precision derivation reproduces, 1e-7 of the diagonal (3 µm on a 30 m building). */
#define AG_PROC_LABEL_EXACT 1e-7
/* A positive stand-in for a tolerance or size of 0 where one divides by it (a cell size, a
 * scale): near the bottom of the double range, so building-sized values divided by it stay
 * finite. */
#define AG_PROC_TINY 1e-300

/* Split tree: box faces within this (relative) coincide: 30 nm on a 30 m building, far below
 * modelled detail, and above the rounding of UTM-sized coordinates (about 1e-9 m). */
#define AG_PROC_COINCIDENT 1e-9
/* Split tree: box extents are floored to this (relative) when components are ordered by
 * volume, so flat walls (zero thickness) sort by their area instead of all at 0. */
#define AG_PROC_ORDER_MIN_EXTENT 1e-3

/* Patterns: a second lattice vector must lie at least this many matching tolerances off the
 * first one's line: instances of one row, each within a tolerance of its place, differ by up
 * to two, so a jittered row is not taken for a two-dimensional lattice. */
#define AG_PROC_LATTICE_OFF_LINE 4

/* Fidelity: the default tolerance (relative) for matching a derived mesh to its input. */
#define AG_PROC_FIDELITY 1e-5
/* Verify: derivation must reproduce the input within this many label tolerances. */
#define AG_PROC_VERIFY_FACTOR 10

/* ---- editing (core/edit) ----------------------------------------------------------------- */

/* Resize: a node stretched past this on an axis splits into two copies of its subtree, and a
 * pattern whose cells pass it doubles its count there. Each half is then at least 0.9 of the
 * original size, close to it and far above the join ratio, so a split never joins back. */
#define AG_EDIT_SPLIT_RATIO 1.8
/* The counterpart of the split ratio (1 / 1.8): a pattern stretched then squeezed back
 * returns to its count, and a cell squeezed to half its size joins with its neighbour. */
#define AG_EDIT_JOIN_RATIO (1.0 / 1.8)

/* Coincidence (relative) where a tree gives none (a tree without eps, the sibling join's
 * span test): the split tree's own AG_PROC_COINCIDENT, so edits and proceduralization agree
 * on what touches. */
#define AG_EDIT_COINCIDENT AG_PROC_COINCIDENT
/* A split plane must lie this many coincidence tolerances inside the box, so both halves keep
 * a size the tree can tell from a face coincidence. */
#define AG_EDIT_SPLIT_MARGIN 10
/* An extent (metres) at or below this is flat: it has no size to scale by or to take a ratio
 * of (a scale of 1 is used). Far below the coincidence tolerance of any real model. */
#define AG_EDIT_FLAT 1e-12
/* A pattern's cell-to-period ratio below this cannot be kept (its cells have vanished). */
#define AG_EDIT_MIN_RATIO 1e-9

/* Attachment weights of the resize least squares (see attach.h): a ratio along an edge or in
 * a plane is what a person sees, so it counts fully; a volume overlap is the least visible;
 * an element's own size matters more than where it sits; the position term only keeps the
 * system definite and lies far below every other term. Largest / smallest stays far below
 * 1e5 so the normal equations keep their precision. */
#define AG_EDIT_WEIGHT_RATIO 1.0
#define AG_EDIT_WEIGHT_VOLUME 0.3
#define AG_EDIT_WEIGHT_SIZE 3.0
#define AG_EDIT_WEIGHT_POSITION 1e-3

/* ---- point clouds (core/points) ---------------------------------------------------------- */

/* Resize of a point model: a node stretched past this splits in two, a pattern's cells double
 * (the paper's 1.5 for point clouds: a stretched point set thins out sooner than a mesh). */
#define AG_POINTS_SPLIT_RATIO 1.5
/* ... but not on an axis thinner than this share of the node's largest extent: a wall's box
 * has the thickness of its points (and of its windows' reveals), and a facade stretched along
 * a side wall's thickness moves that wall, it does not make two walls of it. */
#define AG_POINTS_THIN_SHARE 0.1
/* Repetition (§3.2): template steps are this share of the template's size on each axis. */
#define AG_POINTS_TEMPLATE_STEP 0.1
/* The label rule (§3.2): box dimensions within this share, point counts within this share. */
#define AG_POINTS_LABEL_DIMS 0.05
#define AG_POINTS_LABEL_COUNT 0.10

/* ---- extrusion (core/extrude) ------------------------------------------------------------
 * The sweep's tolerances (delta1..delta3, parallel, same slope, and their scaling with the
 * plan's extent) live in core/extrude/tolerance.h for now and move here. */

#endif
