/* The buildings of an extrusion model (kind "extrusion"): one building description
 * extruded into a mesh of its own (stored per building, store/extrusions.h), and the model's
 * mesh assembled from the stored buildings in order, one group (named by the footprint id) and
 * one component per building that has geometry. The extrude job and plan/profile edits share
 * these, so an upload and an edit always give the same geometry. */
#ifndef AG_EXTRUSION_H
#define AG_EXTRUSION_H

#include <stddef.h>
#include <stdint.h>

#include "../core/extrude/plan.h"
#include "../core/mesh.h"
#include "../store/db.h"

typedef struct {
    char status[16];   /* ok | not_watertight | failed */
    char reason[256];  /* "" when ok */
    ag_status failure; /* why it failed (AG_OK unless failed) */
    size_t triangles;
    double seconds;
    uint8_t *blob;     /* meshblob of this building alone; NULL when failed */
    size_t blob_len;
} ag_extrusion_built;

void ag_extrusion_built_clear(ag_extrusion_built *b);

/* Extrudes plan (validated and cleaned in place) as one component of a group named
 * footprint. A plan that fails validation or the sweep gives status "failed" with the reason
 * and AG_OK; a shell that is not watertight is kept, with the failing faces in the reason.
 * When into is not NULL the building is also appended to it. Fails only on out-of-memory. */
ag_status ag_extrusion_build(ag_plan *plan, const char *footprint, ag_mesh *into,
                             ag_extrusion_built *out, ag_error *err);

/* Appends src to dst: its groups, components, vertices and triangles. */
ag_status ag_extrusion_append(ag_mesh *dst, const ag_mesh *src);

/* Assembles the model's mesh from its stored buildings (inside the caller's transaction)
 * and stores it as the model's mesh with its stats. *triangles (may be NULL) gets the total. */
ag_status ag_extrusion_store_mesh(ag_db *db, int64_t model, size_t *triangles, ag_error *err);

/* Summary JSON of a mesh as stored in models.stats (malloc'd, NULL on out-of-memory). */
char *ag_extrusion_stats(const ag_mesh *m);

#endif
