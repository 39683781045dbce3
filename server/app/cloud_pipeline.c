#include "cloud_pipeline.h"

#include <string.h>

#include "../store/models.h"

/* Not built yet: consensus terminals and the point split tree come from the point pipeline's
 * later stages (§4 of the point cloud paper). */
const ag_cloud_proceduralize_fn ag_cloud_pipeline_proceduralize = NULL;

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
