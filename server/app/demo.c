#include "demo.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../core/demo_building.h"
#include "../store/models.h"
#include "store_ws.h"

/* A short street of footprints in metres (x along the street), each with a height: the
 * extrusion demo. Written as GeoJSON so it goes through the same job as an upload. */
static char *demo_street_geojson(void)
{
    static const struct { double x, w, d, h; int kind; } lots[] = {
        {0, 9, 12, 7.5, 0},  {10, 7, 11, 6.0, 0}, {18, 12, 14, 9.0, 1},
        {31, 8, 12, 7.0, 0}, {40, 16, 16, 10.5, 2}, {57, 6, 10, 5.5, 0},
    };
    json_t *features = json_array();
    for (size_t i = 0; features && i < sizeof lots / sizeof lots[0]; i++) {
        double x0 = lots[i].x, x1 = x0 + lots[i].w, d = lots[i].d;
        json_t *outer;
        if (lots[i].kind == 1) /* an L: the back right corner cut away */
            outer = json_pack("[[f,f],[f,f],[f,f],[f,f],[f,f],[f,f],[f,f]]", x0, 0.0, x1, 0.0,
                              x1, d * 0.5, x0 + lots[i].w * 0.5, d * 0.5, x0 + lots[i].w * 0.5, d,
                              x0, d, x0, 0.0);
        else
            outer = json_pack("[[f,f],[f,f],[f,f],[f,f],[f,f]]", x0, 0.0, x1, 0.0, x1, d, x0, d,
                              x0, 0.0);
        json_t *rings = json_pack("[o]", outer);
        if (rings && lots[i].kind == 2) /* a courtyard: a clockwise hole */
            json_array_append_new(rings, json_pack("[[f,f],[f,f],[f,f],[f,f],[f,f]]", x0 + 5, 5.0,
                                                   x0 + 5, d - 5, x1 - 5, d - 5, x1 - 5, 5.0,
                                                   x0 + 5, 5.0));
        char id[32];
        snprintf(id, sizeof id, "lot-%zu", i + 1);
        json_array_append_new(features,
                              json_pack("{s:s, s:s, s:{s:f}, s:{s:s, s:o}}", "type", "Feature",
                                        "id", id, "properties", "height", lots[i].h, "geometry",
                                        "type", "Polygon", "coordinates", rings));
    }
    json_t *doc = json_pack("{s:s, s:o}", "type", "FeatureCollection", "features", features);
    char *text = doc ? json_dumps(doc, JSON_COMPACT) : NULL;
    json_decref(doc);
    return text;
}

/* Spools the street to a temporary file (the extrude job reads and removes its upload). */
static char *spool_street(ag_error *err)
{
    char *text = demo_street_geojson();
    const char *tmp = getenv("TMPDIR");
    char *path = NULL;
    if (!text || asprintf(&path, "%s/archgram-demo-XXXXXX", tmp && *tmp ? tmp : "/tmp") < 0) {
        free(text);
        ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        return NULL;
    }
    int fd = mkstemp(path);
    size_t len = strlen(text);
    int ok = fd >= 0 && write(fd, text, len) == (ssize_t)len;
    if (fd >= 0)
        close(fd);
    free(text);
    if (!ok) {
        if (fd >= 0)
            unlink(path);
        ag_error_set(err, AG_ERR_IO, 0, "cannot write the demo street to %s", path);
        free(path);
        return NULL;
    }
    return path;
}

ag_status ag_demo_load_if_empty(ag_db *db, ag_jobqueue *jobs, ag_error *err)
{
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    int64_t ids[8];
    int n = 0;
    if (ag_models_count(db) == 0) {
        for (int i = 0; s == AG_OK && n < 8; i++) {
            ag_mesh *m = ag_demo_building(i);
            if (!m)
                break;
            s = ag_store_ws_insert_model(db, ag_demo_building_name(i), m, NULL, 0, NULL,
                                         &ids[n], err);
            /* the server's own content: every account may look at it */
            if (s == AG_OK)
                s = ag_models_set_public_read(db, ids[n], 1, err);
            n++;
            ag_mesh_free(m);
        }
    }
    s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    if (s != AG_OK || n == 0)
        return s;
    /* The demo buildings are proceduralized and the street extruded by ordinary jobs, so a
     * newcomer can edit at once; a job that fails leaves the plain model, never a partial one. */
    int64_t job;
    for (int i = 0; s == AG_OK && i < n; i++) {
        ag_job_params p = {.type = AG_JOB_PROCEDURALIZE,
                           .u.proceduralize = {.model = ids[i], .base = 1, .author = "demo"}};
        s = ag_jobqueue_submit(jobs, "proceduralize", &p, &job, err);
    }
    char *path = s == AG_OK ? spool_street(err) : NULL;
    if (path) {
        ag_job_params p = {.type = AG_JOB_EXTRUDE,
                           .u.extrude = {.upload = path,
                                         .name = "Demo street",
                                         .format = "geojson",
                                         .style = "gable",
                                         .height_property = "height",
                                         .seed = -1,
                                         .lonlat = -1}};
        s = ag_jobqueue_submit(jobs, "extrude", &p, &job, err);
        if (s != AG_OK)
            unlink(path);
        free(path);
    } else if (s == AG_OK) {
        s = err ? err->code : AG_ERR_IO;
    }
    return s;
}
