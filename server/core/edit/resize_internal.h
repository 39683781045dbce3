/* Internal to the resize files: the solver's state and the pieces its phases share.
 *
 *   resize.c         the solver's life (create runs the system phases, free, matches), the
 *                    shared helpers below, and ag_edit_resize (solve, then emit)
 *   resize_system.c  system assembly in named phases: gather nodes, targets, attachment
 *                    equations, size equations, columns and factorization, target terms
 *   resize_solve.c   the solve for one target: right-hand side, least squares, boxes of the
 *                    unknowns, boxes of the nodes derived from them
 *   resize_emit.c    emission of the new mesh: affine maps, split past the split ratio,
 *                    pattern count changes, joins of squeezed siblings
 *
 * The area of effect has slots (one per node that is an unknown); each slot has six
 * coordinates, min x, y, z and max x, y, z, numbered slot * 6 + c as ag_box_coord numbers
 * them. Hard equalities merge coordinates into classes (a union-find with offsets: value =
 * value of the class root + offset); a class is free (one column of the least squares),
 * fixed to a constant, or a target (set anew by every solve). */
#ifndef AG_EDIT_RESIZE_INTERNAL_H
#define AG_EDIT_RESIZE_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "../base/uf.h"
#include "lsq.h"
#include "resize.h"

/* One soft equation before substitution: sum coef * coord = rhs over coordinate ids; terms on
 * nodes outside the area are folded into rhs. */
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

struct ag_edit_resize_solver {
    const ag_proceduralize_result *in;
    /* what the solver was built for (ag_edit_resize_solver_matches) */
    int32_t node;
    int mode, has_region;
    ag_box region;
    int affine;             /* root or invisible node: no solve */
    double diag;            /* of the root box */
    /* gathered nodes */
    size_t nedit;
    int32_t *edit;          /* edited nodes */
    int *edit_turn;         /* quarter turns from the op's node to each edited node */
    int32_t *slot;          /* per tree node: its slot or -1 */
    int32_t *slot_node;     /* per slot: its tree node */
    size_t nslots;
    int32_t *va;            /* per node: nearest visible ancestor (0 = root) */
    /* coordinate classes */
    ag_uf classes;          /* 6 * nslots coordinates, with offsets */
    int8_t *fix;            /* per root: AG__RESIZE_FREE, _FIXED or _TARGETED */
    double *val;            /* per root: the value when fixed or targeted */
    int32_t *col;           /* per root: its column when free */
    size_t ncols;
    /* equations */
    ag__resize_row *rows;
    size_t nrows, cap_rows;
    ag__resize_hard *hard;
    size_t nhard, cap_hard;
    ag_lsq *lsq;
    double *b, *x;
    /* resolved once the classes are final, so a re-solve does no lookups */
    uint32_t *croot;        /* per coordinate: its class root */
    double *coff;           /* per coordinate: offset from the root */
    double *b0;             /* per row: right-hand side without the targets */
    uint32_t *trow, *troot; /* terms on target classes: row, root and coefficient */
    double *tcoef;
    size_t nterms_t;
};

/* Builds the system of s (s->in and the op's fields set, s not affine): every phase of
 * resize_system.c in order. On failure s holds what was built; ag_edit_resize_solver_free
 * releases it. */
ag_status ag__resize_system_build(ag_edit_resize_solver *s, const ag_edit_op *op,
                                  ag_error *err);

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

#endif
