#include "usecase_segment.h"

#include "../core/base/clock.h"
#include "../core/points/segment_cloud.h"

/* Where each stage of a whole run starts in the job's progress (the last ends at 0.95). */
static const double stage_start[AG_SEGMENT_CLOUD_STAGES + 1] = {0.05, 0.08, 0.35, 0.5,
                                                                0.8,  0.84, 0.9,  0.95};

static int on_stage(void *user, ag_segment_cloud_stage stage, double fraction)
{
    double a = stage_start[stage], b = stage_start[stage + 1];
    return ag_workspace_progress(user, a + (b - a) * fraction,
                                 ag_segment_cloud_stage_name(stage));
}

static ag_segment_cloud_options options_of(const ag_usecase_segment_params *p, ag_workspace *ws)
{
    ag_segment_cloud_options o = {0};
    if (p) {
        o.fine_threshold = p->threshold;
        o.coarse_threshold = p->coarse_threshold;
        o.cluster_tolerance = p->cluster_tolerance;
        o.recompute_normals = p->recompute_normals;
    }
    o.progress = on_stage;
    o.user = ws;
    return o;
}

static ag_status too_large(const ag_cloud *c, ag_error *err)
{
    return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                        "the cloud holds %zu points; archgram segments at most %zu at once (cut "
                        "it into buildings first: archgram cut)",
                        c->n, AG_CLOUD_MAX_SEGMENT_POINTS);
}

/* Saves st's segmentation under kind with report, handing the report back. */
static ag_status save(ag_workspace *ws, const ag_cloud_state *st, const char *kind,
                      json_t *rep, json_t **report, ag_error *err)
{
    ag_status s = rep ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK && ag_workspace_progress(ws, 0.95, "store"))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK)
        s = ag_workspace_save_segmentation(ws, st, &(ag_segment_outcome){kind, rep}, err);
    if (s == AG_OK && report)
        *report = json_incref(rep);
    json_decref(rep);
    return s;
}

ag_status ag_usecase_segment_run(ag_workspace *ws, const ag_usecase_segment_params *p,
                                 json_t **report, ag_error *err)
{
    if (report)
        *report = NULL;
    ag_cloud_state st;
    ag_status s = ag_workspace_input_cloud(ws, 0, 0, &st, err);
    if (s != AG_OK)
        return s;
    if (st.cloud->n > AG_CLOUD_MAX_SEGMENT_POINTS)
        s = too_large(st.cloud, err);
    ag_segment_cloud_options o = options_of(p, ws);
    ag_segment_cloud_result *r = NULL;
    if (s == AG_OK)
        s = ag_segment_cloud_run(st.cloud, &o, &r, err);
    if (s == AG_ERR_CANCELLED || (s != AG_OK && ag_workspace_cancelled(ws)))
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
    if (s == AG_OK) {
        ag_segment_cloud_free(st.seg); /* a new segmentation replaces the one there was */
        st.seg = r;
        json_t *rep = ag_cloud_state_segmentation(r, 1);
        if (rep)
            json_object_set_new(rep, "normals",
                                json_string(st.had_normals && !o.recompute_normals ? "cloud"
                                                                                  : "computed"));
        s = save(ws, &st, "segment", rep, report, err);
    }
    ag_cloud_state_clear(&st);
    return s;
}

ag_status ag_usecase_segment_roi(ag_workspace *ws, const double box[6],
                                 const ag_usecase_segment_params *p, json_t **report,
                                 ag_error *err)
{
    if (report)
        *report = NULL;
    ag_cloud_state st;
    ag_status s = ag_workspace_input_cloud(ws, 0, 1, &st, err);
    if (s != AG_OK)
        return s;
    size_t inside = 0;
    for (size_t i = 0; i < st.cloud->n; i++) {
        const double *q = st.cloud->xyz + 3 * i;
        inside += q[0] >= box[0] && q[0] <= box[3] && q[1] >= box[1] && q[1] <= box[4] &&
                  q[2] >= box[2] && q[2] <= box[5];
    }
    if (!inside)
        s = ag_error_set(err, AG_ERR_INVALID, 0,
                         "box: no point of the cloud lies inside [%g, %g, %g, %g, %g, %g]",
                         box[0], box[1], box[2], box[3], box[4], box[5]);
    else if (st.cloud->n > AG_CLOUD_MAX_SEGMENT_POINTS)
        s = too_large(st.cloud, err);
    size_t before = st.seg ? st.seg->nsegments : 0;
    ag_segment_cloud_options o = options_of(p, ws);
    o.progress = NULL; /* an op: short, and not a job */
    double t0 = ag_clock_seconds();
    if (s == AG_OK)
        s = ag_segment_cloud_refine(st.cloud, st.seg, box, box + 3, &o, err);
    if (s == AG_OK) {
        json_t *rep = ag_cloud_state_segmentation(st.seg, 0);
        if (rep) {
            json_object_set_new(rep, "inside", json_integer((json_int_t)inside));
            json_object_set_new(rep, "segments_before", json_integer((json_int_t)before));
            json_object_set_new(rep, "seconds", json_real(ag_clock_seconds() - t0));
        }
        s = save(ws, &st, "segment_roi", rep, report, err);
    }
    ag_cloud_state_clear(&st);
    return s;
}
