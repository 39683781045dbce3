/* The extrusions and extrusion_buildings tables (migration 0003): how an extrusion model was
 * made (one plan, or a batch of footprints with a style) and, per building, its building
 * description JSON, its own mesh (the meshblob encoding, so an edit re-assembles the model
 * without re-extruding the other buildings), and its outcome.
 *
 * Every write runs inside the caller's transaction (ag_db_begin). */
#ifndef AG_EXTRUSIONS_H
#define AG_EXTRUSIONS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"

typedef struct {
    int64_t model;
    int batch;       /* 0: one plan uploaded as it is */
    char *meta_json; /* malloc'd */
    size_t buildings;
} ag_extrusion_row;

void ag_extrusions_row_clear(ag_extrusion_row *row);

typedef struct {
    int64_t model;
    int64_t building;  /* 0-based, mesh order */
    char *footprint;   /* the feature id; the mesh group's name */
    char *plan_json;   /* building description JSON */
    void *mesh;        /* meshblob of this building; NULL when it failed */
    size_t mesh_len;
    int64_t triangles;
    char status[16];   /* ok | failed (| not_watertight in rows of older versions) */
    char *reason;      /* NULL when built as described */
    /* what was built instead of the description's building: "simplified" | "flat" |
     * "block", or NULL (as described, or failed); borrowed when writing, static text when
     * read */
    const char *fallback;
    double moved;      /* a simplified footprint's boundary moved up to this far (m) */
} ag_extrusion_building;

/* Frees what ag_extrusions_get_building / _each_building filled in. */
void ag_extrusions_building_clear(ag_extrusion_building *b);

ag_status ag_extrusions_put(ag_db *db, int64_t model, int batch, const char *meta_json,
                            ag_error *err);
/* AG_ERR_NOT_FOUND when there is no such model, or when it is not an extrusion (the message
 * says which). */
ag_status ag_extrusions_get(ag_db *db, int64_t model, ag_extrusion_row *row, ag_error *err);

/* Inserts building b->building of b->model, or replaces it when it exists. Borrowed strings;
 * mesh may be NULL. */
ag_status ag_extrusions_put_building(ag_db *db, const ag_extrusion_building *b, ag_error *err);

enum {
    AG_EXTRUSIONS_PLAN = 1, /* read plan_json */
    AG_EXTRUSIONS_MESH = 2, /* read mesh */
};

/* One building; `what` says which large columns to read. AG_ERR_NOT_FOUND when the model has
 * no such building. */
ag_status ag_extrusions_get_building(ag_db *db, int64_t model, int64_t building, unsigned what,
                                     ag_extrusion_building *b, ag_error *err);
/* Calls fn for every building in order (the row's memory lives until fn returns; fn may keep
 * pointers by taking them and setting them to NULL). fn returns non-zero to stop; that value's
 * status goes back (an ag_status). */
ag_status ag_extrusions_each_building(ag_db *db, int64_t model, unsigned what,
                                      ag_status (*fn)(void *user, ag_extrusion_building *b),
                                      void *user, ag_error *err);

#endif
