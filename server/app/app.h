/* The application: the database, the worker pool, the event bus and the use cases, shared
 * by the REST and live layers. Each thread that calls ag_app_db gets its own connection. */
#ifndef AG_APP_H
#define AG_APP_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "../store/db.h"
#include "events.h"

#define AG_VERSION "0.1.0"

typedef struct ag_app ag_app;

typedef struct {
    const char *db_path;      /* required */
    const char *upload_dir;   /* NULL = "<db_path>.uploads" */
    int workers;              /* 0 = number of cores */
    size_t queue_capacity;    /* 0 = 256 queued jobs */
    int demo;                 /* load the demo buildings when the database has no model */
} ag_app_options;

ag_status ag_app_create(const ag_app_options *opt, ag_app **out, ag_error *err);
/* Cancels queued and running jobs (marked cancelled in the store), joins the workers. */
void ag_app_shutdown(ag_app *app);
void ag_app_free(ag_app *app);

/* This thread's connection, opened on first use (NULL with err filled when it cannot be). */
ag_db *ag_app_db(ag_app *app, ag_error *err);
ag_events *ag_app_events(ag_app *app);
const char *ag_app_upload_dir(const ag_app *app);
const char *ag_app_db_path(const ag_app *app);
int ag_app_workers(const ag_app *app);

/* Serialises op commits and their events across threads, so events leave in version order. */
void ag__app_lock_ops(ag_app *app);
void ag__app_unlock_ops(ag_app *app);
struct ag_jobqueue *ag__app_jobqueue(ag_app *app);
/* The in-memory edit states of models (app/edit_session.h). */
struct ag_edit_sessions *ag__app_edit_sessions(ag_app *app);

#endif
