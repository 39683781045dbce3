/* Composing a part into a model as an op: the "compose" row of the op table (app/optable.h),
 * client-sent, undoable, on the structural lane:
 *
 *   {"kind":"compose","part":P,"version":V,"target":N,"mode":"replace"|"insert"|"fill",
 *    "scope":"node"|"rule"}
 *
 * P is a part of the library (its newest version when "version" is left out), N a node of
 * the model's tree at the op's base ("root" for node 0); scope defaults to "node". The
 * composition use case (app/usecase_compose.h) runs on the store workspace: one new version
 * with the composed grammar, its terminals and the tree of what it derives, logged as the op
 * with the part version it used ("version" filled in) and the composition's report
 * ({"part","root_rule","target_rule","instances","counts","turn","fitted","grammar","fit",
 * "message","compose_ms","state_ms"}), undone like an edit. */
#ifndef AG_COMPOSE_OPS_H
#define AG_COMPOSE_OPS_H

#include <jansson.h>
#include <stdint.h>

#include "../core/mesh.h"
#include "optable.h"
#include "store_env.h"
#include "workspace.h"

/* The op's shape; ref and cop (may be NULL) receive what it names. */
ag_status ag_compose_ops_parse(const json_t *op, ag_part_ref *ref, ag_compose_op *cop,
                               ag_error *err);
ag_status ag_compose_ops_validate(const json_t *op, ag_error *err);

/* The whole op, as ag_modelops_apply (duplicate, stale and version semantics). */
ag_status ag_compose_ops_run(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
                             int *duplicate, ag_error *err);

/* The op composed on version base without storing anything: *mesh is what the new version
 * would derive (one component per placed terminal, grouped by label), *report the
 * composition's report (a new object). AG_ERR_STALE (the current version in err->element)
 * when base is not the model's version. */
ag_status ag_compose_ops_preview(const ag_store_env *env, int64_t model, int64_t base,
                                 const json_t *op, ag_mesh **mesh, json_t **report,
                                 ag_error *err);

#endif
