#include "usecase_mark_template.h"

#include "../core/base/clock.h"
#include "../core/points/template_mark.h"

static json_t *vec3(const double *v)
{
    return json_pack("[f,f,f]", v[0], v[1], v[2]);
}

ag_status ag_usecase_mark_template(ag_workspace *ws, int32_t segment, const double box[6],
                                   json_t **report, ag_error *err)
{
    if (report)
        *report = NULL;
    ag_cloud_state st;
    ag_status s = ag_workspace_input_cloud(ws, 0, 1, &st, err);
    if (s != AG_OK)
        return s;
    ag_template_mark_report tm = {0};
    double t0 = ag_clock_seconds();
    s = ag_template_mark(st.cloud, &st.seg, segment, box, box + 3, &tm, err);
    json_t *rep = NULL;
    if (s == AG_OK) {
        json_t *copies = json_array();
        for (size_t i = 0; copies && i < tm.copies; i++)
            json_array_append_new(copies,
                                  json_pack("{s:I, s:o, s:o}", "points",
                                            (json_int_t)tm.copy[i].count, "min",
                                            vec3(tm.copy[i].min), "max", vec3(tm.copy[i].max)));
        rep = copies ? json_pack("{s:I, s:I, s:I, s:I, s:I, s:o, s:I, s:I, s:f}",
                                 "template_points", (json_int_t)tm.template_points,
                                 "template_segment", (json_int_t)tm.template_segment, "label",
                                 (json_int_t)tm.label, "positions", (json_int_t)tm.positions,
                                 "copies", (json_int_t)tm.copies, "copy_boxes", copies,
                                 "segments", (json_int_t)ag_segment_cloud_in_use(st.seg), "labels",
                                 (json_int_t)st.seg->nlabels, "seconds",
                                 ag_clock_seconds() - t0)
                     : NULL;
        if (rep) /* ids below it may be in use; the next new segment gets it */
            json_object_set_new(rep, "segment_ids", json_integer((json_int_t)st.seg->nsegments));
        s = rep ? ag_workspace_save_segmentation(
                      ws, &st, &(ag_segment_outcome){"mark_template", rep}, err)
                : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (s == AG_OK && report)
        *report = json_incref(rep);
    json_decref(rep);
    ag_template_mark_report_clear(&tm);
    ag_cloud_state_clear(&st);
    return s;
}
