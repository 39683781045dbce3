/* The op log: one row per model version after the first, the op that made it. */
#ifndef AG_OPS_H
#define AG_OPS_H

#include <stdint.h>

#include "db.h"

typedef struct {
    int64_t model;
    int64_t version;
    const char *author;
    const char *cid;
    const char *kind;
    const char *body_json;
    const char *at;
} ag_op_row;

/* Inside the caller's transaction, after ag_models_bump_version gave `version`. */
ag_status ag_ops_insert(ag_db *db, const ag_op_row *op, ag_error *err);
/* The version an (author, cid) pair got on a model, or 0 when it is new. */
ag_status ag_ops_find_cid(ag_db *db, int64_t model, const char *author, const char *cid,
                          int64_t *version, ag_error *err);
/* Calls fn for each op with version > since, oldest first, at most limit (0 = all);
 * the row's strings live until fn returns. */
ag_status ag_ops_each_since(ag_db *db, int64_t model, int64_t since, int64_t limit,
                            void (*fn)(void *user, const ag_op_row *op), void *user,
                            ag_error *err);

#endif
