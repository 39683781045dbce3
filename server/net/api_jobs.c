/* GET and DELETE /api/v1/jobs/{id}. */
#include "../app/app_jobs.h"
#include "routes.h"

enum MHD_Result ag_api_job_get(ag_request *r)
{
    return ag_reply_job(r, r->ids[0], 200);
}

enum MHD_Result ag_api_job_cancel(ag_request *r)
{
    ag_error err;
    ag_status s = ag_app_jobs_cancel(r->cfg->app, r->ids[0], &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    return ag_reply_job(r, r->ids[0], 200);
}
