/* The JSON representations of stored resources (models, jobs, ops), as the REST and live
 * layers serve them (through app/app_query.h). Problems: app/problem.h. */
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

#endif
