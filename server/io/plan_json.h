/* The building description JSON (schema/plan.schema.json, documented in schema/plan.md)
 * ↔ ag_plan, and the batch style JSON → ag_style. Errors name the JSON element. */
#ifndef AG_PLAN_JSON_H
#define AG_PLAN_JSON_H

#include <stddef.h>

#include "../core/extrude/plan.h"
#include "../core/extrude/style.h"
#include "../core/status.h"

/* A description from the network or memory: it may not name mesh files ("meshes"). */
ag_status ag_plan_json_read_buffer(const char *data, size_t len, ag_plan **out, ag_error *err);
/* A trusted description whose mesh files are relative to folder dir. */
ag_status ag_plan_json_read_buffer_in(const char *data, size_t len, const char *dir, ag_plan **out,
                                      ag_error *err);
ag_status ag_plan_json_read_file(const char *path, ag_plan **out, ag_error *err);

/* Style file: {"name", "height", "cap", "seed", "short_below", "long_above", "street",
 * "profiles": {name: [[w, dz], ...]}, "rules": [{"length", "orientation", "axis",
 * "profiles": {name: weight}}]}. */
ag_status ag_plan_json_read_style_buffer(const char *data, size_t len, ag_style *out,
                                         ag_error *err);
ag_status ag_plan_json_read_style_file(const char *path, ag_style *out, ag_error *err);

#endif
