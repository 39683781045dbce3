/* A point cloud as a procedural model: terminals that are point sets, placed by affine maps,
 * organized by the same split tree, rules, patterns and grammar as meshes (core/proc).
 *
 * A terminal is a point set in local coordinates of its box [0, size] (a consensus model, or
 * one segment's points). A placement puts a terminal in the cloud: x = A p + b, A a quarter
 * turn about z with per-axis scales (what a grammar application does), its box the image of
 * [0, size].
 *
 * The proxy. core/proc and core/edit work on meshes; a point model hands them a proxy mesh:
 * one component per placement, a tetrahedron on four corners of its box (the images of the
 * terminal's local origin and of its three axes' ends), grouped "L<terminal + 1>", with the
 * placements' boxes as the component boxes and the terminal as label and variant. The split
 * tree, rules, patterns and the grammar are then found by core/proc itself (one terminal per
 * variant, point terminals in the text), and the edits of core/edit (resize with the
 * attachment equations and the SuiteSparse solve, split, join, paste, remove) run unchanged:
 * every component they emit is a placement again, read back from its tetrahedron (the map
 * of the terminal's local frame) and its group (the terminal; "src_L<n>" one of a paste's
 * source model; "L<a>+L<b>" a join). A grammar is read the same way: its terminals get
 * tetrahedra of their size and the derivation of core/proc places them.
 *
 * Derivation of points: every placement's terminal mapped by A and b, the density kept where
 * A stretches (resample.h: stretch compensation), and overlapping placements thinned at their
 * seams; each point says its terminal (`label`) and its placement (`segment`). */
#ifndef AG_POINTMODEL_H
#define AG_POINTMODEL_H

#include <stddef.h>
#include <stdint.h>

#include "../base/box.h"
#include "../edit/edit.h"
#include "../proc/grammar.h"
#include "../status.h"
#include "cloud.h"

typedef struct {
    ag_cloud *points;   /* local coordinates in [0, size], with normals and properties */
    double size[3];
    double spacing;     /* median distance between neighbouring points, metres */
    /* where it came from (consensus models): the members it merged and the points before */
    size_t members, merged;
    size_t points_before; /* the base member's */
    double mean_before;   /* points per member */
} ag_pointmodel_terminal;

typedef struct {
    int32_t terminal;
    double A[3][3]; /* row-major: x = A p + b */
    double b[3];
    ag_box box;
    uint8_t rot;    /* the quarter turns of A about z */
} ag_pointmodel_placement;

typedef struct ag_pointmodel {
    double offset[3];  /* the cloud's local origin (positions are relative to it) */
    double scale[3];   /* coordinate resolution of the source, 0 = unknown */
    double spacing;    /* typical point spacing, metres */
    double tolerance;  /* matching tolerance of rules and patterns, metres */
    size_t nterminals, cap_terminals;
    ag_pointmodel_terminal *terminals;
    size_t nplacements, cap_placements;
    ag_pointmodel_placement *placements;
    ag_edit_model *em; /* the proxy (after ag_pointmodel_build): em->proc->tree numbers the
                        * nodes; node n's placement is its component */
    double build_seconds[2];     /* the last build: tree (rules, patterns), grammar export */
    double build_cpu_seconds[2];
} ag_pointmodel;

ag_pointmodel *ag_pointmodel_create(void);
void ag_pointmodel_free(ag_pointmodel *pm);

/* Adds a terminal from points in cloud-local coordinates (taken: *points becomes NULL) within
 * box (NULL: their bounds); an axis thinner than min_thickness is padded to it around its
 * middle. *origin (optional) gets the local origin, so that the points' placement is
 * x = p + origin. spacing 0: measured. */
ag_status ag_pointmodel_add_terminal(ag_pointmodel *pm, ag_cloud **points, const ag_box *box,
                                     double min_thickness, double spacing, double origin[3],
                                     size_t *index, ag_error *err);
/* Adds a placement (its box and turn are derived from A and b). */
ag_status ag_pointmodel_add_placement(ag_pointmodel *pm, int32_t terminal, const double A[3][3],
                                      const double b[3], ag_error *err);

/* Builds the proxy: drops terminals nothing places, turns each terminal so that one of its
 * placements is unturned, and runs split tree, rules, patterns and grammar export. The
 * grammar's terminals are the model's terminals (grammar terminal info->terminal_of_variant[t]
 * for terminal t; their sizes the terminals' own). */
ag_status ag_pointmodel_build(ag_pointmodel *pm, ag_error *err);

/* The proxy mesh ag_pointmodel_build makes: a tetrahedron per placement (component i places
 * placement i), in a group per terminal ("L<t + 1>"). */
ag_status ag_pointmodel_proxy_mesh(const ag_pointmodel *pm, ag_mesh **out, ag_error *err);

/* The grammar of a built model (pm->em->proc->grammar) and which of its terminals is which of
 * the model's: term[g] = model terminal of grammar terminal g (malloc'd). */
ag_status ag_pointmodel_grammar_terminals(const ag_pointmodel *pm, int32_t **term,
                                          ag_error *err);

/* A model from a resolved grammar and one point set per grammar terminal (points[g], local to
 * its box, taken: the entries become NULL): the grammar derived (core/proc) and every
 * application read as a placement, then built. Terminal t of the model is grammar terminal g
 * in the grammar's order, or in the order of their labels when they are L1 .. Lk. */
ag_status ag_pointmodel_from_grammar(const ag_grammar *g, ag_cloud **points,
                                     const double offset[3], ag_pointmodel **out,
                                     ag_error *err);

typedef struct {
    size_t points;          /* derived */
    size_t stretched;       /* placements whose density was compensated */
    size_t seam_dropped;    /* points dropped at seams */
} ag_pointmodel_derive_info;

/* The derived cloud (with the model's offset): terminal properties, normals, and int32
 * `label` (terminal) and `segment` (placement). max_points 0 = 100 million (AG_ERR_TOO_LARGE
 * past it). */
ag_status ag_pointmodel_derive(const ag_pointmodel *pm, size_t max_points, ag_cloud **out,
                               ag_pointmodel_derive_info *info, ag_error *err);

/* How well a derived cloud reproduces an input: the share of input points within tol of a
 * derived point (coverage) and of derived points within tol of an input point (precision). */
typedef struct {
    double coverage, precision;
    size_t input, derived;
    double tolerance;
} ag_pointmodel_fidelity;

ag_status ag_pointmodel_compare(const ag_cloud *input, const ag_cloud *derived, double tol,
                                 ag_pointmodel_fidelity *f, ag_error *err);

/* Placements of a proxy mesh (an edit's or a derivation's output): each tetrahedron of
 * component c in group G is a placement of terminal lookup(G, legs) with the map read from the
 * tetrahedron (a component with several, a join, gives one placement each, and *joined counts
 * the extra ones). legs are the lengths of the tetrahedron's three edges from its first corner
 * (they tell the terminals of a join apart). lookup returns the terminal of the model being
 * made (it may add one, e.g. a pasted model's), or -1 when the group names none
 * (AG_ERR_INTERNAL names it) or with err set. */
typedef int32_t (*ag_pointmodel_lookup)(void *user, const char *group, const double legs[3],
                                        ag_error *err);
ag_status ag_pointmodel_read_proxy(ag_pointmodel *pm, const ag_mesh *proxy,
                                   ag_pointmodel_lookup lookup, void *user, size_t *joined,
                                   ag_error *err);

#endif
