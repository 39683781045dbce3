#include "plan_edit.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/extrude/plan.h"
#include "../io/plan_json.h"
#include "../store/extrusions.h"
#include "extrusion.h"
#include "modelops.h"

#define AG_PROFILE_NAME_MAX 100

/* Parses a description given as JSON; errors become AG_ERR_PARSE prefixed with `what`. */
static ag_status parse(const json_t *doc, const char *what, ag_plan **plan, char **text,
                       ag_error *err)
{
    *plan = NULL;
    char *t = json_dumps(doc, JSON_COMPACT);
    if (!t)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_error e = {0};
    ag_status s = ag_plan_json_read_buffer(t, strlen(t), plan, &e);
    if (s == AG_ERR_NOMEM)
        s = ag_error_set(err, s, 0, "out of memory");
    else if (s != AG_OK)
        s = ag_error_set(err, AG_ERR_PARSE, 0, "%s%s", what, e.text);
    if (s != AG_OK || !text)
        free(t);
    else
        *text = t;
    return s;
}

/* A profile checked on its own: a one-triangle plan that uses it. */
static ag_status check_profile(const char *name, const json_t *profile, ag_error *err)
{
    json_t *doc = json_pack("{s:{s:O}, s:[[[i,i],[i,i],[i,i]]]}", "profiles", name, profile,
                            "loops", 0, 0, 1, 0, 0, 1);
    if (!doc)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_plan *p = NULL;
    ag_status s = parse(doc, "profile op: ", &p, NULL, err);
    ag_plan_free(p);
    json_decref(doc);
    return s;
}

ag_status ag_plan_edit_validate(const json_t *op, ag_error *err)
{
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (kind && strcmp(kind, "plan") == 0) {
        static const char *const allowed[] = {"kind", "building", "plan", NULL};
        json_t *bi = json_object_get(op, "building"), *plan = json_object_get(op, "plan");
        if (!json_is_integer(bi) || json_integer_value(bi) < 0)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "a plan op needs \"building\", a building index (0, 1, …)");
        if (!json_is_object(plan))
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "a plan op needs \"plan\", a building description object");
        ag_status s = ag_modelops_only_members(op, allowed, err);
        ag_plan *p = NULL;
        if (s == AG_OK)
            s = parse(plan, "plan op: ", &p, NULL, err);
        ag_error e = {0};
        if (s == AG_OK && (s = ag_plan_validate(p, NULL, NULL, &e)) != AG_OK)
            s = s == AG_ERR_NOMEM ? ag_error_set(err, s, 0, "out of memory")
                                  : ag_error_set(err, AG_ERR_PARSE, 0,
                                                 "plan op: the plan is not valid: %s", e.text);
        ag_plan_free(p);
        return s;
    }
    static const char *const allowed[] = {"kind", "name", "profile", NULL};
    const char *name = json_string_value(json_object_get(op, "name"));
    if (!name || !*name || strlen(name) > AG_PROFILE_NAME_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a profile op needs \"name\", the profile's name (1–%d bytes)",
                            AG_PROFILE_NAME_MAX);
    json_t *profile = json_object_get(op, "profile");
    if (!json_is_array(profile) && !json_is_object(profile))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a profile op needs \"profile\": [[w, z], …] or {\"points\": …}");
    ag_status s = ag_modelops_only_members(op, allowed, err);
    return s != AG_OK ? s : check_profile(name, profile, err);
}

/* One building's new description, extruded; stored once the whole op has succeeded. */
typedef struct {
    int64_t building;
    char *footprint;
    char *plan_json;
    ag_extrusion_built built;
} update;

static void update_clear(update *u)
{
    free(u->footprint);
    free(u->plan_json);
    ag_extrusion_built_clear(&u->built);
}

/* Extrudes doc as building b (footprint id given); failure → AG_ERR_PARSE naming both,
 * unless may_fail: a building that already failed before the op (a batch's bad footprint)
 * is kept as failed with its new reason rather than refusing an op that did not cause it. */
static ag_status rebuild(const json_t *doc, int64_t b, const char *footprint, int may_fail,
                         update *u, ag_error *err)
{
    memset(u, 0, sizeof *u);
    u->building = b;
    if (!(u->footprint = strdup(footprint)))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    char what[160];
    snprintf(what, sizeof what, "building %lld (\"%.100s\"): ", (long long)b, footprint);
    ag_plan *plan = NULL;
    ag_status s = parse(doc, what, &plan, &u->plan_json, err);
    if (s == AG_OK)
        s = ag_extrusion_build(plan, footprint, NULL, NULL, &u->built, err);
    ag_plan_free(plan);
    if (s == AG_OK && strcmp(u->built.status, "failed") == 0 && !may_fail)
        s = ag_error_set(err, AG_ERR_PARSE, 0, "%sthe plan cannot be extruded: %s", what,
                         u->built.reason);
    return s;
}

static ag_status store(ag_db *db, int64_t model, update *u, size_t n, ag_error *err)
{
    ag_status s = AG_OK;
    for (size_t i = 0; i < n && s == AG_OK; i++) {
        ag_extrusion_building row = {.model = model,
                                     .building = u[i].building,
                                     .footprint = u[i].footprint,
                                     .plan_json = u[i].plan_json,
                                     .mesh = u[i].built.blob,
                                     .mesh_len = u[i].built.blob_len,
                                     .triangles = (int64_t)u[i].built.triangles,
                                     .reason = u[i].built.reason[0] ? u[i].built.reason : NULL,
                                     .fallback = ag_extrusion_built_fallback(&u[i].built),
                                     .moved = u[i].built.moved};
        snprintf(row.status, sizeof row.status, "%s", u[i].built.status);
        s = ag_extrusions_put_building(db, &row, err);
    }
    return s == AG_OK ? ag_extrusion_store_mesh(db, model, NULL, err) : s;
}

static ag_status apply_plan(ag_db *db, int64_t model, size_t buildings, const json_t *op,
                            ag_error *err)
{
    json_int_t bi = json_integer_value(json_object_get(op, "building"));
    if ((size_t)bi >= buildings)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "model %lld has %zu building%s; there is no building %lld",
                            (long long)model, buildings, buildings == 1 ? "" : "s",
                            (long long)bi);
    ag_extrusion_building row;
    ag_status s = ag_extrusions_get_building(db, model, bi, 0, &row, err);
    if (s != AG_OK)
        return s;
    update u;
    s = rebuild(json_object_get(op, "plan"), bi, row.footprint, 0, &u, err);
    ag_extrusions_building_clear(&row);
    if (s == AG_OK)
        s = store(db, model, &u, 1, err);
    update_clear(&u);
    return s;
}

typedef struct {
    const char *name;
    const json_t *profile;
    update *u;
    size_t n, cap;
    ag_error *err;
} profile_edit;

static ag_status visit(void *user, ag_extrusion_building *b)
{
    profile_edit *pe = user;
    json_t *doc = json_loads(b->plan_json, 0, NULL);
    json_t *profiles = json_object_get(doc, "profiles");
    if (!json_object_get(profiles, pe->name)) {
        json_decref(doc);
        return AG_OK;
    }
    json_object_set(profiles, pe->name, (json_t *)pe->profile);
    if (pe->n == pe->cap) {
        size_t cap = pe->cap ? 2 * pe->cap : 16;
        update *g = realloc(pe->u, cap * sizeof *g);
        if (!g) {
            json_decref(doc);
            return ag_error_set(pe->err, AG_ERR_NOMEM, 0, "out of memory");
        }
        pe->u = g;
        pe->cap = cap;
    }
    ag_status s = rebuild(doc, b->building, b->footprint, strcmp(b->status, "failed") == 0,
                          &pe->u[pe->n], pe->err);
    pe->n++; /* cleared by the caller whatever happened */
    json_decref(doc);
    return s;
}

static ag_status apply_profile(ag_db *db, int64_t model, const json_t *op, ag_error *err)
{
    profile_edit pe = {.name = json_string_value(json_object_get(op, "name")),
                       .profile = json_object_get(op, "profile"),
                       .err = err};
    ag_status s = ag_extrusions_each_building(db, model, AG_EXTRUSIONS_PLAN, visit, &pe, err);
    if (s == AG_OK && pe.n == 0)
        s = ag_error_set(err, AG_ERR_INVALID, 0, "no building of model %lld has a profile named "
                         "\"%s\"", (long long)model, pe.name);
    if (s == AG_OK)
        s = store(db, model, pe.u, pe.n, err);
    for (size_t i = 0; i < pe.n; i++)
        update_clear(&pe.u[i]);
    free(pe.u);
    return s;
}

ag_status ag_plan_edit_apply(ag_db *db, int64_t model, const json_t *op, ag_error *err)
{
    ag_extrusion_row row;
    ag_error e = {0};
    ag_status s = ag_extrusions_get(db, model, &row, &e);
    if (s == AG_ERR_NOT_FOUND)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s", e.text);
    if (s != AG_OK) {
        if (err)
            *err = e;
        return s;
    }
    size_t buildings = row.buildings;
    ag_extrusions_row_clear(&row);
    const char *kind = json_string_value(json_object_get(op, "kind"));
    return strcmp(kind, "plan") == 0 ? apply_plan(db, model, buildings, op, err)
                                     : apply_profile(db, model, op, err);
}
