/* Plan and profile edits of extrusion models, as ops (validated and applied by
 * app/modelops.c like every op from their rows of the op table, app/optable.h, inside the
 * transaction that raises the version):
 *
 *   {"kind": "plan", "building": i, "plan": {...}}   replaces building i's description
 *   {"kind": "profile", "name": "...", "profile": [[w, z], ...] | {"points", "tag", "priority"}}
 *                                                    replaces that profile in every building
 *                                                    whose description has it
 *
 * Only the buildings an op touches are extruded again (app/extrusion.h: under the service's
 * budget, stopped on shutdown); the model's mesh is re-assembled from the stored buildings.
 * A description that does not parse or validate refuses the whole op (AG_ERR_PARSE, 422,
 * naming the building and the reason) and nothing is stored; only a building that had
 * already failed before a profile op (a batch's bad footprint) may stay failed. A building
 * whose new description does not give a good building (not a closed 2-manifold, reaching
 * outside its footprint, over its budget) falls back to a flat roof or a block, stored with
 * the reason and the fallback, as the extrude job does. */
#ifndef AG_PLAN_EDIT_H
#define AG_PLAN_EDIT_H

#include <jansson.h>
#include <stdint.h>

#include "../core/status.h"
#include "../store/db.h"

/* The op's shape and its description or profile (parsed and validated without a model). */
ag_status ag_plan_edit_validate(const json_t *op, ag_error *err);

/* Applies a validated op to the model inside the caller's transaction. AG_ERR_INVALID when
 * the model is not an extrusion, has no such building or no building uses the profile. */
ag_status ag_plan_edit_apply(ag_db *db, int64_t model, const json_t *op, ag_error *err);

#endif
