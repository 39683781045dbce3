#include "app.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../core/utf8.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "auth.h"
#include "demo.h"
#include "extrude_job.h"
#include "heap.h"
#include "import_job.h"
#include "jobqueue.h"
#include "proceduralize_job.h"
#include "segment_job.h"
#include "store_env.h"

struct ag_app {
    char *upload_dir;
    int workers;
    ag_work_limits limits;
    ag_events *events;
    ag_store_services services; /* the pool, the sequencer, the kept edit models */
    ag_jobqueue *jobs;
    ag_auth_cache *auth; /* tokens found lately (app/auth.h) */
};

ag_status ag__app_env(ag_app *app, ag_store_env *env, ag_error *err)
{
    return ag_store_services_env(&app->services, env, err);
}

ag_db *ag_app_db(ag_app *app, ag_error *err) { return ag_dbpool_get(app->services.pool, err); }
ag_events *ag_app_events(ag_app *app) { return app->events; }
const char *ag_app_upload_dir(const ag_app *app) { return app->upload_dir; }
int ag_app_workers(const ag_app *app) { return app->workers; }
struct ag_jobqueue *ag__app_jobqueue(ag_app *app) { return app->jobs; }
struct ag_auth_cache *ag__app_auth_cache(ag_app *app) { return app->auth; }

ag_status ag_app_check_name(const char *name, ag_error *err)
{
    return ag_models_check_name(name, err);
}

ag_status ag_app_check_utf8(const char *what, const char *s, size_t len, ag_error *err)
{
    size_t valid = ag_utf8_valid_prefix(s, len);
    if (valid == len)
        return AG_OK;
    return ag_error_set(err, AG_ERR_INVALID, (long)valid + 1, "%s is not valid UTF-8 (byte %zu)",
                        what, valid + 1);
}

const ag_work_limits *ag_app_limits(const ag_app *app) { return &app->limits; }

ag_status ag_app_run_task(ag_app *app, ag_task_kind kind, int64_t model,
                          void (*run)(void *user, ag_task_budget *budget),
                          void (*drop)(void *user), void *user, ag_error *err)
{
    double seconds = kind == AG_TASK_PREVIEW ? app->limits.preview_seconds
                                             : app->limits.op_seconds;
    return ag_jobqueue_run_task(app->jobs, kind == AG_TASK_PREVIEW ? 0 : model, seconds, run,
                                drop, user, err);
}

static void purge_uploads(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    char path[4096];
    while ((e = readdir(d))) {
        if (strncmp(e->d_name, "upload-", 7) != 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        unlink(path);
    }
    closedir(d);
}

/* A previous process that died mid-job left rows behind: say what became of them. */
static ag_status cancel_leftovers(ag_db *db, ag_error *err)
{
    int left = 0;
    ag_status s = ag_db_begin(db, err);
    if (s != AG_OK)
        return s;
    s = ag_jobs_cancel_unfinished(
        db,
        "{\"type\":\"urn:archgram:problem:cancelled\",\"title\":\"the work was cancelled\","
        "\"status\":409,\"detail\":\"archgramd stopped before the job finished\"}",
        &left, err);
    return s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
}

ag_status ag_app_create(const ag_app_options *opt, ag_app **out, ag_error *err)
{
    ag_heap_keep_large_blocks();
    *out = NULL;
    ag_app *app = calloc(1, sizeof *app);
    if (!app)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (opt->upload_dir)
        app->upload_dir = strdup(opt->upload_dir);
    else if (asprintf(&app->upload_dir, "%s.uploads", opt->db_path) < 0)
        app->upload_dir = NULL;
    app->limits = ag_work_limits_resolved(&opt->limits);
    app->services.limits = &app->limits;
    app->events = ag_events_create();
    app->services.seq = app->events ? ag_sequencer_create(app->events) : NULL;
    app->services.sessions = ag_edit_sessions_create();
    app->auth = ag_auth_cache_create();
    if (!app->upload_dir || !app->services.seq || !app->services.sessions || !app->auth) {
        ag_app_free(app);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    if (mkdir(app->upload_dir, 0700) != 0 && errno != EEXIST) {
        ag_error_set(err, AG_ERR_IO, 0, "cannot create the upload folder %s: %s",
                     app->upload_dir, strerror(errno));
        ag_app_free(app);
        return AG_ERR_IO;
    }
    purge_uploads(app->upload_dir);
    ag_status s = ag_dbpool_create_ex(opt->db_path, opt->db_max_bytes, &app->services.pool, err);
    ag_db *db = s == AG_OK ? ag_dbpool_get(app->services.pool, err) : NULL;
    if (s == AG_OK && !db)
        s = err ? err->code : AG_ERR_DB;
    if (s == AG_OK)
        s = cancel_leftovers(db, err);
    if (s != AG_OK) {
        ag_app_free(app);
        return s;
    }
    app->workers = opt->workers > 0 ? opt->workers : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (app->workers < 1)
        app->workers = 1;
    int task_workers = opt->task_workers;
    if (task_workers <= 0) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        task_workers = cores > 0 ? 2 * (int)cores : 4;
        if (task_workers < 4)
            task_workers = 4;
    }
    ag_jobqueue_options qo = {.db = app->services.pool,
                              .seq = app->services.seq,
                              .workers = app->workers,
                              .capacity = opt->queue_capacity,
                              .job_seconds = app->limits.job_seconds,
                              .task_workers = task_workers};
    if (!(app->jobs = ag_jobqueue_create(&qo))) {
        ag_app_free(app);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "cannot start the worker threads");
    }
    ag_jobqueue_register(app->jobs, &ag_import_job_kind, &app->services);
    ag_jobqueue_register(app->jobs, &ag_extrude_job_kind, &app->services);
    ag_jobqueue_register(app->jobs, &ag_proceduralize_job_kind, &app->services);
    ag_jobqueue_register(app->jobs, &ag_demo_parts_job_kind, &app->services);
    ag_jobqueue_register(app->jobs, &ag_segment_job_kind, &app->services);
    /* after the job kinds: the demo content is proceduralized and extruded by jobs */
    if (opt->demo && (s = ag_demo_load_if_empty(db, app->jobs, err)) != AG_OK) {
        ag_app_free(app);
        return s;
    }
    *out = app;
    return AG_OK;
}

int ag_app_shutdown(ag_app *app, double grace)
{
    return app && app->jobs ? ag_jobqueue_stop(app->jobs, grace) : 1;
}

void ag_app_abandon(ag_app *app)
{
    if (!app || !app->services.pool)
        return;
    /* a connection of its own with a short wait: a worker may hold the write lock, and then
     * the next start records the rows instead (cancel_leftovers) */
    ag_db *db = NULL;
    if (ag_db_open(ag_dbpool_path(app->services.pool),
                   &(ag_db_options){.busy_timeout_ms = 200, .no_migrate = 1}, &db,
                   NULL) == AG_OK)
        cancel_leftovers(db, NULL);
    ag_db_close(db);
}

void ag_app_free(ag_app *app)
{
    if (!app)
        return;
    ag_jobqueue_free(app->jobs);
    ag_edit_sessions_free(app->services.sessions);
    ag_dbpool_free(app->services.pool);
    ag_sequencer_free(app->services.seq);
    ag_events_free(app->events);
    ag_auth_cache_free(app->auth);
    free(app->upload_dir);
    free(app);
}
