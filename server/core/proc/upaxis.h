/* Which coordinate axis points up in a mesh whose file does not say it, decided from the
 * content and reported with the evidence.
 *
 * The mesh is given as read, without any axis change. Only y and z are candidates (the two
 * conventions of OBJ, PLY, STL and CAD/GIS exports). The cues, each a fact about buildings
 * under gravity, not about one data set:
 *   georeferenced  two axes hold map coordinates (centres of ten kilometres and more, as in
 *                  UTM or national grids) and the third does not: that one is the elevation.
 *                  Decides alone.
 *   base           a building rests on a flat base and does not end in one: per axis, the
 *                  largest support (convex hull of the vertices of one level, as a share of
 *                  the model's cross-section) in the lowest twentieth of its extent, less the
 *                  same in the highest twentieth. Along a horizontal axis both ends are
 *                  facades and the difference is near 0.
 *   vertical       walls are vertical and floors horizontal whatever their azimuth: the share
 *                  of the surface whose normal is perpendicular or parallel to the axis. Plans
 *                  that are not aligned with the coordinate axes (most geo-referenced data)
 *                  make this large for the up axis only; aligned plans make it similar for all
 *                  axes, so differences below VERTICAL_DEAD_ZONE count for nothing.
 *   storey         a building is at least a storey tall: an axis along which the model is
 *                  lower than AG_UPAXIS_MIN_HEIGHT is not up when the other is at least that
 *                  tall (a lone facade slab lies down on no base). Decides alone, after the
 *                  map coordinates.
 *   roof           roofs shed water: a building's sloped surfaces (normals neither along the
 *                  axis nor across it) face one way along the up axis, while along a
 *                  horizontal axis they face both ways (the two sides of a ridge) and cancel:
 *                  per axis, |sum of the normals' components| / sum of their sizes over the
 *                  sloped surfaces, 0..1 (sign-free, so a file whose winding faces inwards says
 *                  the same; 0 when sloped surfaces are under 2 % of the area). A clear roof
 *                  (at least 0.1, and twice the other axis's) decides alone, after the storey:
 *                  the base cue is fooled by one flat wall closing an open building at one
 *                  end of a horizontal axis (a stoa's back wall looks like a floor), the roof
 *                  cue is not. It must be clear also in its strict reading, which leaves out
 *                  the surfaces upright about the other candidate: those are that axis's
 *                  walls, and a plan turned off the coordinate axes makes its walls sloped
 *                  about the horizontal axis, facing one way where one side has more wall.
 *   origin         models kept in their own frame (game and CAD assets) have the origin on the
 *                  ground at the centre of the plan: the two horizontal axes are centred on 0
 *                  and the up axis is not.
 * score = base(z) - base(y) + vertical(z) - vertical(y) (beyond the dead zone) +
 * (origin(z) - origin(y)) / 2; positive means z. A score within AG_UPAXIS_UNDECIDED of 0
 * decides nothing (the caller keeps its format's convention and says so). Linear in the mesh
 * (a sort of the vertices near the two ends of each axis). */
#ifndef AG_UPAXIS_H
#define AG_UPAXIS_H

#include "../mesh.h"
#include "../status.h"

/* Scores closer to 0 than this decide nothing. */
#define AG_UPAXIS_UNDECIDED 0.1
/* Metres: the storey cue's least height of a building. */
#define AG_UPAXIS_MIN_HEIGHT 2.0

typedef struct {
    double base;     /* support at the low end less support at the high end, -1..1 */
    double top;      /* the high end's support, 0..1 (base = bottom - top) */
    double vertical; /* share of the area perpendicular or parallel to the axis, 0..1 */
    double roof;     /* how one way the sloped surfaces face along the axis, 0..1 */
    double roof_strict; /* the same without the surfaces upright about the other axis */
    double extent;   /* the model's extent along the axis, metres */
    double origin;   /* how far the axis's centre is above the origin, in half extents,
                        when the two other axes are centred on the origin (else 0), 0..1 */
} ag_upaxis_cues;

typedef struct {
    int axis;             /* 1 = y, 2 = z; 0 when the content decides nothing */
    int georeferenced;    /* the map-coordinate cue decided */
    int storey;           /* the storey cue decided */
    int roof;             /* the roof cue decided */
    double score;         /* > 0 for z, < 0 for y */
    double centre[3];     /* of the bounding box, as read */
    ag_upaxis_cues cue[2]; /* [0] for y, [1] for z */
} ag_upaxis_evidence;

/* Decides from the mesh as read (no axis change applied). AG_ERR_EMPTY for a mesh without
 * triangles, AG_ERR_NOMEM. */
ag_status ag_upaxis_decide(const ag_mesh *m, ag_upaxis_evidence *ev, ag_error *err);

/* Turns a y-up mesh into archgram's z-up frame in place: (x, y, z) -> (x, -z, y), the same
 * turn the readers apply for a y-up file. */
void ag_upaxis_turn_y_to_z(ag_mesh *m);

#endif
