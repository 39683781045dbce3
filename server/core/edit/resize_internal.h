/* Internal to the resize files: the units the equations move, the least-squares system over
 * them, and the pieces the phases share.
 *
 *   resize.c         the solver's life (create builds the units and the system of the edited
 *                    level, free, matches), the shared helpers below, ag_edit_resize
 *   resize_units.c   the units of a tree: every visible node, every pattern node standing for
 *                    its cells (a pattern is one box in the equations; its cells are laid out
 *                    again by their period), the units' adjacency
 *   resize_system.c  the system of one set of units in named phases: targets and the frame,
 *                    attachment equations, size equations, frame ratios, columns and
 *                    factorization, target terms
 *   resize_solve.c   the solve for one target: right-hand side, least squares, unit boxes
 *   resize_layout.c  from the solved level down: each changed node's children solved in its new
 *                    box, patterns laid out again by their period (count changes), leaves
 *                    stretched past the split ratio split, squeezed siblings joined; the new
 *                    tree (a commit) or every node's box (a preview)
 *
 * A system has slots: one per unit, and a last one for its frame (the box its units lie in:
 * the edited root's target, a changed parent's new box, or the unchanged visible ancestor of
 * the edited level) when it has one. Each slot has six coordinates, min x, y, z and max x, y,
 * z, numbered slot * 6 + c as ag_box_coord numbers them. Hard equalities merge coordinates
 * into classes (a union-find with offsets: value = value of the class root + offset); a class
 * is free (one column of the least squares), fixed to a constant, or a target (set anew by
 * every solve). */
#ifndef AG_EDIT_RESIZE_INTERNAL_H
#define AG_EDIT_RESIZE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "../base/uf.h"
#include "lsq.h"
#include "resize.h"

/* ---- units ------------------------------------------------------------------------------- */

typedef struct {
    const ag_splittree *t;
    int32_t *va;          /* per node: nearest visible ancestor (0 = the root; the root: -1) */
    int32_t *unit;        /* per node: the unit it is (itself) or belongs to (a closed pattern's
                             cell: the pattern node); -1 for nodes that are no unit */
    uint8_t *open;        /* per pattern node: its cells are units of their own (a cell is
                             edited) */
    uint8_t *lattice;     /* per unit: bit a set for a pattern repeating along axis a */
    uint32_t *adj_start;  /* unit adjacency, CSR over node indices: nnodes + 1 offsets */
    uint32_t *adj_list;
} ag__resize_units;

/* The units of t, with the patterns holding any of the `nopen` nodes `open` (cells) opened. */
ag_status ag__resize_units_build(ag__resize_units *u, const ag_splittree *t, const int32_t *open,
                                 size_t nopen, ag_error *err);
void ag__resize_units_free(ag__resize_units *u);
/* The chain ends below node n that are units (n's children through split nodes; a pattern's
 * cells when it is open). Returns how many, writing at most cap into out. */
size_t ag__resize_child_units(const ag__resize_units *u, int32_t n, int32_t *out, size_t cap);

/* ---- the system -------------------------------------------------------------------------- */

/* One soft equation before substitution: sum coef * coord = rhs over coordinate ids. */
typedef struct {
    uint32_t coord[4];
    double coef[4];
    uint8_t nterms, type; /* type: ag_attach_type */
    double rhs;
} ag__resize_row;

/* A hard equality x[coord] - other = d, other being a coordinate (other_coord), a constant
 * (other_coord = AG__RESIZE_CONST, the value in d) or the coordinate's target
 * (AG__RESIZE_TARGET). Kept to report how well the solution holds them. */
#define AG__RESIZE_CONST UINT32_MAX
#define AG__RESIZE_TARGET (UINT32_MAX - 1)
typedef struct {
    uint32_t coord, other_coord;
    double d;
} ag__resize_hard;

/* The state of a class (at its root). */
enum { AG__RESIZE_FREE = 0, AG__RESIZE_FIXED = 1, AG__RESIZE_TARGETED = 2 };

/* What a system is built over. */
enum { AG__FRAME_NONE = 0, AG__FRAME_FIXED = 1, AG__FRAME_TARGETED = 2 };
typedef struct {
    size_t nunits;
    const int32_t *units;     /* tree nodes, one per slot; the first nedit are edited */
    size_t nedit;
    int frame;                /* AG__FRAME_*: the frame slot's coordinates fixed or targets */
    int32_t frame_node;       /* the frame's tree node (not attached as an outside unit), -1 */
    ag_box frame_old;         /* the frame's box the units' attachments are measured in */
    ag_box frame_new;         /* a fixed frame: its new box */
    int outside;              /* attach to adjacent units that are not in the system (the
                                 edited level: they stay where they are) */
    const ag_box *old;        /* per unit: the box attachments are measured on */
    const ag_box *expect;     /* per unit: where the weak position terms hold it; NULL: old */
    const uint8_t *held;      /* per unit (NULL: none): a unit a local edit happens on (it
                                 holds the region): no ratio to an edited unit moves it */
} ag__resize_spec;

typedef struct {
    const ag_proceduralize_result *in;
    const ag__resize_units *u;
    size_t nslots;            /* units, and the frame's slot last when there is one */
    size_t nunits;
    int32_t *slot_node;       /* per unit slot: its tree node */
    ag_box *old;              /* per slot: the box attachments were measured on */
    int frame;
    uint8_t *stretch;         /* per unit slot: bit a set when it follows what it lies in along
                                 axis a (a pattern repeating there; one of several units of one
                                 rule, unless a is a thin axis), else it keeps its size */
    double diag;
    /* coordinate classes */
    ag_uf classes;            /* 6 * nslots coordinates, with offsets */
    int8_t *fix;              /* per root: AG__RESIZE_FREE, _FIXED or _TARGETED */
    double *val;              /* per root: the value when fixed or targeted */
    int32_t *col;             /* per root: its column when free */
    size_t ncols;
    /* equations */
    ag__resize_row *rows;
    size_t nrows, cap_rows;
    ag__resize_hard *hard;
    size_t nhard, cap_hard;
    ag_lsq *lsq;
    double *b, *x;
    /* resolved once the classes are final, so a re-solve does no lookups */
    uint32_t *croot;          /* per coordinate: its class root */
    double *coff;             /* per coordinate: offset from the root */
    double *b0;               /* per row: right-hand side without the targets */
    uint32_t *trow, *troot;   /* terms on target classes: row, root and coefficient */
    double *tcoef;
    size_t nterms_t;
} ag__resize_system;

/* Builds the system of spec over in's tree (units u). On failure s holds what was built;
 * ag__resize_system_free releases it. */
ag_status ag__resize_system_build(ag__resize_system *s, const ag_proceduralize_result *in,
                                  const ag__resize_units *u, const ag__resize_spec *spec,
                                  ag_error *err);
void ag__resize_system_free(ag__resize_system *s);
/* Solves with the edited slots' targets (targets: 6 per edited slot, nedit of them) and the
 * frame's (a targeted frame: frame_target): every slot's box into boxes (nslots). *residual
 * gets the largest violation of a hard equality. */
ag_status ag__resize_system_solve(ag__resize_system *s, size_t nedit, const ag_box *targets,
                                  const ag_box *frame_target, ag_box *boxes, double *residual,
                                  ag_error *err);

/* ---- the solver of the edited level (kept for drags) -------------------------------------- */

struct ag_edit_resize_solver {
    const ag_proceduralize_result *in;
    /* what the solver was built for (ag_edit_resize_solver_matches) */
    int32_t node;
    int mode, has_region;
    ag_box region;
    double diag;
    ag__resize_units units;
    /* the edited level */
    int root;                 /* the root is edited: its target is the frame's */
    size_t nedit;
    int32_t *edit;            /* edited units (the op's node's unit first) */
    int *edit_turn;           /* quarter turns from the op's node to each edited node */
    uint8_t *edit_mirror;     /* per edited node: a mirror image of the op's node (reflected
                                 along x, then turned by edit_turn) */
    int32_t frame_node;       /* the level's frame: the edited units' visible ancestor (or the
                                 root), -1 when the level has none */
    size_t nunits;
    int32_t *level;           /* the level's units, the edited first */
    uint8_t *held;            /* per level unit: it holds a local edit's region */
    ag_box *old;              /* their boxes */
    ag__resize_system sys;
    const ag_edit_budget *budget; /* a commit's limits and stop flag (not owned), NULL */
    /* the op's ratios for the layout: split past split_ratio, join under join_ratio, never on
     * an axis thinner than thin_ratio of the largest (ag_edit_op.split_ratio, thin_share) */
    double split_ratio, join_ratio, thin_ratio;
};

/* How far apart faces may be and still touch (attach): the tree's coincidence, or its exact
 * tolerance when larger, so a vertex jitter below what derivation reproduces does not undo an
 * attachment (a wall whose end lies a fraction of a micrometre inside the building's face). */
double ag__resize_touch(const ag_splittree *t, double diag);

/* The nearest visible ancestor of node n, 0 (the root) when there is none. */
int32_t ag__resize_visible_ancestor(const ag_splittree *t, int32_t n);
/* The op's target box for its node (op->box, or op->scale about the node's min corner). */
ag_status ag__resize_target(const ag_proceduralize_result *in, const ag_edit_op *op, ag_box *t,
                            ag_error *err);

/* An affine map per axis, x -> s x + t. */
typedef struct {
    double s[3], t[3];
} ag__resize_map;

/* The map taking box `from` onto box `to` (scale 1 along a flat axis of `from`). */
ag__resize_map ag__resize_map_between(const ag_box *from, const ag_box *to);
ag_box ag__resize_map_box(const ag__resize_map *m, const ag_box *b);

/* Solves the edited level for op's target: the boxes of the level's units (s->nunits, in
 * s->units order) and of the frame (the root's new box when the root is edited). */
ag_status ag__resize_solve_level(ag_edit_resize_solver *s, const ag_edit_op *op,
                                 ag_box *unit_boxes, ag_box *frame_box, ag_edit_report *rep,
                                 ag_error *err);

/* ---- layout ------------------------------------------------------------------------------ */

/* From the edited level's solution down. Preview (structural = 0): every node's new box into
 * boxes (nnodes entries), the tree's structure kept (patterns keep their counts). Commit
 * (structural = 1): *out gets the new tree (old nodes at their indices, new ones after,
 * removed ones dead) and *source (per node of the new tree: the old node it copies, malloc'd);
 * rep gets the splits and joins. */
ag_status ag__resize_layout(const ag_edit_resize_solver *s, const ag_box *unit_boxes,
                            const ag_box *frame_box, int structural, ag_box *boxes,
                            ag_splittree **out, int32_t **source, ag_edit_report *rep,
                            ag_error *err);

#endif
