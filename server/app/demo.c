#include "demo.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../core/demo_building.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "store_ws.h"
#include "usecase_save_part.h"

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

/* --- demo parts ----------------------------------------------------------------------------- */

/* The pattern holding the most nodes: the row house's grid of windows. */
static int32_t largest_pattern(const ag_splittree *t)
{
    int32_t best = -1;
    size_t most = 1;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_PATTERN || n->pattern < 0)
            continue;
        const ag_pattern *p = &t->patterns[n->pattern];
        size_t cells = (size_t)p->counts[0] * p->counts[1] * p->counts[2];
        if (cells > most) {
            most = cells;
            best = (int32_t)i;
        }
    }
    return best;
}

/* A visible node of a door's size (0.5 to 1.2 m wide, 1.9 to 2.5 m tall), once. */
static int32_t door_sized(const ag_splittree *t)
{
    int32_t found = -1;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        double w = fmax(n->box.max[0] - n->box.min[0], n->box.max[1] - n->box.min[1]);
        double h = n->box.max[2] - n->box.min[2];
        if (n->kind == AG_NODE_COMPONENT && w >= 0.5 && w <= 1.2 && h >= 1.9 && h <= 2.5) {
            if (found >= 0)
                return -1;
            found = (int32_t)i;
        }
    }
    return found;
}

typedef struct {
    int building;                     /* ag_demo_building index */
    int32_t (*pick)(const ag_splittree *t);
    const char *name, *description;
    const char *tags[3];
    size_t ntags;
} demo_part;

static const demo_part demo_parts[] = {
    {0, ag_splittree_most_repeated, "Framed window", "A window of the row house: a frame of four bars", {"window", "frame", "demo"}, 3},
    {0, largest_pattern, "Row of windows", "The row house's grid of twelve windows", {"window", "facade", "demo"}, 3},
    {0, door_sized, "Front door", "The row house's door: a frame and its leaf", {"door", "demo"}, 2},
    {1, ag_splittree_most_repeated, "Column", "A column of the octagonal tower", {"column", "demo"}, 2},
};

/* The model's edit state once a job has proceduralized it (polled, at most a minute). */
static ag_status wait_proceduralized(ag_store_env *env, ag_jobctx *ctx, int64_t model,
                                     ag_edit_state **st, ag_error *err)
{
    for (int tries = 0;; tries++) {
        ag_error e;
        ag_error_clear(&e);
        ag_status s = ag_edit_session_acquire(env->sessions, env->db, model, st, &e);
        if (s != AG_ERR_NOT_PROCEDURALIZED) {
            if (s != AG_OK && err)
                *err = e;
            return s;
        }
        if (ag_jobctx_cancelled(ctx))
            return ag_error_set(err, AG_ERR_CANCELLED, 0, "the job was cancelled");
        if (tries == 1200)
            return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                                "demo model %lld was not proceduralized within a minute",
                                (long long)model);
        usleep(50000);
    }
}

static ag_status run_demo_parts(void *services, ag_jobctx *ctx, int64_t job,
                                const ag_job_params *p, ag_error *err)
{
    if (p->type != AG_JOB_DEMO_PARTS)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "a demo-parts job without its params");
    ag_store_env env;
    ag_status s = ag_store_services_env(services, &env, err);
    json_t *saved = json_array();
    const size_t nparts = sizeof demo_parts / sizeof demo_parts[0];
    for (size_t i = 0; s == AG_OK && i < nparts; i++) {
        const demo_part *d = &demo_parts[i];
        if ((size_t)d->building >= p->u.demo_parts.n)
            continue;
        int64_t model = p->u.demo_parts.models[d->building];
        ag_edit_state *st = NULL;
        if ((s = wait_proceduralized(&env, ctx, model, &st, err)) != AG_OK)
            break;
        int32_t node = d->pick(st->em->proc->tree);
        int64_t version = st->version;
        ag_edit_session_release(env.sessions, st);
        if (node < 0)
            continue; /* the building no longer looks as the pick expects: no such part */
        ag_part_meta meta = {.name = d->name, .description = d->description, .tags = d->tags,
                             .ntags = d->ntags};
        ag_store_ws w;
        ag_store_ws_init(&w, &(ag_store_ws_options){.env = env, .model = model,
                                                    .base = version});
        ag_usecase_save_part_result r;
        s = ag_usecase_save_part_run(
            &w.ws, &(ag_usecase_save_part_params){.nodes = &node, .nnodes = 1, .meta = &meta},
            &r, err);
        ag_store_ws_end(&w, s);
        if (s == AG_OK)
            json_array_append_new(saved, json_integer((json_int_t)w.part_id));
        ag_jobctx_progress(ctx, (double)(i + 1) / (double)nparts, "parts");
    }
    char *result = NULL;
    if (s == AG_OK) {
        json_t *r = json_pack("{s:O}", "parts", saved);
        result = r ? json_dumps(r, JSON_COMPACT) : NULL;
        json_decref(r);
        if (!result)
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (s == AG_OK && (s = ag_db_begin(env.db, err)) == AG_OK) {
        s = ag_jobs_finish(env.db, job, "succeeded", result, NULL, 0, err);
        s = s == AG_OK ? ag_db_commit(env.db, err) : (ag_db_rollback(env.db), s);
    }
    free(result);
    json_decref(saved);
    return s;
}

const ag_job_kind ag_demo_parts_job_kind = {.kind = "demo-parts", .run = run_demo_parts};

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
    /* a few parts saved from the buildings once they are proceduralized */
    ag_job_params dp = {.type = AG_JOB_DEMO_PARTS};
    for (int i = 0; i < n && i < AG_DEMO_PARTS_MAX_MODELS; i++)
        dp.u.demo_parts.models[dp.u.demo_parts.n++] = ids[i];
    if (s == AG_OK)
        s = ag_jobqueue_submit(jobs, "demo-parts", &dp, &job, err);
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
