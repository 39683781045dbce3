#include "extrusion.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/extrude/extrude.h"
#include "../io/meshblob.h"
#include "../io/meshjson.h"
#include "../store/extrusions.h"
#include "../store/models.h"

void ag_extrusion_built_clear(ag_extrusion_built *b)
{
    if (!b)
        return;
    free(b->blob);
    b->blob = NULL;
    b->blob_len = 0;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Set once at start-up, before any worker runs; read-only afterwards. */
static ag_extrusion_limits limits = {.seconds = AG_EXTRUSION_SECONDS};
static atomic_int stopping;

void ag_extrusion_configure(const ag_extrusion_limits *l)
{
    limits = *l;
    if (!limits.seconds)
        limits.seconds = AG_EXTRUSION_SECONDS;
}

ag_extrusion_limits ag_extrusion_limits_get(void)
{
    return limits;
}

void ag_extrusion_stop_all(void)
{
    atomic_store(&stopping, 1);
}

int ag_extrusion_stopping(void)
{
    return atomic_load(&stopping) != 0;
}

static int hook_cancelled(void *user)
{
    const ag_extrusion_cancel *h = user;
    return atomic_load(&stopping) || (h->cancel && atomic_load(h->cancel)) ||
           (h->cancelled && h->cancelled(h->user));
}

void ag_extrusion_options(ag_extrude_options *o, ag_extrusion_cancel *hook, double deadline,
                          const atomic_int *cancel, int (*cancelled)(void *user), void *user)
{
    memset(o, 0, sizeof *o);
    hook->cancel = cancel;
    hook->cancelled = cancelled;
    hook->user = user;
    double seconds = limits.seconds;
    if (deadline > 0) {
        seconds = deadline - now();
        if (seconds <= 0)
            seconds = 1e-9; /* already past: stops at its first poll */
    }
    o->budget.max_seconds = seconds;
    o->budget.max_events = limits.max_events;
    o->budget.max_bytes = limits.max_bytes;
    o->budget.cancelled = hook_cancelled;
    o->budget.user = hook;
}

const char *ag_extrusion_built_fallback(const ag_extrusion_built *b)
{
    return b->built == AG_BUILT_SIMPLIFIED || b->built == AG_BUILT_FLAT ||
                   b->built == AG_BUILT_BLOCK
               ? ag_built_name(b->built)
               : NULL;
}

ag_status ag_extrusion_built_set(ag_extrusion_built *out, const ag_building_result *r,
                                 const ag_mesh *m, ag_error *err)
{
    memset(out, 0, sizeof *out);
    out->built = r->built;
    out->moved = r->moved;
    out->triangles = r->triangles;
    out->events = r->events;
    out->seconds = r->seconds;
    snprintf(out->reason, sizeof out->reason, "%s", r->reason);
    snprintf(out->fixes, sizeof out->fixes, "%s", r->fixes);
    if (r->built == AG_BUILT_NONE) {
        snprintf(out->status, sizeof out->status, "failed");
        out->failure = AG_ERR_INVALID;
        if (!out->reason[0])
            snprintf(out->reason, sizeof out->reason, "nothing could be built");
        return AG_OK;
    }
    snprintf(out->status, sizeof out->status, "ok");
    ag_status st = ag_meshblob_encode(m, &out->blob, &out->blob_len);
    return st == AG_OK ? AG_OK : ag_error_set(err, st, 0, "cannot keep the mesh of a building");
}

ag_status ag_extrusion_append(ag_mesh *dst, const ag_mesh *src)
{
    size_t v0 = dst->nverts, g0 = dst->ngroups, c0 = dst->ncomponents;
    if (dst->nverts + src->nverts > UINT32_MAX)
        return AG_ERR_TOO_LARGE;
    ag_status s = ag_mesh_reserve(dst, dst->nverts + src->nverts, dst->ntris + src->ntris);
    for (size_t g = 0; s == AG_OK && g < src->ngroups; g++)
        s = ag_mesh_add_group(dst, src->group_names[g], NULL);
    for (size_t c = 0; s == AG_OK && c < src->ncomponents; c++) {
        int32_t g = src->component_group[c];
        s = ag_mesh_add_component(dst, g < 0 ? -1 : (int32_t)(g0 + (size_t)g), NULL);
    }
    for (size_t i = 0; s == AG_OK && i < src->nverts; i++)
        s = ag_mesh_add_vertex(dst, src->pos[3 * i], src->pos[3 * i + 1], src->pos[3 * i + 2]);
    for (size_t t = 0; s == AG_OK && t < src->ntris; t++)
        s = ag_mesh_add_triangle(dst, (uint32_t)(v0 + src->tri[3 * t]),
                                 (uint32_t)(v0 + src->tri[3 * t + 1]),
                                 (uint32_t)(v0 + src->tri[3 * t + 2]),
                                 (uint32_t)(c0 + src->tri_component[t]));
    return s;
}

ag_status ag_extrusion_build(ag_plan *plan, const char *footprint, const ag_extrude_options *opt,
                             ag_mesh *into, ag_extrusion_built *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_extrude_options own;
    ag_extrusion_cancel hook;
    if (!opt) {
        ag_extrusion_options(&own, &hook, 0, NULL, NULL, NULL);
        opt = &own;
    }
    ag_mesh *m = ag_mesh_create();
    size_t group = 0;
    if (!m || ag_mesh_add_group(m, footprint, &group) != AG_OK) {
        ag_mesh_free(m);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    ag_building_result r;
    ag_error e = {0};
    ag_status st = ag_building_extrude_plan(plan, opt, m, (int32_t)group, &r, &e);
    if (st == AG_OK)
        st = ag_extrusion_built_set(out, &r, m, &e);
    if (st == AG_OK && into && out->blob)
        st = ag_extrusion_append(into, m);
    ag_mesh_free(m);
    if (st != AG_OK) {
        ag_extrusion_built_clear(out);
        if (st == AG_ERR_CANCELLED)
            return ag_error_set(err, st, 0, "extruding %s was stopped: %s", footprint, e.text);
        return ag_error_set(err, st, 0, "out of memory extruding %s", footprint);
    }
    return AG_OK;
}

char *ag_extrusion_stats(const ag_mesh *m)
{
    json_t *summary = ag_meshjson_summary(m);
    char *stats = summary ? json_dumps(summary, JSON_COMPACT) : NULL;
    json_decref(summary);
    return stats;
}

typedef struct {
    ag_mesh *mesh;
    ag_error *err;
} assembly;

static ag_status add_building(void *user, ag_extrusion_building *b)
{
    assembly *a = user;
    if (!b->mesh)
        return AG_OK; /* failed: no geometry */
    ag_mesh *m = NULL;
    ag_status s = ag_meshblob_decode(b->mesh, b->mesh_len, &m, a->err);
    if (s != AG_OK)
        return ag_error_set(a->err, AG_ERR_INTERNAL, b->building + 1,
                            "the stored mesh of building %lld is corrupt",
                            (long long)b->building);
    s = ag_extrusion_append(a->mesh, m);
    ag_mesh_free(m);
    return s == AG_OK ? AG_OK : ag_error_set(a->err, s, 0, "out of memory assembling the mesh");
}

ag_status ag_extrusion_store_mesh(ag_db *db, int64_t model, size_t *triangles, ag_error *err)
{
    assembly a = {ag_mesh_create(), err};
    if (!a.mesh)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status s = ag_extrusions_each_building(db, model, AG_EXTRUSIONS_MESH, add_building, &a, err);
    uint8_t *blob = NULL;
    size_t len = 0;
    char *stats = NULL;
    if (s == AG_OK && (s = ag_meshblob_encode(a.mesh, &blob, &len)) != AG_OK)
        ag_error_set(err, s, 0, "cannot encode the mesh");
    if (s == AG_OK && !(stats = ag_extrusion_stats(a.mesh)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory summarising the mesh");
    if (s == AG_OK)
        s = ag_models_set_mesh(db, model, blob, len, stats, NULL, err);
    if (s == AG_OK && triangles)
        *triangles = a.mesh->ntris;
    free(stats);
    free(blob);
    ag_mesh_free(a.mesh);
    return s;
}
