#include "proceduralize_job.h"

#include "cloud_pipeline.h"
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
    ag_store_ws w;
    ag_store_ws_init_job(&w, &env, ctx, job, pj->model, pj->base, pj->author);
    int cloud = 0;
    s = ag_cloud_pipeline_is_cloud(env.db, pj->model, &cloud, err);
    ag_usecase_proceduralize_result r;
    ag_usecase_proceduralize_params up = {
        .max_triangles = ag_work_limits_resolved(env.limits).max_triangles};
    up.label.exact_copies = pj->exact;
    up.label.metres_per_unit = pj->metres_per_unit;
    if (s == AG_OK && cloud)
        s = ag_cloud_pipeline_proceduralize ? ag_cloud_pipeline_proceduralize(&w.ws, pj->cloud, err)
                                            : ag_cloud_pipeline_missing(pj->model, "proceduralize",
                                                                        err);
    else if (s == AG_OK)
        s = ag_usecase_proceduralize_run(&w.ws, &up, &r, err);
    ag_store_ws_end(&w, s);
    return s;
}

const ag_job_kind ag_proceduralize_job_kind = {.kind = "proceduralize", .run = run};
