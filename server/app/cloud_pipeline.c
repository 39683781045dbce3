#include "cloud_pipeline.h"

#include <stdlib.h>
#include <string.h>

#include "../store/models.h"
#include "points_proc_options.h"
#include "usecase_points.h"

/* The point pipeline of `archgram proceduralize CLOUD` (app/usecase_points.h): segments,
 * automatic repetition, consensus terminals, the split tree, rules, patterns and grammar. */
static ag_status proceduralize(ag_workspace *ws, const char *options, ag_error *err)
{
    json_t *o = options ? json_loads(options, 0, NULL) : NULL;
    if (options && !o)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "the job's point cloud options do not read");
    ag_usecase_points_proceduralize_params p;
    ag_box *boxes = NULL;
    ag_status s = ag_points_proc_options_read(o, &p, &boxes, err);
    json_decref(o);
    ag_usecase_points_proceduralize_result r;
    if (s == AG_OK)
        s = ag_usecase_points_proceduralize_run(ws, &p, &r, err);
    free(boxes);
    return s;
}

ag_status ag_cloud_pipeline_check_options(int64_t model, int cloud, const json_t *options,
                                          char **text, ag_error *err)
{
    *text = NULL;
    if (!cloud) {
        const char *key = json_object_iter_key(json_object_iter((json_t *)options));
        if (key && ag_points_proc_options_is_key(key))
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "\"%s\": model %lld is a mesh; templates, rois and auto are "
                                "options of point clouds",
                                key, (long long)model);
        return ag_error_set(err, AG_ERR_INVALID, 0, "\"%s\" is not an option of proceduralize",
                            key ? key : "");
    }
    ag_usecase_points_proceduralize_params p;
    ag_box *boxes = NULL;
    ag_status s = ag_points_proc_options_read(options, &p, &boxes, err);
    free(boxes);
    if (s == AG_OK && !(*text = json_dumps(options, JSON_COMPACT)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return s;
}

const ag_cloud_proceduralize_fn ag_cloud_pipeline_proceduralize = proceduralize;

ag_status ag_cloud_pipeline_missing(int64_t model, const char *step, ag_error *err)
{
    if (strcmp(step, "proceduralize") == 0)
        return ag_error_set(err, AG_ERR_NOT_AVAILABLE, 0,
                            "model %lld is a point cloud: proceduralizing point clouds needs "
                            "consensus terminals and the point split tree (§4 of the point "
                            "cloud paper), which this archgramd does not have yet; segment it "
                            "(POST /api/v1/models/%lld/segment) and mark templates",
                            (long long)model, (long long)model);
    return ag_error_set(err, AG_ERR_NOT_AVAILABLE, 0,
                        "model %lld is a point cloud: %s is not available for point clouds yet",
                        (long long)model, step);
}

ag_status ag_cloud_pipeline_is_cloud(struct ag_db *db, int64_t model, int *cloud, ag_error *err)
{
    *cloud = 0;
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s == AG_OK) {
        *cloud = strcmp(row.kind, "pointcloud") == 0;
        ag_models_row_clear(&row);
    }
    return s;
}
