/* ag_plan → building description JSON (schema/plan.md), the inverse of io/plan_json.h:
 * reading the output back gives the same profiles, loops, anchors, steps, cap height and
 * priority scheme (numbers are written with full precision). */
#ifndef AG_PLAN_WRITE_H
#define AG_PLAN_WRITE_H

#include <jansson.h>

#include "../core/extrude/plan.h"
#include "../core/status.h"

/* *out is a new reference. AG_ERR_INVALID when two profiles share a name (JSON names them)
 * or an edge names no profile. */
ag_status ag_plan_write_json(const ag_plan *p, json_t **out, ag_error *err);

#endif
