#include "proceduralize_job.h"

#include <stdio.h>

#include "store_ws.h"
#include "usecase_proceduralize.h"

static ag_status run(void *services, ag_jobctx *ctx, int64_t job, const ag_job_params *p,
                     ag_error *err)
{
    if (p->type != AG_JOB_PROCEDURALIZE)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "a proceduralize job without its params");
    const ag_proceduralize_job *pj = &p->u.proceduralize;
    ag_store_env env;
    ag_status s = ag_store_services_env(services, &env, err);
    if (s != AG_OK)
        return s;
    char cid[48];
    snprintf(cid, sizeof cid, "job-%lld", (long long)job);
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env,
                                                .model = pj->model,
                                                .base = pj->base,
                                                .author = pj->author,
                                                .cid = cid,
                                                .job = ctx,
                                                .job_id = job});
    ag_usecase_proceduralize_result r;
    ag_usecase_proceduralize_params up = {0};
    up.label.exact_copies = pj->exact;
    s = ag_usecase_proceduralize_run(&w.ws, &up, &r, err);
    ag_store_ws_end(&w, s);
    return s;
}

const ag_job_kind ag_proceduralize_job_kind = {.kind = "proceduralize", .run = run};
