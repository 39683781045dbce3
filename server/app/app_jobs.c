#include "app_jobs.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../core/extrude/style.h"
#include "../core/proc/units.h"
#include "../io/cloud_import.h"
#include "../io/import.h"
#include "../store/pointclouds.h"
#include "app_query.h"
#include "cloud_pipeline.h"
#include "cloud_state.h"
#include "modelops.h"
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
    if (s == AG_OK && p->format && ag_format_from_name(p->format) == AG_FORMAT_UNKNOWN &&
        ag_cloud_format_from_name(p->format) == AG_CLOUD_FORMAT_UNKNOWN)
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                         "unknown format \"%s\"; archgram reads obj, ply, stl, gltf, glb, fbx and "
                         "dae meshes and ply, las, laz and xyz point clouds",
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
                                    const int64_t *if_match,
                                    const ag_app_mesh_proc_options *mesh,
                                    const json_t *cloud_options, int64_t *job, ag_error *err)
{
    int exact = mesh && mesh->exact;
    double metres_per_unit = 0;
    if (mesh && mesh->unit && ag_units_named(mesh->unit, &metres_per_unit))
        return ag_error_set(err, AG_ERR_INVALID, 0, "\"unit\": the length unit of the mesh, "
                            AG_UNITS_NAMES " (or left out: decided from the content)");
    int64_t current;
    ag_status s = ag_app_query_version(app, model, &current, err);
    if (s != AG_OK)
        return s;
    if (if_match && *if_match != -1 && *if_match != current)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "model %lld is at version %lld, not %lld", (long long)model,
                            (long long)current, (long long)*if_match);
    int cloud = 0;
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    if ((s = ag_cloud_pipeline_is_cloud(db, model, &cloud, err)) != AG_OK)
        return s;
    if (cloud && !ag_cloud_pipeline_proceduralize)
        return ag_cloud_pipeline_missing(model, "proceduralize", err);
    if (cloud && exact)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "\"exact\": model %lld is a point cloud; its terminals are consensus "
                            "models of each label's members, exact is an option of meshes",
                            (long long)model);
    if (cloud && metres_per_unit > 0)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "\"unit\": model %lld is a point cloud, read in metres; unit is an "
                            "option of meshes",
                            (long long)model);
    ag_pointcloud_info info;
    if (cloud && (s = ag_pointclouds_info(db, model, &info, err)) != AG_OK)
        return s;
    if (cloud && info.points > AG_CLOUD_MAX_SEGMENT_POINTS) /* the pipeline segments it first */
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "model %lld holds %zu points; archgram proceduralizes at most %zu at "
                            "once (cut it into buildings first: archgram cut)",
                            (long long)model, info.points, AG_CLOUD_MAX_SEGMENT_POINTS);
    char *options = NULL;
    if (cloud_options && json_object_size(cloud_options) &&
        (s = ag_cloud_pipeline_check_options(model, cloud, cloud_options, &options, err)) != AG_OK)
        return s;
    ag_job_params jp = {.type = AG_JOB_PROCEDURALIZE,
                        .user = who->user,
                        .u.proceduralize = {.model = model, .base = current,
                                            .author = (char *)who->name, .exact = exact != 0,
                                            .metres_per_unit = metres_per_unit,
                                            .cloud = options}};
    s = submit(app, &jp, NULL, job, err);
    free(options);
    return s;
}

/* An optional fraction of the diagonal in (0, 1). */
static ag_status fraction(const json_t *body, const char *name, double *v, ag_error *err)
{
    const json_t *j = json_object_get(body, name);
    *v = 0;
    if (!j)
        return AG_OK;
    *v = json_number_value(j);
    if (!json_is_number(j) || !(*v > 0 && *v < 1))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%s: a fraction of the cloud's diagonal between 0 and 1 is needed",
                            name);
    return AG_OK;
}

ag_status ag_app_jobs_segment(ag_app *app, const ag_identity *who, int64_t model,
                              const int64_t *if_match, const json_t *body, int64_t *job,
                              ag_error *err)
{
    static const char *const allowed[] = {"threshold", "coarse_threshold", "cluster_tolerance",
                                          "recompute_normals", NULL};
    ag_segment_job sj = {.model = model, .author = (char *)who->name};
    ag_status s = json_is_object(body) ? AG_OK
                                       : ag_error_set(err, AG_ERR_INVALID, 0,
                                                      "the body must be a JSON object");
    if (s == AG_OK)
        s = ag_modelops_only_members(body, allowed, err);
    if (s == AG_OK)
        s = fraction(body, "threshold", &sj.threshold, err);
    if (s == AG_OK)
        s = fraction(body, "coarse_threshold", &sj.coarse_threshold, err);
    if (s == AG_OK)
        s = fraction(body, "cluster_tolerance", &sj.cluster_tolerance, err);
    const json_t *rn = json_object_get(body, "recompute_normals");
    if (s == AG_OK && rn && !json_is_boolean(rn))
        s = ag_error_set(err, AG_ERR_INVALID, 0, "recompute_normals: true or false");
    sj.recompute_normals = json_is_true(rn);
    if (s != AG_OK)
        return s;
    int64_t current;
    if ((s = ag_app_query_version(app, model, &current, err)) != AG_OK)
        return s;
    if (if_match && *if_match != -1 && *if_match != current)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "model %lld is at version %lld, not %lld", (long long)model,
                            (long long)current, (long long)*if_match);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    int cloud = 0;
    if ((s = ag_cloud_pipeline_is_cloud(db, model, &cloud, err)) != AG_OK)
        return s;
    if (!cloud)
        return ag_error_set(err, AG_ERR_CONFLICT, 0,
                            "model %lld is not a point cloud: segmentation works on point clouds "
                            "(meshes are segmented by proceduralize)",
                            (long long)model);
    ag_pointcloud_info info;
    if ((s = ag_pointclouds_info(db, model, &info, err)) != AG_OK)
        return s;
    if (info.points > AG_CLOUD_MAX_SEGMENT_POINTS)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                            "model %lld holds %zu points; archgram segments at most %zu at once "
                            "(cut it into buildings first: archgram cut)",
                            (long long)model, info.points, AG_CLOUD_MAX_SEGMENT_POINTS);
    sj.base = current;
    ag_job_params jp = {.type = AG_JOB_SEGMENT, .user = who->user, .u.segment = sj};
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
