#include "extrusions.h"

#include <stdlib.h>
#include <string.h>

void ag_extrusions_row_clear(ag_extrusion_row *row)
{
    if (!row)
        return;
    free(row->meta_json);
    row->meta_json = NULL;
}

void ag_extrusions_building_clear(ag_extrusion_building *b)
{
    if (!b)
        return;
    free(b->footprint);
    free(b->plan_json);
    free(b->mesh);
    free(b->reason);
    b->footprint = b->plan_json = b->reason = NULL;
    b->mesh = NULL;
    b->mesh_len = 0;
}

ag_status ag_extrusions_put(ag_db *db, int64_t model, int batch, const char *meta_json,
                            ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "INSERT OR REPLACE INTO extrusions (model_id, batch, meta) "
                                 "VALUES (?, ?, ?)",
                                 err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    sqlite3_bind_int(st, 2, batch ? 1 : 0);
    sqlite3_bind_text(st, 3, meta_json ? meta_json : "{}", -1, SQLITE_STATIC);
    return ag_db_step_done(db, st, "storing an extrusion", err);
}

ag_status ag_extrusions_get(ag_db *db, int64_t model, ag_extrusion_row *row, ag_error *err)
{
    memset(row, 0, sizeof *row);
    sqlite3_stmt *st;
    /* The LEFT JOIN tells "no such model" from "not an extrusion" in one statement. */
    ag_status s = ag_db_prepared(
        db, &st,
        "SELECT e.model_id, e.batch, e.meta, "
        "(SELECT count(*) FROM extrusion_buildings b WHERE b.model_id = m.id) "
        "FROM models m LEFT JOIN extrusions e ON e.model_id = m.id WHERE m.id = ?",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, model);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    else if (rc != SQLITE_ROW)
        s = ag_db_fail(db, err, "reading an extrusion");
    else if (sqlite3_column_type(st, 0) == SQLITE_NULL)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0,
                         "model %lld is not an extrusion: it has no plan", (long long)model);
    else {
        int bad = 0;
        row->model = model;
        row->batch = sqlite3_column_int(st, 1);
        row->meta_json = ag_db_column_dup(st, 2, NULL, &bad);
        row->buildings = (size_t)sqlite3_column_int64(st, 3);
        if (bad || !row->meta_json) {
            ag_extrusions_row_clear(row);
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading an extrusion");
        }
    }
    sqlite3_reset(st);
    return s;
}

ag_status ag_extrusions_put_building(ag_db *db, const ag_extrusion_building *b, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "INSERT INTO extrusion_buildings "
        "(model_id, building, footprint, plan, mesh, triangles, status, reason, fallback, moved) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?) "
        "ON CONFLICT (model_id, building) DO UPDATE SET footprint = excluded.footprint, "
        "plan = excluded.plan, mesh = excluded.mesh, triangles = excluded.triangles, "
        "status = excluded.status, reason = excluded.reason, fallback = excluded.fallback, "
        "moved = excluded.moved",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, b->model);
    sqlite3_bind_int64(st, 2, b->building);
    sqlite3_bind_text(st, 3, b->footprint ? b->footprint : "", -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 4, b->plan_json ? b->plan_json : "{}", -1, SQLITE_STATIC);
    if (b->mesh)
        sqlite3_bind_blob64(st, 5, b->mesh, b->mesh_len, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 5);
    sqlite3_bind_int64(st, 6, b->triangles);
    sqlite3_bind_text(st, 7, b->status[0] ? b->status : "ok", -1, SQLITE_STATIC);
    if (b->reason)
        sqlite3_bind_text(st, 8, b->reason, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 8);
    if (b->fallback)
        sqlite3_bind_text(st, 9, b->fallback, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 9);
    if (b->fallback)
        sqlite3_bind_double(st, 10, b->moved);
    else
        sqlite3_bind_null(st, 10);
    return ag_db_step_done(db, st, "storing a building of an extrusion", err);
}

/* The stored fallback name as static text (the table's CHECK allows these only). */
static const char *fallback_name(sqlite3_stmt *st, int col)
{
    static const char *const names[] = {"simplified", "flat", "block"};
    const char *v = (const char *)sqlite3_column_text(st, col);
    for (size_t i = 0; v && i < sizeof names / sizeof *names; i++)
        if (strcmp(v, names[i]) == 0)
            return names[i];
    return NULL;
}

/* Fills b from a row of SELECT building, footprint, triangles, status, reason, plan, mesh,
 * fallback, moved. */
static int read_building(sqlite3_stmt *st, int64_t model, unsigned what, ag_extrusion_building *b)
{
    memset(b, 0, sizeof *b);
    int bad = 0;
    b->model = model;
    b->building = sqlite3_column_int64(st, 0);
    b->footprint = ag_db_column_dup(st, 1, NULL, &bad);
    b->triangles = sqlite3_column_int64(st, 2);
    ag_db_column_copy(st, 3, b->status, sizeof b->status);
    b->reason = ag_db_column_dup(st, 4, NULL, &bad);
    if (what & AG_EXTRUSIONS_PLAN)
        b->plan_json = ag_db_column_dup(st, 5, NULL, &bad);
    if ((what & AG_EXTRUSIONS_MESH) && sqlite3_column_type(st, 6) == SQLITE_BLOB) {
        size_t n = (size_t)sqlite3_column_bytes(st, 6);
        b->mesh = malloc(n ? n : 1);
        if (b->mesh) {
            memcpy(b->mesh, sqlite3_column_blob(st, 6), n);
            b->mesh_len = n;
        } else {
            bad = 1;
        }
    }
    b->fallback = fallback_name(st, 7);
    b->moved = sqlite3_column_double(st, 8);
    if (!b->footprint)
        bad = 1;
    if (bad)
        ag_extrusions_building_clear(b);
    return !bad;
}

#define BUILDING_COLUMNS                                                                        \
    "SELECT building, footprint, triangles, status, reason, CASE WHEN ? THEN plan END, "        \
    "CASE WHEN ? THEN mesh END, fallback, moved FROM extrusion_buildings WHERE model_id = ? "

ag_status ag_extrusions_get_building(ag_db *db, int64_t model, int64_t building, unsigned what,
                                     ag_extrusion_building *b, ag_error *err)
{
    memset(b, 0, sizeof *b);
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, BUILDING_COLUMNS "AND building = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int(st, 1, (what & AG_EXTRUSIONS_PLAN) != 0);
    sqlite3_bind_int(st, 2, (what & AG_EXTRUSIONS_MESH) != 0);
    sqlite3_bind_int64(st, 3, model);
    sqlite3_bind_int64(st, 4, building);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "model %lld has no building %lld",
                         (long long)model, (long long)building);
    else if (rc != SQLITE_ROW)
        s = ag_db_fail(db, err, "reading a building of an extrusion");
    else if (!read_building(st, model, what, b))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a building");
    sqlite3_reset(st);
    return s;
}

ag_status ag_extrusions_each_building(ag_db *db, int64_t model, unsigned what,
                                      ag_status (*fn)(void *user, ag_extrusion_building *b),
                                      void *user, ag_error *err)
{
    /* Not the statement cache: fn may read other buildings while this one is stepping. */
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(ag_db_handle(db), BUILDING_COLUMNS "ORDER BY building", -1, &st,
                           NULL) != SQLITE_OK)
        return ag_db_fail(db, err, "reading the buildings of an extrusion");
    sqlite3_bind_int(st, 1, (what & AG_EXTRUSIONS_PLAN) != 0);
    sqlite3_bind_int(st, 2, (what & AG_EXTRUSIONS_MESH) != 0);
    sqlite3_bind_int64(st, 3, model);
    ag_status s = AG_OK;
    int rc = SQLITE_DONE;
    while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        ag_extrusion_building b;
        if (!read_building(st, model, what, &b)) {
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading a building");
            break;
        }
        s = fn(user, &b);
        ag_extrusions_building_clear(&b);
    }
    if (s == AG_OK && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading the buildings of an extrusion");
    sqlite3_finalize(st);
    return s;
}
