#include "import_job.h"

#include <string.h>

#include "store_ws.h"
#include "usecase_import.h"
#include "usecase_import_cloud.h"

static ag_up_axis up_from(const char *s)
{
    if (s && (strcmp(s, "z") == 0 || strcmp(s, "Z") == 0))
        return AG_UP_Z;
    if (s && (strcmp(s, "y") == 0 || strcmp(s, "Y") == 0))
        return AG_UP_Y;
    return AG_UP_DEFAULT; /* absent or "auto": the format, else the content decides */
}

static ag_status run(void *services, ag_jobctx *ctx, int64_t job, const ag_job_params *p,
                     ag_error *err)
{
    if (p->type != AG_JOB_IMPORT)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "an import job without import params");
    const ag_import_job *ij = &p->u.import;
    ag_store_env env;
    ag_status s = ag_store_services_env(services, &env, err);
    if (s != AG_OK)
        return s;
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .job = ctx, .job_id = job});
    ag_mesh_source src = {.path = ij->upload,
                          .format = ij->format,
                          .filename = ij->filename,
                          .up = up_from(ij->up),
                          .what = "the uploaded file",
                          .format_hint = "name it with ?format=",
                          /* assimp apart: its loops, crashes and leaks end with the child */
                          .sandbox_seconds = ag_work_limits_resolved(env.limits).import_seconds};
    int64_t model = 0;
    s = ag_usecase_import_cloud_accepts(&src)
            ? ag_usecase_import_cloud_run(&w.ws, &src, ij->name, &model, err)
            : ag_usecase_import_run(&w.ws, &src, ij->name, &model, err);
    ag_store_ws_end(&w, s);
    return s;
}

const ag_job_kind ag_import_job_kind = {.kind = "import", .run = run};
