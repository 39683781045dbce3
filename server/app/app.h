/* The application: the composition of the store (one connection per thread), the sequencer
 * and its event bus, the job queue and its lanes, the kept edit models, and the use cases;
 * what archgramd's REST and live layers talk to. Their calls are in app_query.h (reads),
 * app_change.h (ops and edits) and app_jobs.h (jobs); the use cases themselves take only what
 * they need (app/store_env.h, app/workspace.h), so the CLI and tests run them without an app. */
#ifndef AG_APP_H
#define AG_APP_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "events.h"

#define AG_VERSION "0.1.0"

typedef struct ag_app ag_app;

typedef struct {
    const char *db_path;      /* required */
    const char *upload_dir;   /* NULL = "<db_path>.uploads" */
    int workers;              /* normal lane threads; 0 = number of cores */
    size_t queue_capacity;    /* 0 = 256 queued jobs */
    int demo;                 /* load the demo buildings when the database has no model */
} ag_app_options;

ag_status ag_app_create(const ag_app_options *opt, ag_app **out, ag_error *err);
/* Cancels queued and running jobs (marked cancelled in the store), drops waiting fast-lane
 * tasks, joins the workers. */
void ag_app_shutdown(ag_app *app);
void ag_app_free(ag_app *app);

ag_events *ag_app_events(ag_app *app);
const char *ag_app_upload_dir(const ag_app *app);
int ag_app_workers(const ag_app *app);

/* Runs run(user) on the job queue's fast lane (live previews and structural ops), or
 * drop(user) if the queue stops first. AG_ERR_BUSY when too much is waiting, AG_ERR_CANCELLED
 * while stopping: then neither is called. */
ag_status ag_app_run_fast(ag_app *app, void (*run)(void *user), void (*drop)(void *user),
                          void *user, ag_error *err);

/* Checks a name given to a model or a user: 1..200 characters of valid UTF-8 without control
 * characters. */
ag_status ag_app_check_name(const char *name, ag_error *err);

/* For the app's own facade files and tests: this thread's store environment, connection and
 * job queue. */
struct ag_store_env;
struct ag_db;
struct ag_jobqueue;
ag_status ag__app_env(ag_app *app, struct ag_store_env *env, ag_error *err);
struct ag_db *ag_app_db(ag_app *app, ag_error *err);
struct ag_jobqueue *ag__app_jobqueue(ag_app *app);
/* The tokens app/auth.c remembers (NULL when it could not be made: nothing is remembered). */
struct ag_auth_cache *ag__app_auth_cache(ag_app *app);

#endif
