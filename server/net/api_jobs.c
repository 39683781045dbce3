/* GET and DELETE /api/v1/jobs/{id}. */
#include "../app/jobqueue.h"
#include "../app/views.h"
#include "../store/jobs.h"
#include "routes.h"

static enum MHD_Result reply_job(ag_request *r, int64_t id)
{
    ag_error err;
    ag_db *db = ag_app_db(r->cfg->app, &err);
    if (!db)
        return ag_reply_problem(r, err.code, &err);
    ag_job_row row;
    ag_status s = ag_jobs_get(db, id, &row, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    json_t *body = ag_view_job(&row);
    ag_jobs_row_clear(&row);
    return ag_reply_json(r, 200, body, NULL);
}

enum MHD_Result ag_api_job_get(ag_request *r)
{
    return reply_job(r, r->ids[0]);
}

enum MHD_Result ag_api_job_cancel(ag_request *r)
{
    ag_error err;
    ag_status s = ag_jobqueue_cancel(r->cfg->app, r->ids[0], &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return reply_job(r, r->ids[0]);
}
