#include "compose_ops.h"

#include <string.h>

#include "../store/ops.h"
#include "modelops.h"
#include "store_ws.h"
#include "usecase_compose.h"

static ag_status whole_number(const json_t *v, const char *field, json_int_t lo, json_int_t *out,
                              ag_error *err)
{
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > INT32_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s: a whole number from %lld", field,
                            (long long)lo);
    *out = json_integer_value(v);
    return AG_OK;
}

ag_status ag_compose_ops_parse(const json_t *op, ag_part_ref *ref, ag_compose_op *cop,
                               ag_error *err)
{
    static const char *const allowed[] = {"kind", "part", "version", "target", "mode", "scope",
                                          NULL};
    ag_part_ref r = {0};
    ag_compose_op c = {.target = -1, .mode = -1, .scope = AG_COMPOSE_NODE};
    json_int_t v = 0;
    ag_status s = whole_number(json_object_get(op, "part"), "part", 1, &v, err);
    if (s != AG_OK)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "part: a compose op needs \"part\", the id of a part of the library");
    r.id = v;
    json_t *jv = json_object_get(op, "version");
    if (jv && (s = whole_number(jv, "version", 1, &v, err)) != AG_OK)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "version: the part's version (1 or more), or left out for its "
                            "newest");
    r.version = jv ? v : 0;
    json_t *jt = json_object_get(op, "target");
    if (json_is_string(jt) && strcmp(json_string_value(jt), "root") == 0)
        c.target = 0;
    else if (whole_number(jt, "target", 0, &v, NULL) == AG_OK)
        c.target = (int32_t)v;
    else
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "target: a node of the model's tree (an index or \"root\")");
    const char *mode = json_string_value(json_object_get(op, "mode"));
    if (!mode || (c.mode = ag_compose_mode_parse(mode)) < 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "mode: \"replace\", \"insert\" or \"fill\"");
    json_t *js = json_object_get(op, "scope");
    if (js) {
        const char *scope = json_string_value(js);
        if (!scope || (c.scope = ag_compose_scope_parse(scope)) < 0)
            return ag_error_set(err, AG_ERR_INVALID, 0, "scope: \"node\" or \"rule\"");
    }
    if ((s = ag_modelops_only_members(op, allowed, err)) != AG_OK)
        return s;
    if (ref)
        *ref = r;
    if (cop)
        *cop = c;
    return AG_OK;
}

ag_status ag_compose_ops_validate(const json_t *op, ag_error *err)
{
    return ag_compose_ops_parse(op, NULL, NULL, err);
}

ag_status ag_compose_ops_run(const ag_store_env *env, const ag_op_request *rq, int64_t *version,
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
    ag_usecase_compose_params p = {0};
    ag_part_ref ref;
    if ((s = ag_compose_ops_parse(rq->op, &ref, &p.op, err)) != AG_OK)
        return s;
    p.part = &ref;
    ag_store_ws w;
    ag_store_ws_init_op(&w, env, rq);
    ag_usecase_compose_result r;
    s = ag_usecase_compose_run(&w.ws, &p, &r, err);
    ag_store_ws_end(&w, s);
    if (s == AG_OK) {
        *version = w.version;
        *duplicate = w.duplicate;
    }
    return s;
}

ag_status ag_compose_ops_preview(const ag_store_env *env, int64_t model, int64_t base,
                                 const json_t *op, ag_mesh **mesh, json_t **report,
                                 ag_error *err)
{
    *mesh = NULL;
    *report = NULL;
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (!json_is_object(op) || !kind || strcmp(kind, "compose") != 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a compose preview carries a compose op");
    ag_usecase_compose_params p = {0};
    ag_part_ref ref;
    ag_status s = ag_compose_ops_parse(op, &ref, &p.op, err);
    if (s != AG_OK)
        return s;
    p.part = &ref;
    ag_store_ws w;
    ag_store_ws_init(&w, &(ag_store_ws_options){.env = *env, .model = model, .base = base});
    ag_usecase_compose_result r;
    if ((s = ag_usecase_compose_preview(&w.ws, &p, mesh, &r, err)) == AG_OK) {
        ag_compose_outcome o = {.op = &p.op, .part = r.part, .report = r.report,
                                .load_ms = r.load_ms, .compose_ms = r.compose_ms,
                                .state_ms = r.state_ms};
        *report = ag_usecase_compose_report_json(&o);
        if (*report) {
            json_object_set_new(*report, "load_ms", json_real(r.load_ms));
            json_object_set_new(*report, "compose_ms", json_real(r.compose_ms));
            json_object_set_new(*report, "state_ms", json_real(r.state_ms));
        }
        else
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_store_ws_end(&w, s);
    if (s != AG_OK) {
        ag_mesh_free(*mesh);
        *mesh = NULL;
    }
    return s;
}
