/* Edit op JSON (schema/edit_ops.md) ↔ ag_edit_op. The same text travels on the websocket,
 * in POST /models/{id}/ops and in `archgram edit --op`. Errors start with the offending
 * field ("box: ...", "nodes[2]: ..."); unknown fields are refused so that a typo is never
 * silently ignored. Node references are an index, its decimal string, or "root". */
#ifndef AG_EDIT_OP_JSON_H
#define AG_EDIT_OP_JSON_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "../core/edit/edit.h"
#include "../core/status.h"

/* Where a paste's source lives when it is not the edited model: another model of the service
 * ("source_model": its id, nodes named by that model's tree) or another proceduralized folder
 * ("source_dir": a path, for `archgram edit`). At most one of the two; op->source is left
 * NULL for the caller to fill once it has loaded that model. */
typedef struct {
    int64_t model; /* "source_model" (>= 1), else 0 */
    char *dir;     /* "source_dir", malloc'd, else NULL */
} ag_edit_op_origin;

void ag_edit_op_origin_clear(ag_edit_op_origin *o);

/* On success *op holds the op (free its arrays with ag_edit_op_clear). These refuse
 * "source_model" and "source_dir" (the caller could not honour them). */
ag_status ag_edit_op_json_parse(const char *text, size_t len, ag_edit_op *op, ag_error *err);
ag_status ag_edit_op_json_from(const json_t *obj, ag_edit_op *op, ag_error *err);
/* Reads a whole file (limit 1 MiB); errors as for parse (element = line for syntax). */
ag_status ag_edit_op_json_read_file(const char *path, ag_edit_op *op, ag_error *err);

/* The same, also accepting a paste's "source_model" / "source_dir" into *origin (cleared
 * first; free it with ag_edit_op_origin_clear). */
ag_status ag_edit_op_json_parse_ex(const char *text, size_t len, ag_edit_op *op,
                                   ag_edit_op_origin *origin, ag_error *err);
ag_status ag_edit_op_json_from_ex(const json_t *obj, ag_edit_op *op, ag_edit_op_origin *origin,
                                  ag_error *err);
ag_status ag_edit_op_json_read_file_ex(const char *path, ag_edit_op *op,
                                       ag_edit_op_origin *origin, ag_error *err);

/* The canonical JSON object of an op (new reference), or NULL when out of memory. */
json_t *ag_edit_op_json_to(const ag_edit_op *op);
/* The same with the paste's origin (may be NULL). */
json_t *ag_edit_op_json_to_ex(const ag_edit_op *op, const ag_edit_op_origin *origin);

/* The report as JSON: {"equations","unknowns","solve_ms","max_residual",
 * "max_residual_relative","splits","joins","instances_per_label":{name: count},"message"}. */
json_t *ag_edit_op_json_report(const ag_edit_report *rep);

#endif
