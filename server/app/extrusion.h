/* The buildings of an extrusion model (kind "extrusion"): one building description
 * extruded into a mesh of its own (stored per building, store/extrusions.h), and the model's
 * mesh assembled from the stored buildings in order, one group (named by the footprint id) and
 * one component per building that has geometry. The extrude job and plan/profile edits share
 * these, so an upload and an edit always give the same geometry.
 *
 * A building counts as described only when its triangles are a closed 2-manifold within
 * reach of its footprint (ag_extrude_result_ok); otherwise it falls back (simplified, flat,
 * block) and says why, exactly as `archgram extrude` reports it. Every extrusion runs under
 * the service's budget (events, time, memory) and stops when its job is cancelled or the
 * service shuts down. */
#ifndef AG_EXTRUSION_H
#define AG_EXTRUSION_H

#include <stddef.h>
#include <stdint.h>

#include <stdatomic.h>

#include "../core/extrude/building.h"
#include "../core/extrude/extrude.h"
#include "../core/extrude/plan.h"
#include "../core/mesh.h"
#include "../store/db.h"

typedef struct {
    char status[16];   /* ok (the geometry kept is good) | failed (none: refused) */
    char reason[256];  /* "" when built as described; else why not (and for failed why) */
    ag_status failure; /* why it failed (AG_OK unless failed) */
    ag_built built;    /* what was built: as described, simplified, flat, block or none */
    double moved;      /* a simplified footprint's boundary moved up to this far (m) */
    size_t triangles;
    size_t events;
    double seconds;
    char fixes[240];   /* what validation cleaned, "loop L corner C: reason; ..." or "" */
    uint8_t *blob;     /* meshblob of this building alone; NULL when failed */
    size_t blob_len;
} ag_extrusion_built;

void ag_extrusion_built_clear(ag_extrusion_built *b);

/* "simplified" | "flat" | "block" for a building that fell back, NULL otherwise (as
 * described, or failed). */
const char *ag_extrusion_built_fallback(const ag_extrusion_built *b);

/* The budget of the service's extrusions, set once at start-up (archgramd's --extrude-*
 * flags) before any extrusion runs; zeroes keep the defaults below. */
typedef struct {
    double seconds;   /* per building (and per preview); 0: AG_EXTRUSION_SECONDS; < 0: none */
    size_t max_events; /* per building; 0: the library's default by plan size */
    size_t max_bytes;  /* per building; 0: the library's default by plan size */
    size_t threads;    /* per batch; 0: every core */
} ag_extrusion_limits;

#define AG_EXTRUSION_SECONDS 10.0

void ag_extrusion_configure(const ag_extrusion_limits *limits);
/* The limits in force (the defaults filled in). */
ag_extrusion_limits ag_extrusion_limits_get(void);

/* Stops every extrusion of the process at its next budget poll (milliseconds) and makes
 * new ones stop at once: archgramd calls it first thing on SIGTERM / SIGINT. */
void ag_extrusion_stop_all(void);
int ag_extrusion_stopping(void);

/* The options of one extrusion in the service: the configured limits, the time budget
 * ending at `deadline` (CLOCK_MONOTONIC seconds; 0: the configured per-building
 * seconds), cancelled when *cancel becomes non-zero (may be NULL), when `cancelled(user)`
 * says so (may be NULL: e.g. ag_workspace_cancelled of a job) and on ag_extrusion_stop_all.
 * `hook` is storage the options point into: it must outlive the extrusion. For a REST
 * preview: ag_extrusion_options(&o, &hook, request_deadline, &client_gone, NULL, NULL). */
typedef struct {
    const atomic_int *cancel;
    int (*cancelled)(void *user);
    void *user;
} ag_extrusion_cancel;
void ag_extrusion_options(ag_extrude_options *o, ag_extrusion_cancel *hook, double deadline,
                          const atomic_int *cancel, int (*cancelled)(void *user), void *user);

/* Extrudes plan (validated and cleaned in place) as one component of a group named
 * footprint, under opt (NULL: ag_extrusion_options' defaults): as described when that
 * building is good, else a flat roof, else a block (ag_building_extrude_plan), each
 * reported in out. A plan that validation refuses gives status "failed" with the reason
 * and AG_OK. When into is not NULL the building is also appended to it. Fails only on
 * out-of-memory and AG_ERR_CANCELLED. */
ag_status ag_extrusion_build(ag_plan *plan, const char *footprint, const ag_extrude_options *opt,
                             ag_mesh *into, ag_extrusion_built *out, ag_error *err);

/* Fills out (holding nothing: new or cleared) from a building's result and its own mesh m
 * (encoded into out->blob unless nothing was built). AG_ERR_NOMEM. */
ag_status ag_extrusion_built_set(ag_extrusion_built *out, const ag_building_result *r,
                                 const ag_mesh *m, ag_error *err);

/* Appends src to dst: its groups, components, vertices and triangles. */
ag_status ag_extrusion_append(ag_mesh *dst, const ag_mesh *src);

/* Assembles the model's mesh from its stored buildings (inside the caller's transaction)
 * and stores it as the model's mesh with its stats. *triangles (may be NULL) gets the total. */
ag_status ag_extrusion_store_mesh(ag_db *db, int64_t model, size_t *triangles, ag_error *err);

/* Summary JSON of a mesh as stored in models.stats (malloc'd, NULL on out-of-memory). */
char *ag_extrusion_stats(const ag_mesh *m);

#endif
