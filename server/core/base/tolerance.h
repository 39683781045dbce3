/* The tolerances and thresholds of core, in one place, each with what it means and why it has
 * its value.
 *
 * Lengths are metres. A value marked "relative" is a fraction of the model's bounding-box
 * diagonal (so a 1 km site and a 10 cm part keep the same relative precision); where a model
 * has no diagonal (a single point) the code takes 1 m instead. Limits on work (counts, cells,
 * triangles) are not here: they stand next to the code they bound. */
#ifndef AG_TOLERANCE_H
#define AG_TOLERANCE_H

#include <float.h>
#include <math.h>

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

/* Label: components whose surfaces are equal within this (relative; see label.h) share a
 * label and, by default, a terminal. 2e-4 of a 20 m building is 4 mm: near-exact copies a
 * person sees as one element (windows modelled by hand a few millimetres apart, or set into
 * facades a fraction of a degree apart) share a label; a window a centimetre larger does
 * not. The default is capped by AG_PROC_LABEL_TOLERANCE_MAX metres, in the model's unit
 * (core/proc/units.h: a millimetre model's cap is 5 units), so sharing a terminal never moves
 * a surface by more than that on large sites (fidelity reports what it did move). */
#define AG_PROC_LABEL_TOLERANCE 2e-4
#define AG_PROC_LABEL_TOLERANCE_MAX 0.005
/* Label: copies whose orientations about the up axis differ (beyond quarter turns) share a
 * label when that turn moves their plan corners by at most this (metres, in the model's unit
 * as the cap above): a facade a degree
 * or two off square holds the same windows; a window on a facade turned further is set
 * otherwise and labelled apart (no terminal could serve both anyway). */
#define AG_PROC_LABEL_TURN_MOVE 0.02
/* Label, exact copies (--exact): components equal within this (relative) share a terminal;
 * it is the precision derivation then reproduces, 1e-7 of the diagonal (3 µm on a 30 m
 * building). */
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
/* Fidelity: surfaces are compared at the tolerance divided by this first, then at the
 * tolerance: a certified bound is only as fine as the tolerance it was proven at, so a close
 * match is proven at the finer one. */
#define AG_PROC_FIDELITY_REFINE 10.0
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

/* Resize: an axis along which an element is thinner than this share of its longest extent is
 * a thin axis (a wall's thickness, a slab's depth, a window's depth): the element keeps its
 * size there, never splits across it, and a pattern of such elements along it keeps the
 * elements and spaces them out. A quarter keeps a window 1.2 m wide and 0.3 m deep thin in its
 * depth but neither a square pier nor a door. */
#define AG_EDIT_THIN_RATIO 0.25

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

/* ---- extrusion (core/extrude) ------------------------------------------------------------ */

/* The sweep computes every event from the planes of the edges involved, in a local frame
 * (each plan is moved to its first corner), so its error grows with the plan's size and
 * with the magnitude of the coordinates it computes with, not with where the plan lies
 * on Earth. Its tolerances are therefore relative: ag_extrude_tolerances() multiplies the
 * relative values below by the plan's size (its bounding-box diagonal, at least
 * AG_EXTRUDE_SIZE_MIN) and adds a few units in the last place of the largest coordinate.
 *
 * The paper tuned delta1 = 1e-4 (height) and delta2 = 1e-6 (plan) for its floor plans;
 * those absolute values are far larger than what double precision needs and are exactly
 * what digitising noise (1 µm .. 0.3 mm jitter) breaks: events of different corners
 * within 0.1 mm of height were merged into one. The values here are a few orders of
 * magnitude above the rounding error of a plane intersection, so genuinely coincident
 * events (symmetric plans, integer grids) still cluster, and noise above them is swept
 * as what it is. */

/* Plans smaller than this get the tolerances of a plan this size (m). */
#define AG_EXTRUDE_SIZE_MIN 10.0
/* delta1: height window of one cluster of intersection events, relative to the size. */
#define AG_EXTRUDE_REL_HEIGHT 1e-8
/* delta2: plan radius within which intersection points are one point, relative. */
#define AG_EXTRUDE_REL_POINT 1e-10
/* delta3: margin by which an edge is lengthened when testing whether a corner hits it. */
#define AG_EXTRUDE_REL_ALONG 1e-9
/* Units in the last place of the largest coordinate added to every tolerance: the
 * rounding of the coordinates themselves. */
#define AG_EXTRUDE_COORD_ULPS 64.0
/* |sin| of the angle between two edges below which they count as parallel (collinear or
 * antiparallel) for a corner's velocity: a corner between them would move faster than
 * 1e9 m per metre of height. Faster corners than a double height can place are still
 * swept right because their events are computed from the planes that meet there
 * (ag__skel_meet3), not from where the corner is said to be. */
#define AG_EXTRUDE_PARALLEL 1e-9
/* An event's height from its three planes replaces the one from its corners' motion
 * when they agree to this fraction of the size (else the corners' motion is kept: the
 * planes then meet somewhere the event is not). */
#define AG_EXTRUDE_MEET_AGREE 1e-6
/* ... which is done when a corner involved is ill-conditioned: its edges' angle has a sine
 * below 1 / this (else the corners' motion is as exact and cheaper). */
#define AG_EXTRUDE_MEET_COND 100.0
/* Three planes whose elimination meets a pivot below this do not meet in one point. */
#define AG_EXTRUDE_MEET_PIVOT 1e-12
/* Slopes (dw/dz) closer than this are equal (collinear neighbours move as one plane). */
#define AG_EXTRUDE_SAME_SLOPE 1e-9
/* Rates (m of length per m of height) below this do not make an edge shrink or a corner
 * close in on an edge. */
#define AG_EXTRUDE_MIN_RATE 1e-12
/* Rays leaving an intersection point whose angles differ less than this (radians) are
 * ordered by the planes' offsets just above the point instead of by angle. */
#define AG_EXTRUDE_RAY_TIE 1e-12
/* Intersection events whose points are within this many delta2 are one point. */
#define AG_EXTRUDE_CLUSTER_POINTS 10.0
/* Two intersection events at one point whose heights differ by less than this many units
 * in the last place (of height plus size), times their corners' condition (1 / sin of
 * the angle between a corner's edges), are one event computed twice. */
#define AG_EXTRUDE_HEIGHT_ULPS 16.0
/* A corner arrives at an intersection point when it is within this many delta2 of it
 * (plus its drift, up to AG_EXTRUDE_DRIFT_MAX delta3). */
#define AG_EXTRUDE_NEAR_POINTS 2.0
#define AG_EXTRUDE_DRIFT_MAX 100.0
/* The post inter-chain repair probes the chains this many delta1 above the current height
 * (far enough for chains leaving one point to have parted by many ulps, below the next
 * event's resolution), and tells a piece's two sides apart by points this fraction of the
 * piece's length (at most delta2) off its middle. */
#define AG_EXTRUDE_WINDING_PROBE 100.0
#define AG_EXTRUDE_WINDING_SIDE 1e-3
/* A cluster's points may spread by the speed of its fastest corner times its height
 * spread, up to this many delta3 (a corner between nearly parallel edges is fast). */
#define AG_EXTRUDE_DRIFT_ALONG 20.0
/* A new corner is moved onto the line where its two planes meet when that line passes
 * within this many delta3 of where it was made (else it keeps its point). */
#define AG_EXTRUDE_ANCHOR 100.0
/* Relative weight that pulls the least-squares apex of an intersection towards the
 * events' mean along directions no plane fixes (parallel planes). */
#define AG_EXTRUDE_APEX_DAMPING 1e-6
/* Two ridge edges closing from both ends count as ending at one point when their lengths
 * differ by less than this many delta2. */
#define AG_EXTRUDE_ZIP_EQUAL 10.0
/* Loops touching at a point (OGC-valid holes touching the outer ring, parts meeting at a
 * corner) are moved this far apart, relative to the plan's size (1e-4 m at 10 m), so that
 * walls on both never share an edge; well above the point tolerance and the 1e-6 m grids
 * outside checks weld on. */
#define AG_EXTRUDE_TOUCH_GAP 1e-5

/* Forced steps and natural steps keep this many delta3 away from the active boundary. */
#define AG_EXTRUDE_STEP_CLEARANCE 10.0
/* Side of the protrusion a natural step grows from (m). */
#define AG_EXTRUDE_STEP_SEED 1e-3

/* Shell check: a face is planar when every corner lies within this fraction of the
 * face's diameter of its Newell plane, plus an absolute floor and the rounding of its
 * coordinates (AG_EXTRUDE_COORD_ULPS of the largest). */
#define AG_EXTRUDE_PLANAR_REL 1e-6
#define AG_EXTRUDE_PLANAR_ABS 1e-8

/* Forced step polygons: an area (m²) below which the polygon has none, and the relative
 * area below which three of its corners count as collinear when checking it is simple. */
#define AG_EXTRUDE_FORCED_MIN_AREA 1e-6
#define AG_EXTRUDE_FORCED_COLLINEAR 1e-12
/* Natural steps: width and |depth| of at least this (m). */
#define AG_EXTRUDE_STEP_MIN 2e-3

/* An outward flat offset (a soffit) bevels a convex corner whose mitre would lead out
 * more than this many times the offset (corners sharper than 60°). */
#define AG_EXTRUDE_BEVEL_MITRE 2.0

/* Building check (verify.c): an outward offset of `reach` may put a convex corner's
 * mitre this many times reach away from the footprint (a 47° corner); sharper corners
 * with an overhang fail the check and are retried or fall back. */
#define AG_VERIFY_MITRE 2.5
/* ... plus this fraction of the plan's size (and its point tolerance) of slack. */
#define AG_VERIFY_REACH_REL 1e-6
/* How far behind a face the building check probes its winding, relative to the
 * building's size. Validation removes spikes no wider than this: the probe of a wall
 * would lie beyond the spike's other wall, and the shell welds the corners of narrower
 * ones (delta1 apart) into one edge used twice. */
#define AG_VERIFY_WINDING_PROBE 1e-7

/* A face whose Newell normal (twice its area, m²) is shorter than this has no area and
 * is not triangulated. */
#define AG_EXTRUDE_NO_AREA 1e-18

/* Ear clipping: a corner whose doubled area is below this fraction of the loop's squared
 * extent is flat. */
#define AG_EXTRUDE_EAR_FLAT 1e-14

typedef struct {
    double size;   /* the plan's size the relative tolerances were scaled by (m) */
    double height; /* delta1 */
    double point;  /* delta2 */
    double along;  /* delta3 */
} ag_extrude_tol;

/* Tolerances for a plan of bounding-box diagonal `extent` whose largest coordinate (in
 * the frame the computation runs in) has magnitude `magnitude`. */
static inline ag_extrude_tol ag_extrude_tolerances(double extent, double magnitude)
{
    ag_extrude_tol t;
    t.size = extent > AG_EXTRUDE_SIZE_MIN ? extent : AG_EXTRUDE_SIZE_MIN;
    double ulps = AG_EXTRUDE_COORD_ULPS * DBL_EPSILON * fabs(magnitude);
    t.height = AG_EXTRUDE_REL_HEIGHT * t.size + ulps;
    t.point = AG_EXTRUDE_REL_POINT * t.size + ulps;
    t.along = AG_EXTRUDE_REL_ALONG * t.size + ulps;
    return t;
}

#endif
