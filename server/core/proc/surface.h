/* How far one triangulated surface lies from another, certified: the comparison behind labels
 * that do not depend on triangulation and behind an honest fidelity.
 *
 * ag_surface_cover checks that every point of surface A lies within tol of surface B. The
 * distance to one triangle is convex, so a piece of A whose three corners lie within d of one
 * triangle of B lies within d of B everywhere: that is the certificate. A piece that no single
 * triangle of B covers (B is triangulated differently there, or A leaves B) is clipped to
 * the prisms over B's triangles (the same convexity proves each clipped part on its
 * triangle); when that does not prove it whole it is cut into four and tried again, down to
 * pieces of the tolerance's size; a corner farther than tol from
 * every triangle of B is a witness that A leaves B. So "covered" is a proof (no sampling gaps),
 * `upper` a bound on the distance over the covered part and `lower` a distance some point of A
 * has. The work is bounded: past the budget the pieces left are counted as not covered, which
 * never reports a match that was not proven. Symmetric use (A on B and B on A) compares two
 * surfaces. */
#ifndef AG_SURFACE_H
#define AG_SURFACE_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../status.h"

/* Triangles of B in a uniform grid. tri (9 doubles per triangle) is borrowed. */
typedef struct {
    const double *tri;
    size_t n;
    ag_box box;
    double cell;
    int64_t dims[3];
    uint32_t *start; /* per cell, into items; ncells + 1 */
    uint32_t *items;
    uint32_t *big;   /* triangles spanning too many cells: checked by every query */
    size_t nbig;
    double *tbox;    /* per triangle: its box, min then max (6 doubles) */
    uint32_t *stamp; /* per triangle: the query that last looked at it */
    uint32_t query;
} ag_surface;

ag_status ag_surface_init(ag_surface *s, const double *tri, size_t n);
void ag_surface_free(ag_surface *s);

typedef struct {
    double upper;     /* every point of the covered triangles lies within this of B */
    double lower;     /* some point of A lies at least this far from B (measured on the
                         corners of pieces no single triangle of B covers) */
    size_t uncovered; /* triangles of A not proven within tol of B */
    int exhausted;    /* the work budget ran out (the rest counted as uncovered) */
} ag_surface_cover_result;

/* Checks the na triangles of A (9 doubles each) against B. budget: pieces to examine at most
 * (0: 64 per triangle of A plus 4096). stop_early: return at the first triangle not covered
 * (a yes/no question). */
void ag_surface_cover(ag_surface *b, const double *a, size_t na, double tol, size_t budget,
                      int stop_early, ag_surface_cover_result *out);

/* Distance from p to the triangle (t0, t1, t2). */
double ag_surface_point_triangle(const double p[3], const double *t0, const double *t1,
                                 const double *t2);

#endif
