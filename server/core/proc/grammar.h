/* The split grammar in memory: terminals, rules in declare-before-use order, the axiom.
 *
 * A rule body is a list of statements over named nodes; `p` is the node the rule is applied
 * to (the axiom's `p` is the building box). Inside a rule, coordinates are local: `p` spans
 * [0, size]. Statements:
 *   SPLIT  node = split(parent, vx, vy, vz, q)      pivot relative to parent's min corner
 *   APPLY  Callee(node) [rot]                       place a terminal / apply a rule
 *   APPLY  Rule(subdivide(node, sx, sy, sz, dx, dy, dz)) [rot]
 *          node's box holds sx*sy*sz cells of equal size spaced by (dx, dy, dz); the cell
 *          size per axis is size - (s - 1) * d; the rule is applied to every cell.
 *   APPLY  Rule(repeat(node, c1, a1, a2, a3 [, c2, b1, b2, b3 [, c3, ...]])) [rot]
 *          a translation lattice in any direction (oblique facades): cell (i, j, k) is offset
 *          by i a + j b + k c; cells are as large as node's box less the lattice's extent.
 * Applying X (size S) with r quarter turns to a box B: X's local box, turned by r about its
 * centre and scaled per axis to B's size, is placed on B. The text form is in
 * schema/grammar.md; parsing and printing live in server/io/grammar_text.c. */
#ifndef AG_GRAMMAR_H
#define AG_GRAMMAR_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "label.h"
#include "splittree.h"

typedef struct {
    char *name;
    char *path;      /* geometry file, relative to the grammar's folder; may be NULL */
    double size[3];
    size_t nverts, ntris;
    double *pos;     /* local coordinates, in [0, size]; NULL until loaded */
    uint32_t *tri;
    int32_t label;   /* the label it stands for when exported, else -1 */
    char *label_name; /* label shared by near-equal terminals ("L3"); NULL when none */
} ag_gterminal;

typedef enum { AG_GSTMT_SPLIT = 1, AG_GSTMT_APPLY = 2 } ag_gstmt_kind;

typedef struct {
    int kind;
    char *node;       /* SPLIT: the node defined; APPLY: the node applied to */
    char *parent;     /* SPLIT */
    double v[3];      /* SPLIT: pivot */
    int octant;       /* SPLIT: 1..8 */
    char *callee;     /* APPLY */
    int rot;          /* APPLY: quarter turns 0..3 */
    int subdivide;    /* APPLY: 0 single, 1 subdivide (axis-aligned), 2 repeat (lattice) */
    uint32_t counts[3]; /* subdivide: per axis; repeat: per vector (nvec used) */
    double step[3];   /* subdivide */
    int nvec;         /* repeat: 1..3 vectors */
    double vec[3][3]; /* repeat: translation vectors */
    long line, col;   /* source position when parsed */
    /* filled by ag_grammar_resolve */
    int32_t node_ix, parent_ix, callee_ix;
    int callee_is_rule;
} ag_gstmt;

typedef struct {
    char *name;       /* NULL for the axiom */
    double size[3];   /* rules: the local box is [0, size] */
    ag_box box;       /* the axiom's building box */
    size_t nstmts, cap;
    ag_gstmt *stmts;
    size_t nnodes;    /* filled by ag_grammar_resolve: p and every split node */
    long line, col;
} ag_grule;

typedef struct {
    size_t nterminals, cap_terminals;
    ag_gterminal *terminals;
    size_t nrules, cap_rules;
    ag_grule *rules;
    ag_grule axiom;
    int has_axiom;
} ag_grammar;

ag_grammar *ag_grammar_create(void);
void ag_grammar_free(ag_grammar *g);

/* Building blocks (the parser and the exporter use them). Names are copied. */
ag_status ag_grammar_add_terminal(ag_grammar *g, const char *name, const double size[3],
                                  size_t *index);
ag_status ag_grammar_add_rule(ag_grammar *g, const char *name, const double size[3],
                              size_t *index);
ag_status ag_grammar_add_split(ag_grule *r, const char *node, const char *parent,
                               const double v[3], int octant, long line, long col);
ag_status ag_grammar_add_apply(ag_grule *r, const char *callee, const char *node, int rot,
                               const uint32_t *counts, const double *step, long line, long col);
ag_status ag_grammar_add_repeat(ag_grule *r, const char *callee, const char *node, int rot,
                                int nvec, const uint32_t *counts, const double vec[][3],
                                long line, long col);
/* Sets a terminal's geometry (copied). */
ag_status ag_grammar_set_terminal_geometry(ag_gterminal *t, const double *pos, size_t nverts,
                                           const uint32_t *tri, size_t ntris);

/* Checks names (unique, declared before use, nodes defined before use), octants, turns and
 * counts, and fills the resolved indices. On failure err->element is the line and *col the
 * column of the offending statement (0 when unknown). */
ag_status ag_grammar_resolve(ag_grammar *g, ag_error *err, long *col);

typedef struct {
    int32_t *rule_of_class;    /* per split-tree rule: grammar rule index or -1 (inlined) */
    int32_t *terminal_of_variant; /* per label variant: terminal index, -1 if unused */
    size_t nclasses, nvariants;
} ag_grammar_export_info;

/* Grammar of a labelled split tree (after rules and patterns). Terminals carry geometry. */
ag_status ag_grammar_export(const ag_mesh *m, const ag_labels *labels, const ag_splittree *t,
                            ag_grammar **out, ag_grammar_export_info *info, ag_error *err);
void ag_grammar_export_info_free(ag_grammar_export_info *info);

typedef struct {
    size_t max_triangles; /* 0 = 50 million */
} ag_grammar_derive_options;

/* Derives the mesh: one component per placed terminal, grouped by label (the terminal's
 * label name, or its own name when it has none). Every terminal needs its geometry. */
ag_status ag_grammar_derive(const ag_grammar *g, const ag_grammar_derive_options *opt,
                            ag_mesh **out, ag_error *err);

typedef struct {
    double max_error;   /* metres: certified bound on the distance between the input and the
                           derived surfaces where they are within tol of each other */
    double relative;    /* max_error / diagonal of the input */
    size_t unmatched;   /* input triangles not reproduced within tol */
    size_t spurious;    /* derived triangles farther than tol from the input */
    size_t input_triangles, derived_triangles;
} ag_fidelity;

/* Compares the input with its derivation within tol (absolute; 0 = 1e-5 of the diagonal),
 * surface to surface (surface.h), so a terminal shared by copies triangulated otherwise is
 * measured by what it moves, not by its triangle list. Components are paired by their boxes
 * (a derivation places one terminal per input component, on its box); a pair with equal
 * triangle lists is compared triangle by triangle, else by the surfaces both ways; what pairs
 * with nothing is compared with the whole other mesh. */
ag_status ag_grammar_fidelity(const ag_mesh *input, const ag_mesh *derived, double tol,
                              ag_fidelity *f, ag_error *err);

#endif
