#include "cloud_ops.h"

#include <math.h>
#include <string.h>

#include "../store/ops.h"
#include "modelops.h"
#include "store_ws.h"
#include "usecase_mark_template.h"
#include "usecase_segment.h"

/* "box": six finite numbers, min <= max on each axis. */
static ag_status read_box(const json_t *op, double box[6], ag_error *err)
{
    const json_t *b = json_object_get(op, "box");
    if (!json_is_array(b) || json_array_size(b) != 6)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "box: an array [x0, y0, z0, x1, y1, z1] of six numbers is needed");
    for (size_t k = 0; k < 6; k++) {
        const json_t *v = json_array_get(b, k);
        box[k] = json_number_value(v);
        if (!json_is_number(v) || !isfinite(box[k]))
            return ag_error_set(err, AG_ERR_INVALID, (long)k + 1,
                                "box[%zu] is not a finite number", k);
    }
    for (int a = 0; a < 3; a++)
        if (box[a] > box[3 + a])
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "box: its minimum %g lies above its maximum %g on axis %c",
                                box[a], box[3 + a], "xyz"[a]);
    return AG_OK;
}

/* An optional fraction of the diagonal: 0 when absent. */
static ag_status read_fraction(const json_t *op, const char *name, double *v, ag_error *err)
{
    const json_t *j = json_object_get(op, name);
    *v = 0;
    if (!j)
        return AG_OK;
    *v = json_number_value(j);
    if (!json_is_number(j) || !(*v > 0 && *v < 1))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%s: a fraction of the diagonal between 0 and 1 is needed", name);
    return AG_OK;
}

static ag_status read_roi(const json_t *op, double box[6], ag_usecase_segment_params *p,
                          ag_error *err)
{
    static const char *const allowed[] = {"kind", "box", "threshold", "coarse_threshold",
                                          "cluster_tolerance", NULL};
    memset(p, 0, sizeof *p);
    ag_status s = ag_modelops_only_members(op, allowed, err);
    if (s == AG_OK)
        s = read_box(op, box, err);
    if (s == AG_OK)
        s = read_fraction(op, "threshold", &p->threshold, err);
    if (s == AG_OK)
        s = read_fraction(op, "coarse_threshold", &p->coarse_threshold, err);
    if (s == AG_OK)
        s = read_fraction(op, "cluster_tolerance", &p->cluster_tolerance, err);
    return s;
}

static ag_status read_template(const json_t *op, int32_t *segment, double box[6], ag_error *err)
{
    static const char *const allowed[] = {"kind", "segment", "box", NULL};
    ag_status s = ag_modelops_only_members(op, allowed, err);
    const json_t *seg = json_object_get(op, "segment");
    if (s == AG_OK && (!json_is_integer(seg) || json_integer_value(seg) < 0 ||
                       json_integer_value(seg) > INT32_MAX))
        s = ag_error_set(err, AG_ERR_INVALID, 0,
                         "segment: the id of a segment of the cloud (0, 1, ...) is needed");
    if (s == AG_OK)
        *segment = (int32_t)json_integer_value(seg);
    return s == AG_OK ? read_box(op, box, err) : s;
}

ag_status ag_cloud_ops_validate_roi(const json_t *op, ag_error *err)
{
    double box[6];
    ag_usecase_segment_params p;
    return read_roi(op, box, &p, err);
}

ag_status ag_cloud_ops_validate_template(const json_t *op, ag_error *err)
{
    double box[6];
    int32_t segment;
    return read_template(op, &segment, box, err);
}

ag_status ag_cloud_ops_run(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
                           int *duplicate, ag_error *err)
{
    *version = 0;
    *duplicate = 0;
    /* a retry is answered before anything is computed */
    int64_t seen = 0;
    ag_status s = ag_ops_find_cid(env->db, rq->model, rq->author, rq->cid, &seen, err);
    if (s != AG_OK || seen) {
        *duplicate = seen != 0;
        *version = seen;
        return s;
    }
    const char *kind = json_string_value(json_object_get(rq->op, "kind"));
    double box[6];
    ag_store_ws w;
    ag_store_ws_init_op(&w, env, rq);
    if (kind && strcmp(kind, "segment_roi") == 0) {
        ag_usecase_segment_params p;
        if ((s = read_roi(rq->op, box, &p, err)) == AG_OK)
            s = ag_usecase_segment_roi(&w.ws, box, &p, NULL, err);
    } else {
        int32_t segment = 0;
        if ((s = read_template(rq->op, &segment, box, err)) == AG_OK)
            s = ag_usecase_mark_template(&w.ws, segment, box, NULL, err);
    }
    ag_store_ws_end(&w, s);
    if (s == AG_OK) {
        *version = w.version;
        *duplicate = w.duplicate;
    }
    return s;
}
