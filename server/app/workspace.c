#include "workspace.h"

#include "points_state.h"

static ag_status unsupported(const char *what, ag_error *err)
{
    return ag_error_set(err, AG_ERR_UNSUPPORTED, 0, "this workspace cannot %s", what);
}

ag_status ag_workspace_add_model(ag_workspace *ws, const char *name, const ag_mesh *mesh,
                                 const void *source, size_t source_len, const char *source_format,
                                 const ag_up_decision *up, int64_t *model, ag_error *err)
{
    *model = 0;
    return ws->ops->add_model ? ws->ops->add_model(ws, name, mesh, source, source_len,
                                                   source_format, up, model, err)
               : unsupported("store a new model", err);
}

ag_status ag_workspace_add_extrusion(ag_workspace *ws, const char *name,
                                    const struct ag_extrude_batch *batch, const ag_mesh *mesh,
                                    const char *source, size_t source_len, const json_t *report,
                                    int64_t *model, ag_error *err)
{
    *model = 0;
    return ws->ops->add_extrusion ? ws->ops->add_extrusion(ws, name, batch, mesh, source,
                                                           source_len, report, model, err)
                                  : unsupported("store an extrusion", err);
}

ag_status ag_workspace_input_mesh(ag_workspace *ws, ag_mesh **mesh, ag_error *err)
{
    *mesh = NULL;
    return ws->ops->input_mesh ? ws->ops->input_mesh(ws, mesh, err)
                               : unsupported("give a mesh to proceduralize", err);
}

ag_status ag_workspace_open_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                   ag_edit_model **em, const ag_edit_model **source,
                                   int64_t *source_version, ag_error *err)
{
    *em = NULL;
    *source = NULL;
    *source_version = 0;
    return ws->ops->open_models ? ws->ops->open_models(ws, from, em, source, source_version, err)
                                : unsupported("open a model to edit", err);
}

ag_status ag_workspace_save(ag_workspace *ws, ag_model_state *st, const ag_proc_outcome *proc,
                            const ag_edit_outcome *edit, ag_error *err)
{
    if (!ws->ops->save) {
        ag_model_state_clear(st);
        return unsupported("save a model", err);
    }
    return ws->ops->save(ws, st, proc, edit, err);
}

ag_status ag_workspace_add_cloud(ag_workspace *ws, const char *name, const ag_cloud_new *c,
                                 int64_t *model, ag_error *err)
{
    *model = 0;
    return ws->ops->add_cloud ? ws->ops->add_cloud(ws, name, c, model, err)
                              : unsupported("store a point cloud", err);
}

ag_status ag_workspace_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                   ag_cloud_state *st, ag_error *err)
{
    st->cloud = NULL;
    st->seg = NULL;
    st->had_normals = 0;
    return ws->ops->input_cloud
               ? ws->ops->input_cloud(ws, with_properties, need_segmentation, st, err)
               : unsupported("give a point cloud", err);
}

ag_status ag_workspace_save_segmentation(ag_workspace *ws, const ag_cloud_state *st,
                                         const ag_segment_outcome *o, ag_error *err)
{
    return ws->ops->save_segmentation ? ws->ops->save_segmentation(ws, st, o, err)
                                      : unsupported("save a segmentation", err);
}

ag_status ag_workspace_model_trace(ag_workspace *ws, const ag_trace **trace, ag_error *err)
{
    *trace = NULL;
    return ws->ops->model_trace ? ws->ops->model_trace(ws, trace, err) : AG_OK;
}

ag_status ag_workspace_open_part(ag_workspace *ws, const ag_part_ref *ref, const ag_part **part,
                                 ag_error *err)
{
    *part = NULL;
    return ws->ops->open_part ? ws->ops->open_part(ws, ref, part, err)
                              : unsupported("give a part to compose", err);
}

ag_status ag_workspace_save_part(ag_workspace *ws, ag_part *part, const ag_part_outcome *o,
                                 ag_error *err)
{
    if (!ws->ops->save_part) {
        ag_part_free(part);
        return unsupported("save a part", err);
    }
    return ws->ops->save_part(ws, part, o, err);
}

ag_status ag_workspace_save_composed(ag_workspace *ws, ag_model_state *st,
                                     const ag_compose_outcome *o, ag_error *err)
{
    if (!ws->ops->save_composed) {
        ag_model_state_clear(st);
        return unsupported("save a composed model", err);
    }
    return ws->ops->save_composed(ws, st, o, err);
}

ag_status ag_workspace_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                         struct ag_pointmodel **pm,
                                         const struct ag_pointmodel **source, ag_error *err)
{
    *pm = NULL;
    *source = NULL;
    return ws->ops->open_point_models ? ws->ops->open_point_models(ws, from, pm, source, err)
                                      : unsupported("open a point model", err);
}

ag_status ag_workspace_save_points(ag_workspace *ws, struct ag_points_state *st,
                                   const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                   ag_error *err)
{
    if (!ws->ops->save_points) {
        ag_points_state_clear(st);
        return unsupported("save a point model", err);
    }
    return ws->ops->save_points(ws, st, proc, edit, err);
}

int ag_workspace_cancelled(ag_workspace *ws)
{
    return ws->ops->cancelled ? ws->ops->cancelled(ws) : 0;
}

int ag_workspace_progress(ag_workspace *ws, double fraction, const char *stage)
{
    if (ws->ops->progress)
        ws->ops->progress(ws, fraction, stage);
    return ag_workspace_cancelled(ws);
}

void ag_workspace_close(ag_workspace *ws)
{
    if (ws && ws->ops->close)
        ws->ops->close(ws);
}
