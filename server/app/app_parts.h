/* What the REST layer asks of the parts library, on the calling thread's connection: saving
 * a part from a model (the save use case on the store workspace, app/usecase_save_part.h),
 * searching, reading a part with its versions, its thumbnail, GLB and bundle, importing and
 * exporting bundles (app/part_library.h), deleting; and what the client needs to select and
 * compose: the common ancestors of a selection, and a composition previewed without storing
 * it (app/compose_ops.h). Composing itself is an op (app_change.h). */
#ifndef AG_APP_PARTS_H
#define AG_APP_PARTS_H

#include <jansson.h>
#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "app_query.h"

#define AG_APP_PARTS_PAGE_MAX 200

typedef struct {
    int64_t model, version;    /* the model, and the version its node ids are of */
    const int32_t *nodes;      /* one node, or a selection: its common ancestor is saved */
    size_t nnodes;
    const char *name;          /* a new version keeps the part's when NULL */
    const char *description;
    const char *const *tags;   /* tags == NULL: a new version keeps the part's */
    size_t ntags;
    int64_t update, base;      /* a new version of part `update` made on its version base */
} ag_app_part_save;

/* *view: the part as GET /api/v1/parts/{id} shows it; *id and *version where it went. */
ag_status ag_app_parts_save(ag_app *app, const ag_app_part_save *rq, json_t **view,
                            int64_t *id, int64_t *version, ag_error *err);
/* Parts matching q (words, prefixes) and tag, best first, at most limit from offset. */
ag_status ag_app_parts_search(ag_app *app, const char *q, const char *tag, size_t offset,
                              size_t limit, json_t **items, int *more, ag_error *err);
/* One part with its versions (newest first) and its newest version. */
ag_status ag_app_parts_get(ag_app *app, int64_t id, json_t **view, int64_t *version,
                           ag_error *err);
ag_status ag_app_parts_version(ag_app *app, int64_t id, int64_t *version, ag_error *err);
/* A version's (0: the newest) thumbnail (PNG), GLB; etag names the version; when fresh(user,
 * etag) says the client has it, data stays NULL. */
ag_status ag_app_parts_thumbnail(ag_app *app, int64_t id, int64_t version,
                                 int (*fresh)(void *user, const char *etag), void *user,
                                 ag_app_bytes *out, ag_error *err);
ag_status ag_app_parts_glb(ag_app *app, int64_t id, int64_t version,
                           int (*fresh)(void *user, const char *etag), void *user,
                           ag_app_bytes *out, ag_error *err);
/* A bundle: n parts at their newest versions (n = 1: `version`, 0 newest), n = 0 the whole
 * library. */
ag_status ag_app_parts_bundle(ag_app *app, const int64_t *ids, size_t n, int64_t version,
                              ag_app_bytes *out, ag_error *err);
/* A bundle stored as new parts: *items their views. The bundle's problems come back as
 * AG_ERR_PARSE whose text begins with the element named ("parts[0].grammar:12:3: ..."). */
ag_status ag_app_parts_import(ag_app *app, const char *data, size_t len, json_t **items,
                              ag_error *err);
/* Deletes the part when its newest version is `version`. */
ag_status ag_app_parts_delete(ag_app *app, int64_t id, int64_t version, ag_error *err);

/* A selection of model nodes (ids of its tree at version base; base 0: the current one):
 * {"model","version","nodes":[{"id","kind","label","rule","box","pattern"}],"tree":N,
 * "rule":[N...]}: the common ancestor at the tree level and those at the rule level. */
ag_status ag_app_parts_selection(ag_app *app, int64_t model, int64_t base, const int32_t *nodes,
                                 size_t n, json_t **out, ag_error *err);
/* A compose op previewed on version base: the GLB of what the new version would derive and
 * the composition's report; nothing is stored. */
ag_status ag_app_parts_compose_preview(ag_app *app, int64_t model, int64_t base,
                                       const json_t *op, ag_app_bytes *glb, json_t **report,
                                       ag_error *err);

#endif
