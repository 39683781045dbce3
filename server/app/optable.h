/* The op table: every kind of op a model's log can hold, once, with what the REST and live
 * layers need to know about it (the model is Redis's command table). A new kind (point-cloud
 * ops) is a new row.
 *
 *   kind       the "kind" member of the op JSON
 *   validate   the op's shape, without a model (parsers name the offending field)
 *   effect     fast kinds: the change, inside the transaction that raises the version
 *   run        structural kinds: the whole op, computed outside the commit lock, then
 *              committed as one change (app/edit_ops.h); effect is NULL for them
 *   flags      AG_OP_CLIENT: clients may send it (else the server makes it, see made_by);
 *              AG_OP_UNDOABLE: an undo step of its author; AG_OP_GEOMETRY: it changes the
 *              model's geometry (another person's later op of such a kind blocks an undo)
 *   lane       AG_OP_FAST: applied at once on the thread that received it;
 *              AG_OP_STRUCTURAL: may take long (a model is loaded and proceduralized, a
 *              batch re-extruded): the live layer runs it on the job queue's fast lane
 *   made_by    server-made kinds: the REST call that makes them (named in the refusal)
 *   rebase     how a live op of the kind made on an older version is applied to the current
 *              one when nothing since conflicts with it (app/rebase.h) */
#ifndef AG_OPTABLE_H
#define AG_OPTABLE_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "task_budget.h"

/* declared, not included: the live layer reads the table without seeing the store */
struct ag_db;
struct ag_store_env;

enum {
    AG_OP_CLIENT = 1u << 0,
    AG_OP_UNDOABLE = 1u << 1,
    AG_OP_GEOMETRY = 1u << 2,
};

typedef enum { AG_OP_FAST = 0, AG_OP_STRUCTURAL = 1 } ag_op_lane;

/* How a live op made on an older version is brought onto the current one (app/rebase.h). */
typedef enum {
    AG_REBASE_NEVER = 0,
    AG_REBASE_ALWAYS,
    AG_REBASE_UNLESS_SAME,
    AG_REBASE_OVER_CONTENT,
    AG_REBASE_NODES,
} ag_op_rebase;

/* One op as a client (or the server) asks for it. */
typedef struct {
    int64_t model;
    int64_t base;       /* the version the op was made on */
    const char *author;
    const char *cid;    /* the client's id of the op: one use per author and model */
    const json_t *op;
    uint64_t origin;    /* the live session it came from, 0 = none */
    ag_task_budget *budget; /* the time it may take and whether to stop; NULL = no limit */
    /* base is what the client had seen (a live op): rebase it onto the current version when
     * nothing since conflicts (app/rebase.h). 0: base is a precondition (REST If-Match). */
    int rebase;
} ag_op_request;

typedef struct {
    const char *kind;
    ag_status (*validate)(const json_t *op, ag_error *err);
    ag_status (*effect)(struct ag_db *db, int64_t model, const json_t *op, ag_error *err);
    ag_status (*run)(const struct ag_store_env *env, const ag_op_request *rq, int64_t *version,
                     int *duplicate, ag_error *err);
    unsigned flags;
    ag_op_lane lane;
    const char *made_by;
    ag_op_rebase rebase;
} ag_op_kind;

extern const ag_op_kind ag_optable[];
extern const size_t ag_optable_count;

/* The row of kind, NULL when there is none. */
const ag_op_kind *ag_optable_find(const char *kind);
/* The row of op's kind: AG_ERR_INVALID when op is not an object with a known string kind. */
ag_status ag_optable_lookup(const json_t *op, const ag_op_kind **row, ag_error *err);

#endif
