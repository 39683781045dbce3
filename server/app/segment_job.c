#include "segment_job.h"

#include "store_ws.h"
#include "usecase_segment.h"

static ag_status run(void *services, ag_jobctx *ctx, int64_t job, const ag_job_params *p,
                     ag_error *err)
{
    if (p->type != AG_JOB_SEGMENT)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "a segment job without its params");
    const ag_segment_job *sj = &p->u.segment;
    ag_store_env env;
    ag_status s = ag_store_services_env(services, &env, err);
    if (s != AG_OK)
        return s;
    ag_store_ws w;
    ag_store_ws_init_job(&w, &env, ctx, job, sj->model, sj->base, sj->author);
    ag_usecase_segment_params sp = {.threshold = sj->threshold,
                                    .coarse_threshold = sj->coarse_threshold,
                                    .cluster_tolerance = sj->cluster_tolerance,
                                    .recompute_normals = sj->recompute_normals};
    s = ag_usecase_segment_run(&w.ws, &sp, NULL, err);
    ag_store_ws_end(&w, s);
    return s;
}

const ag_job_kind ag_segment_job_kind = {.kind = "segment", .run = run};
