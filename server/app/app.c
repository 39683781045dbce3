#include "app.h"

#include <dirent.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../store/jobs.h"
#include "demo.h"
#include "edit_session.h"
#include "extrude_job.h"
#include "import_job.h"
#include "jobqueue.h"
#include "proceduralize_job.h"

struct ag_app {
    char *db_path;
    char *upload_dir;
    int workers;
    ag_events *events;
    ag_jobqueue *jobs;
    ag_edit_sessions *edit_sessions;
    pthread_key_t db_key;
    pthread_mutex_t ops_lock;
    pthread_mutex_t conns_lock;
    ag_db **conns; /* every connection opened, closed at ag_app_free */
    size_t nconns, capconns;
};

static void forget_thread_db(void *db)
{
    (void)db; /* connections are owned by the app's list; nothing to do at thread exit */
}

ag_db *ag_app_db(ag_app *app, ag_error *err)
{
    ag_db *db = pthread_getspecific(app->db_key);
    if (db)
        return db;
    if (ag_db_open(app->db_path, &(ag_db_options){.no_migrate = 1}, &db, err) != AG_OK)
        return NULL;
    pthread_mutex_lock(&app->conns_lock);
    if (app->nconns == app->capconns) {
        size_t cap = app->capconns ? app->capconns * 2 : 16;
        ag_db **grown = realloc(app->conns, cap * sizeof *grown);
        if (!grown) {
            pthread_mutex_unlock(&app->conns_lock);
            ag_db_close(db);
            ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory opening a connection");
            return NULL;
        }
        app->conns = grown;
        app->capconns = cap;
    }
    app->conns[app->nconns++] = db;
    pthread_mutex_unlock(&app->conns_lock);
    pthread_setspecific(app->db_key, db);
    return db;
}

/* Thread-local connections of threads that have ended (MHD's, workers') are closed here;
 * threads are few and long-lived, so keeping them until then costs little. */
static void close_all_connections(ag_app *app)
{
    for (size_t i = 0; i < app->nconns; i++)
        ag_db_close(app->conns[i]);
    free(app->conns);
    app->conns = NULL;
    app->nconns = app->capconns = 0;
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

ag_events *ag_app_events(ag_app *app) { return app->events; }
const char *ag_app_upload_dir(const ag_app *app) { return app->upload_dir; }
const char *ag_app_db_path(const ag_app *app) { return app->db_path; }
int ag_app_workers(const ag_app *app) { return app->workers; }
void ag__app_lock_ops(ag_app *app) { pthread_mutex_lock(&app->ops_lock); }
void ag__app_unlock_ops(ag_app *app) { pthread_mutex_unlock(&app->ops_lock); }
struct ag_jobqueue *ag__app_jobqueue(ag_app *app) { return app->jobs; }
struct ag_edit_sessions *ag__app_edit_sessions(ag_app *app) { return app->edit_sessions; }

ag_status ag_app_create(const ag_app_options *opt, ag_app **out, ag_error *err)
{
    *out = NULL;
    ag_app *app = calloc(1, sizeof *app);
    if (!app)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    pthread_key_create(&app->db_key, forget_thread_db);
    pthread_mutex_init(&app->ops_lock, NULL);
    pthread_mutex_init(&app->conns_lock, NULL);
    app->db_path = strdup(opt->db_path);
    if (opt->upload_dir)
        app->upload_dir = strdup(opt->upload_dir);
    else if (asprintf(&app->upload_dir, "%s.uploads", opt->db_path) < 0)
        app->upload_dir = NULL;
    app->events = ag_events_create();
    app->edit_sessions = ag_edit_sessions_create();
    if (!app->db_path || !app->upload_dir || !app->events || !app->edit_sessions) {
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

    /* The first connection creates and migrates the schema; the others only open it. */
    ag_db *db = NULL;
    ag_status s = ag_db_open(app->db_path, NULL, &db, err);
    if (s != AG_OK) {
        ag_app_free(app);
        return s;
    }
    ag_db_close(db);
    if (!(db = ag_app_db(app, err))) {
        ag_app_free(app);
        return err ? err->code : AG_ERR_DB;
    }
    /* A previous process that died mid-job left rows behind: say what became of them. */
    int left = 0;
    if ((s = ag_db_begin(db, err)) == AG_OK) {
        s = ag_jobs_cancel_unfinished(
            db,
            "{\"type\":\"urn:archgram:problem:cancelled\",\"title\":\"the work was cancelled\","
            "\"status\":409,\"detail\":\"archgramd stopped before the job finished\"}",
            &left, err);
        s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    }
    if (s != AG_OK) {
        ag_app_free(app);
        return s;
    }
    app->workers = opt->workers > 0 ? opt->workers : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (app->workers < 1)
        app->workers = 1;
    app->jobs = ag_jobqueue_create(app, app->workers, opt->queue_capacity);
    if (!app->jobs) {
        ag_app_free(app);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "cannot start the worker threads");
    }
    ag_jobqueue_register(app->jobs, &ag_import_job_kind);
    ag_jobqueue_register(app->jobs, &ag_extrude_job_kind);
    ag_jobqueue_register(app->jobs, &ag_proceduralize_job_kind);
    /* after the job kinds: the demo content is proceduralized and extruded by jobs */
    if (opt->demo && (s = ag_demo_load_if_empty(app, err)) != AG_OK) {
        ag_app_free(app);
        return s;
    }
    *out = app;
    return AG_OK;
}

void ag_app_shutdown(ag_app *app)
{
    if (app && app->jobs)
        ag_jobqueue_stop(app->jobs);
}

void ag_app_free(ag_app *app)
{
    if (!app)
        return;
    ag_jobqueue_free(app->jobs);
    ag_edit_sessions_free(app->edit_sessions);
    close_all_connections(app);
    ag_events_free(app->events);
    pthread_key_delete(app->db_key);
    pthread_mutex_destroy(&app->ops_lock);
    pthread_mutex_destroy(&app->conns_lock);
    free(app->db_path);
    free(app->upload_dir);
    free(app);
}
