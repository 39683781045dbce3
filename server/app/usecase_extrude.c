#include "usecase_extrude.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/extrude/style.h"
#include "../io/footprints.h"
#include "../io/plan_json.h"
#include "../io/plan_write.h"
#include "extrude_batch.h"

void ag_usecase_extrude_batch_clear(ag_extrusion_batch *b)
{
    for (size_t i = 0; i < b->n; i++) {
        free(b->items[i].id);
        free(b->items[i].plan_json);
        ag_plan_free(b->items[i].plan);
        ag_extrusion_built_clear(&b->items[i].built);
    }
    free(b->items);
    json_decref(b->meta);
    memset(b, 0, sizeof *b);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* What the body is when ?format= does not say: GeoJSON by its "type", a list of buildings by
 * "buildings", a building description by "loops". */
static const char *sniff(const json_t *root)
{
    const char *type = json_string_value(json_object_get(root, "type"));
    if (type && (strcmp(type, "FeatureCollection") == 0 || strcmp(type, "Feature") == 0))
        return "geojson";
    if (json_is_array(json_object_get(root, "buildings")))
        return "buildings";
    if (json_object_get(root, "loops"))
        return "plan";
    return NULL;
}

static ag_status add_building(ag_extrusion_batch *b, size_t cap, const char *id, char *plan_json,
                              ag_plan *plan, ag_error *err)
{
    if (!b->items && !(b->items = calloc(cap ? cap : 1, sizeof *b->items))) {
        free(plan_json);
        ag_plan_free(plan);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_extrude_building *it = &b->items[b->n++];
    it->id = strdup(id);
    it->plan_json = plan_json;
    it->plan = plan;
    if (!it->id)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return AG_OK;
}

/* A description as stored: compact, members in the order given. */
static ag_status parse_description(json_t *doc, const char *what, char **text, ag_plan **plan,
                                   ag_error *err)
{
    *plan = NULL;
    *text = json_dumps(doc, JSON_COMPACT);
    if (!*text)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_error e = {0};
    ag_status s = ag_plan_json_read_buffer(*text, strlen(*text), plan, &e);
    if (s != AG_OK) {
        free(*text);
        *text = NULL;
        return ag_error_set(err, s, e.element, "%s%s", what, e.text);
    }
    return AG_OK;
}

static ag_status read_plan(json_t *root, const char *name, ag_extrusion_batch *b, ag_error *err)
{
    char *text;
    ag_plan *plan;
    ag_status s = parse_description(root, "", &text, &plan, err);
    return s != AG_OK ? s : add_building(b, 1, name, text, plan, err);
}

static ag_status read_buildings(json_t *root, ag_extrusion_batch *b, ag_error *err)
{
    json_t *list = json_object_get(root, "buildings");
    size_t n = json_array_size(list);
    if (!json_is_array(list) || n == 0)
        return ag_error_set(err, AG_ERR_PARSE, 0, "\"buildings\" must be a non-empty array");
    size_t i;
    json_t *item;
    json_array_foreach(list, i, item)
    {
        json_t *id = json_object_get(item, "id"), *plan = json_object_get(item, "plan");
        if (!json_is_object(item) || !json_is_object(plan) ||
            (id && !json_is_string(id) && !json_is_integer(id)))
            return ag_error_set(err, AG_ERR_PARSE, (long)i + 1,
                                "buildings[%zu] must be an object with a \"plan\" object and "
                                "an optional \"id\" (string or integer)", i);
        char idbuf[32];
        const char *ids = json_string_value(id);
        if (!ids) {
            snprintf(idbuf, sizeof idbuf, "%lld",
                     id ? (long long)json_integer_value(id) : (long long)i);
            ids = idbuf;
        }
        char what[64], *text;
        ag_plan *p;
        snprintf(what, sizeof what, "buildings[%zu].", i);
        ag_status s = parse_description(plan, what, &text, &p, err);
        if (s == AG_OK)
            s = add_building(b, n, ids, text, p, err);
        if (s != AG_OK)
            return s;
    }
    return AG_OK;
}

/* A GeoJSON batch: its footprints (*out, for the batch to extrude) and, per footprint, the
 * plan its style makes, stored as the building's description. */
static ag_status read_geojson(const char *data, size_t len, const ag_extrude_input *params,
                              ag_style *style, ag_footprints **out, ag_extrusion_batch *b,
                              ag_error *err)
{
    *out = NULL;
    ag_status s = ag_style_builtin(params->style ? params->style : "hip", style, err);
    if (s != AG_OK)
        return s;
    if (params->seed >= 0)
        style->seed = (uint64_t)params->seed;
    ag_footprints_options fo = {
        .height_property = params->height_property,
        .lonlat = params->lonlat,
    };
    ag_footprints *f = NULL;
    if ((s = ag_footprints_read_buffer(data, len, &fo, &f, err)) != AG_OK)
        return s;
    if (f->n == 0) {
        s = ag_error_set(err, AG_ERR_EMPTY, 0, "the GeoJSON holds no polygon footprint%s%s",
                         f->skipped ? "; " : "", f->skipped ? f->first_skip : "");
        ag_footprints_free(f);
        return s;
    }
    b->skipped = f->skipped;
    b->meta = json_pack("{s:s, s:s, s:b, s:[f,f], s:I}", "format", "geojson", "style",
                        style->name, "lonlat", f->lonlat, "origin", f->origin[0], f->origin[1],
                        "skipped_features", (json_int_t)f->skipped);
    for (size_t i = 0; i < f->n && s == AG_OK; i++) {
        const ag_footprint *fp = &f->items[i];
        ag_plan *plan = NULL;
        json_t *doc = NULL;
        char *text = NULL;
        ag_error e = {0};
        /* the plan the batch's first attempt extrudes (same style, footprint and index) */
        ag_status made = ag_style_apply(style, (const double *const *)fp->loops, fp->sizes,
                                        fp->nloops, fp->height, i, &plan, &e);
        if (made == AG_OK && (made = ag_plan_write_json(plan, &doc, &e)) == AG_OK &&
            !(text = json_dumps(doc, JSON_COMPACT)))
            made = ag_error_set(&e, AG_ERR_NOMEM, 0, "out of memory");
        json_decref(doc);
        ag_plan_free(plan);
        if (made == AG_ERR_NOMEM) {
            free(text);
            s = ag_error_set(err, made, 0, "out of memory");
            break;
        }
        if (made != AG_OK) {
            free(text);
            text = NULL; /* the batch reports why */
        }
        s = add_building(b, f->n, fp->id, text, NULL, err);
    }
    if (s == AG_OK)
        *out = f;
    else
        ag_footprints_free(f);
    return s;
}

/* --- the batch: every building on every core -------------------------------------------- */

typedef struct {
    ag_extrusion_batch *b;
    const ag_footprints *f; /* GeoJSON: footprints with a style; else the items' plans */
    const ag_style *style;
} batch_input;

static ag_status build_one(void *user, size_t i, const ag_extrude_options *opt, ag_mesh *m,
                           ag_building_result *out, ag_error *err)
{
    const batch_input *in = user;
    ag_extrude_building *it = &in->b->items[i];
    size_t group = 0;
    if (ag_mesh_add_group(m, it->id, &group) != AG_OK)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (in->f) {
        const ag_footprint *fp = &in->f->items[i];
        return ag_building_extrude(in->style, (const double *const *)fp->loops, fp->sizes,
                                   fp->nloops, fp->height, i, opt, m, (int32_t)group, out, err);
    }
    return ag_building_extrude_plan(it->plan, opt, m, (int32_t)group, out, err);
}

static void batch_progress(void *user, size_t done, size_t total)
{
    ag_workspace_progress(user, 0.05 + 0.85 * (double)done / (double)(total ? total : 1),
                          "extrude");
}

static int ws_cancelled(void *user)
{
    return ag_workspace_cancelled(user);
}

/* Extrudes every building of b on every core into its built record (and `mesh`, in order)
 * and fills the report. */
static ag_status extrude_all(ag_workspace *ws, ag_extrusion_batch *b, const ag_footprints *f,
                             const ag_style *style, ag_mesh *mesh, ag_footprints_report *report,
                             ag_error *err)
{
    memset(report, 0, sizeof *report);
    report->footprints = b->n;
    ag_mesh **meshes = calloc(b->n ? b->n : 1, sizeof *meshes);
    ag_building_result *results = calloc(b->n ? b->n : 1, sizeof *results);
    if (!meshes || !results) {
        free(meshes);
        free(results);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_extrude_batch_options bo;
    memset(&bo, 0, sizeof bo);
    ag_extrusion_cancel hook;
    ag_extrusion_options(&bo.extrude, &hook, 0, NULL, ws_cancelled, ws);
    bo.threads = ag_extrusion_limits_get().threads;
    bo.progress = batch_progress;
    bo.progress_user = ws;
    batch_input in = {b, f, style};
    ag_error e = {0};
    ag_status s = ag_extrude_batch_each(b->n, build_one, &in, &bo, meshes, results, &e);
    if (s == AG_ERR_CANCELLED)
        ag_error_set(err, s, 0, "the job was cancelled (%s)", e.text);
    else if (s != AG_OK)
        ag_error_set(err, s, 0, "%s", e.text[0] ? e.text : ag_status_message(s));
    for (size_t i = 0; s == AG_OK && i < b->n; i++) {
        ag_extrude_building *it = &b->items[i];
        ag_extrusion_built_clear(&it->built);
        s = ag_extrusion_built_set(&it->built, &results[i], meshes[i], err);
        if (s == AG_OK && it->built.blob)
            s = ag_extrusion_append(mesh, meshes[i]);
        if (s == AG_OK)
            s = ag_footprints_report_add_id(report, it->id, f ? f->items[i].fixes : NULL,
                                            &results[i]);
        if (s == AG_ERR_NOMEM)
            ag_error_set(err, s, 0, "out of memory");
    }
    for (size_t i = 0; i < b->n; i++)
        ag_mesh_free(meshes[i]);
    free(meshes);
    free(results);
    return s;
}

ag_status ag_usecase_extrude_run(ag_workspace *ws, const ag_extrude_input *params,
                                 int64_t *model, ag_error *err)
{
    *model = 0;
    const char *name = params->name;
    const char *format = params->format;
    const char *data = params->data;
    size_t len = params->len;
    json_t *root = NULL;
    ag_mesh *mesh = NULL;
    ag_extrusion_batch b = {0};
    ag_footprints *footprints = NULL;
    ag_style style;
    ag_footprints_report report;
    memset(&report, 0, sizeof report);
    ag_status s;
    if (!data || !name) {
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "an extrusion without an input or a name");
        goto done;
    }
    ag_workspace_progress(ws, 0.01, "parse");
    json_error_t je;
    if (!(root = json_loadb(data, len, 0, &je))) {
        s = ag_error_set(err, AG_ERR_PARSE, je.line, "the body is not JSON: %s (line %d, column %d)",
                         je.text, je.line, je.column);
        goto done;
    }
    if (!format)
        format = json_is_object(root) ? sniff(root) : NULL;
    if (!format) {
        s = ag_error_set(err, AG_ERR_UNSUPPORTED, 0,
                         "the body is neither a building description (with \"loops\"), a list of "
                         "them (\"buildings\") nor a GeoJSON FeatureCollection; say which with "
                         "?format=plan|buildings|geojson");
        goto done;
    }
    if (!json_is_object(root)) {
        s = ag_error_set(err, AG_ERR_PARSE, 0, "the body must be a JSON object");
        goto done;
    }
    if (strcmp(format, "geojson") == 0) {
        s = read_geojson(data, len, params, &style, &footprints, &b, err);
    } else if (strcmp(format, "buildings") == 0) {
        b.meta = json_pack("{s:s}", "format", "buildings");
        s = read_buildings(root, &b, err);
    } else {
        format = "plan";
        b.meta = json_pack("{s:s}", "format", "plan");
        s = read_plan(root, name, &b, err);
    }
    b.format = format;
    json_decref(root);
    root = NULL;
    if (s != AG_OK)
        goto done;
    if (!b.meta) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }

    if (!(mesh = ag_mesh_create())) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    ag_workspace_progress(ws, 0.05, "extrude");
    double t0 = now();
    s = extrude_all(ws, &b, footprints, &style, mesh, &report, err);
    double seconds = now() - t0;
    if (s != AG_OK)
        goto done;
    int single = strcmp(format, "plan") == 0;
    if (report.nfailed == b.n) {
        const ag_extrude_building *first = &b.items[0];
        s = single ? ag_error_set(err, first->built.failure ? first->built.failure : AG_ERR_INVALID,
                                  0, "the plan cannot be extruded: %s", first->built.reason)
                   : ag_error_set(err, AG_ERR_EMPTY, 0,
                                  "none of the %zu footprints could be extruded; the first, "
                                  "\"%s\": %s",
                                  b.n, first->id, first->built.reason);
        goto done;
    }
    json_t *rep = ag_footprints_report_json(&report);
    if (rep && json_object_update_new(rep, json_pack("{s:f, s:I}", "seconds", seconds,
                                                     "skipped_features",
                                                     (json_int_t)b.skipped)) != 0) {
        json_decref(rep);
        rep = NULL;
    }
    if (!rep) {
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    if (ag_workspace_progress(ws, 0.92, "store")) {
        json_decref(rep);
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        goto done;
    }
    s = ag_workspace_add_extrusion(ws, name, &b, mesh, data, len, rep, model, err);
    json_decref(rep);
done:
    json_decref(root);
    ag_mesh_free(mesh);
    ag_footprints_report_free(&report);
    ag_footprints_free(footprints);
    ag_usecase_extrude_batch_clear(&b);
    return s;
}
