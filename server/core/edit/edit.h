/* Structure-preserving editing of a proceduralized model.
 *
 * An edit model is a proceduralization result (segmented mesh, labels, split tree, rules,
 * patterns, grammar) plus cached solver state. Every operation is a pure function of the
 * result and an op. ag_edit_apply makes the edited split tree (resize.h, treeedit.h: every
 * node the edit does not remove keeps its index, new nodes are appended, removed ones are
 * dead) and rebuilds the model from it (rebuild.h: rules and patterns found afresh) without
 * proceduralizing again. The mesh-returning functions below make the operation's mesh — one
 * component per placed terminal, grouped by label name — which point clouds
 * (points/pointedit.h) and AG_EDIT_MESH_PATH proceduralize again.
 *
 * Nodes are named by their index in the model's split tree (model->proc->tree); node 0 is
 * the root. A visible node's geometry is kept relative to its box: when the box changes, the
 * component's vertices are mapped affinely from the old box to the new one. */
#ifndef AG_EDIT_H
#define AG_EDIT_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../proc/proceduralize.h"
#include "../status.h"

typedef enum {
    AG_EDIT_RESIZE = 1,
    AG_EDIT_SPLIT = 2,
    AG_EDIT_JOIN = 3,
    AG_EDIT_PASTE = 4,
    AG_EDIT_REMOVE = 5,
} ag_edit_kind;

typedef enum { AG_EDIT_GLOBAL = 0, AG_EDIT_LOCAL = 1 } ag_edit_mode;
typedef enum { AG_EDIT_INSERT = 0, AG_EDIT_REPLACE = 1 } ag_edit_placement;
typedef enum { AG_EDIT_FILL = 0, AG_EDIT_DERIVE = 1 } ag_edit_fit;

#define AG_EDIT_ROOT 0 /* node index of the root ("root" in op JSON) */

/* What one edit may make and how long it may run (the service's limits and time budget):
 * an edit whose result would pass a limit is refused with AG_ERR_RESULT_TOO_LARGE before the
 * result is made (a resize counts what its emission would place first), and `cancelled` is
 * polled while the result is emitted and between the stages of proceduralizing it. */
typedef struct {
    size_t max_triangles;  /* of the new mesh; 0: the operation's own ceiling */
    size_t max_components; /* placed terminals (components) of the new mesh; 0: idem */
    int (*cancelled)(void *user); /* non-zero stops the edit with AG_ERR_CANCELLED; may be NULL */
    void *user;
} ag_edit_budget;

/* Non-zero when the budget's callback asks to stop (b may be NULL). */
int ag_edit_budget_cancelled(const ag_edit_budget *b);

typedef struct {
    int kind; /* ag_edit_kind */

    /* resize, split: the node; paste: the destination node */
    int32_t node;

    /* resize: either the new world box or a per-axis scale about the node's min corner */
    int has_box;
    ag_box box;
    int has_scale;
    double scale[3];
    int mode;       /* ag_edit_mode */
    int has_region; /* local mode: the area of effect (world box); without it, the node's
                       parent box */
    ag_box region;
    /* resize: the stretch past which a node or a pattern's cells double (and its inverse,
     * under which they join); 0 = AG_EDIT_SPLIT_RATIO (meshes). Point clouds use
     * AG_POINTS_SPLIT_RATIO, the paper's 1.5. */
    double split_ratio;
    /* resize: a node is not split (nor a pattern's count changed) on an axis where it is
     * thinner than this share of its largest extent (a wall's thickness); 0 =
     * AG_EDIT_THIN_RATIO (meshes) */
    double thin_share;

    /* split: axis 0..2 and the plane's world coordinate on it */
    int axis;
    double at;

    /* join, remove: the selection; paste: the source selection. malloc'd, owned by the op */
    size_t nnodes;
    int32_t *nodes;

    /* paste */
    int placement;  /* ag_edit_placement */
    int fit;        /* ag_edit_fit */
    /* paste across models: the source model (not owned); NULL = the edited model */
    const ag_proceduralize_result *source;

    /* limits and cancellation (not owned); NULL: the built-in ceilings, never cancelled */
    const ag_edit_budget *budget;
} ag_edit_op;

/* Frees the op's arrays and zeroes it. */
void ag_edit_op_clear(ag_edit_op *op);
/* Deep copy of the arrays (source is shared). */
ag_status ag_edit_op_copy(ag_edit_op *dst, const ag_edit_op *src, ag_error *err);

typedef struct {
    char *name;   /* label name (mesh group name) */
    size_t count; /* terminal instances */
} ag_edit_label_count;

typedef struct {
    size_t equations, unknowns;  /* of the least-squares system (resize), else 0 */
    double solve_ms;             /* equations + factorization + solve (a drag re-solve: solve) */
    double max_residual;         /* largest hard-attachment violation after the solve, metres */
    double max_residual_rel;     /* the same relative to the model diagonal */
    size_t splits, joins;        /* pattern cells / nodes split and joined */
    size_t nlabels;              /* filled by ag_edit_apply from the new model */
    ag_edit_label_count *labels; /* malloc'd */
    char message[256];
} ag_edit_report;

/* Frees the report's arrays and zeroes it. */
void ag_edit_report_clear(ag_edit_report *rep);
/* Fills rep->labels / nlabels with the triangle-bearing components per group of m. */
ag_status ag_edit_report_count_labels(ag_edit_report *rep, const ag_mesh *m, ag_error *err);

/* The operations, each a pure function of the model. *out is a new mesh: one component per
 * placed terminal, group name = label name. rep may be NULL. */
ag_status ag_edit_resize(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err);
ag_status ag_edit_split(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                        ag_edit_report *rep, ag_error *err);
ag_status ag_edit_join(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                       ag_edit_report *rep, ag_error *err);
ag_status ag_edit_paste(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                        ag_edit_report *rep, ag_error *err);
ag_status ag_edit_remove(const ag_proceduralize_result *in, const ag_edit_op *op, ag_mesh **out,
                         ag_edit_report *rep, ag_error *err);

/* Checks that a node index names a live node of the tree (precise error naming `field`). */
ag_status ag_edit_check_node(const ag_proceduralize_result *in, int32_t node, const char *field,
                             ag_error *err);

/* The model being edited. */
typedef struct ag_edit_cache ag_edit_cache;
typedef struct {
    ag_proceduralize_result *proc;  /* owned */
    ag_proceduralize_options opt;   /* used for every re-proceduralization */
    ag_edit_cache *cache;           /* private: kept factorization for drags */
} ag_edit_model;

/* Proceduralizes mesh (opt may be NULL: defaults). */
ag_status ag_edit_model_create(const ag_mesh *mesh, const ag_proceduralize_options *opt,
                               ag_edit_model **out, ag_error *err);
/* Derives g (terminals need their geometry) and proceduralizes the derived mesh: node ids
 * then refer to the tree that a later load of the same grammar gives again (derivation
 * order), which is how a model written by ag_edit_apply or `archgram proceduralize` is read
 * back. */
ag_status ag_edit_model_from_grammar(const ag_grammar *g, const ag_proceduralize_options *opt,
                                     ag_edit_model **out, ag_error *err);
/* Takes ownership of r. */
ag_status ag_edit_model_wrap(ag_proceduralize_result *r, const ag_proceduralize_options *opt,
                             ag_edit_model **out, ag_error *err);
void ag_edit_model_free(ag_edit_model *m);

/* Applies op: the edited tree rebuilt into the new model, then derives its grammar and
 * proceduralizes that again (so the new model's ids are those a reload of its grammar gives,
 * see ag_edit_model_from_grammar), returns the new model and fills rep (instances per label
 * counted on the new model's tree, named as its grammar's labels). The input model is
 * unchanged. */
ag_status ag_edit_apply(ag_edit_model *m, const ag_edit_op *op, ag_edit_model **out,
                        ag_edit_report *rep, ag_error *err);

typedef enum {
    /* read the result back through its grammar (a second proceduralization) so its ids are
     * those a reload of the grammar gives: for callers that keep no model between edits
     * (the CLI). A caller that keeps the returned model and maps ids itself (the service)
     * leaves it out and saves the second run. */
    AG_EDIT_READ_BACK = 1,
    /* make the operation's mesh and proceduralize it again (every node renumbered) instead of
     * rebuilding the edited tree: for comparisons and benchmarks */
    AG_EDIT_MESH_PATH = 2,
} ag_edit_apply_flags;

/* ag_edit_apply is ag_edit_apply_ex(..., AG_EDIT_READ_BACK, ...). */
ag_status ag_edit_apply_ex(ag_edit_model *m, const ag_edit_op *op, unsigned flags,
                           ag_edit_model **out, ag_edit_report *rep, ag_error *err);

/* Live drag of a resize: solves for op's target reusing the model's factorization when only
 * the target moved since the last call (same node, mode and region), and returns the new box
 * of every tree node (*boxes: malloc'd, model->proc->tree->nnodes entries; dead nodes keep
 * their box). No re-proceduralization and no pattern split/join: commit with ag_edit_apply. */
ag_status ag_edit_preview(ag_edit_model *m, const ag_edit_op *op, ag_box **boxes,
                          ag_edit_report *rep, ag_error *err);

#endif
