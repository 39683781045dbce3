#include "app_jobs.h"

#include <string.h>
#include <unistd.h>

#include "../core/extrude/style.h"
#include "../io/import.h"
#include "app_query.h"
#include "jobqueue.h"

static ag_status submit(ag_app *app, const ag_job_params *p, const char *upload, int64_t *job,
                        ag_error *err)
{
    ag_status s = ag_jobqueue_submit(ag__app_jobqueue(app), ag_job_params_kind(p->type), p, job,
                                     err);
    if (s != AG_OK && upload)
        unlink(upload);
    return s;
}

ag_status ag_app_jobs_check_import(const ag_import_job *p, ag_error *err)
{
    ag_status s = ag_app_check_name(p->name, err);
    if (s == AG_OK && p->format && ag_format_from_name(p->format) == AG_FORMAT_UNKNOWN)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                         "unknown format \"%s\"; archgram reads obj, ply, stl, gltf, glb, fbx and "
                         "dae",
                         p->format);
    if (s == AG_OK && p->up && strcmp(p->up, "y") != 0 && strcmp(p->up, "z") != 0 &&
        strcmp(p->up, "auto") != 0)
        s = ag_error_set(err, AG_ERR_INVALID, 0, "up must be \"auto\", \"y\" or \"z\", not \"%s\"",
                         p->up);
    return s;
}

ag_status ag_app_jobs_import(ag_app *app, const ag_identity *who, const ag_import_job *p,
                             int64_t *job, ag_error *err)
{
    ag_status s = ag_app_jobs_check_import(p, err);
    if (s != AG_OK) {
        if (p->upload)
            unlink(p->upload);
        return s;
    }
    ag_job_params jp = {.type = AG_JOB_IMPORT, .user = who->user, .u.import = *p};
    return submit(app, &jp, p->upload, job, err);
}

ag_status ag_app_jobs_proceduralize(ag_app *app, const ag_identity *who, int64_t model,
                                    const int64_t *if_match, int exact, int64_t *job,
                                    ag_error *err)
{
    int64_t current;
    ag_status s = ag_app_query_version(app, model, &current, err);
    if (s != AG_OK)
        return s;
    if (if_match && *if_match != -1 && *if_match != current)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "model %lld is at version %lld, not %lld", (long long)model,
                            (long long)current, (long long)*if_match);
    ag_job_params jp = {.type = AG_JOB_PROCEDURALIZE,
                        .user = who->user,
                        .u.proceduralize = {.model = model, .base = current,
                                            .author = (char *)who->name, .exact = exact != 0}};
    return submit(app, &jp, NULL, job, err);
}

ag_status ag_app_jobs_check_extrude(const ag_extrude_job *p, ag_error *err)
{
    ag_status s = ag_app_check_name(p->name, err);
    if (s == AG_OK && p->format && strcmp(p->format, "plan") != 0 &&
        strcmp(p->format, "buildings") != 0 && strcmp(p->format, "geojson") != 0)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                         "unknown format \"%s\"; extrusions read plan, buildings and geojson",
                         p->format);
    ag_style probe;
    if (s == AG_OK && p->style && ag_style_builtin(p->style, &probe, NULL) != AG_OK)
        s = ag_error_set(err, AG_ERR_INVALID, 0,
                         "unknown style \"%s\"; the styles are flat, hip, gable, mansard and "
                         "overhang",
                         p->style);
    return s;
}

ag_status ag_app_jobs_extrude(ag_app *app, const ag_identity *who, const ag_extrude_job *p,
                              int64_t *job, ag_error *err)
{
    ag_status s = ag_app_jobs_check_extrude(p, err);
    if (s != AG_OK) {
        if (p->upload)
            unlink(p->upload);
        return s;
    }
    ag_job_params jp = {.type = AG_JOB_EXTRUDE, .user = who->user, .u.extrude = *p};
    if (!jp.u.extrude.style)
        jp.u.extrude.style = "hip";
    return submit(app, &jp, p->upload, job, err);
}

ag_status ag_app_jobs_cancel(ag_app *app, int64_t job, ag_error *err)
{
    return ag_jobqueue_cancel(ag__app_jobqueue(app), job, err);
}
