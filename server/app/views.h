/* The JSON representations of resources and problems, shared by REST and the live layer. */
#ifndef AG_VIEWS_H
#define AG_VIEWS_H

#include <jansson.h>

#include "../core/status.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "../store/ops.h"

json_t *ag_view_model(const ag_model_row *row);
json_t *ag_view_job(const ag_job_row *row);
json_t *ag_view_op(const ag_op_row *op);
/* RFC 9457 problem object: type urn:archgram:problem:<slug>, title, status, detail
 * (err->text or the status message) and, when err->element > 0, "line" for parse errors
 * or "element" otherwise. */
json_t *ag_view_problem(ag_status status, const ag_error *err);
/* A problem as compact JSON text (malloc'd). */
char *ag_view_problem_text(ag_status status, const ag_error *err);

#endif
