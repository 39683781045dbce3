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
#include "task_budget.h"
#include "work_limits.h"

#define AG_VERSION "0.1.0"

typedef struct ag_app ag_app;

typedef struct {
    const char *db_path;      /* required */
    const char *upload_dir;   /* NULL = "<db_path>.uploads" */
    int workers;              /* normal lane threads; 0 = number of cores */
    size_t queue_capacity;    /* 0 = 256 queued jobs */
    int demo;                 /* load the demo buildings when the database has no model */
    int task_workers;         /* threads of the per-model task lanes; 0 = 2 × cores, at least 4 */
    ag_work_limits limits;    /* zero fields: the defaults (app/work_limits.h) */
    size_t db_max_bytes;      /* the database may grow to this size (0: no limit); past it
                                 changes fail with AG_ERR_STORAGE_FULL */
} ag_app_options;

ag_status ag_app_create(const ag_app_options *opt, ag_app **out, ag_error *err);
/* Cancels queued and running jobs (marked cancelled in the store), stops running tasks
 * (their budgets) and answers waiting ones through their drop functions, and waits at most
 * grace seconds (< 0: as long as it takes) for the workers. Returns 1 when all of them
 * stopped; 0 when work inside a stage that cannot be interrupted still runs: then record it
 * with ag_app_abandon and end the process without ag_app_free. */
int ag_app_shutdown(ag_app *app, double grace);
/* After a shutdown that did not stop everything: the jobs still running are recorded as
 * cancelled (on a connection of the caller's thread), so the store says what became of them
 * before the process ends. */
void ag_app_abandon(ag_app *app);
void ag_app_free(ag_app *app);

ag_events *ag_app_events(ag_app *app);
const char *ag_app_upload_dir(const ag_app *app);
int ag_app_workers(const ag_app *app);

/* The limits the app runs under (defaults filled in). */
const ag_work_limits *ag_app_limits(const ag_app *app);

/* Interactive work on the job queue's task lanes (app/jobqueue.h), under a budget. */
typedef enum {
    AG_TASK_OP,      /* a structural op, grammar edit or drag preview of `model`: op_seconds */
    AG_TASK_PREVIEW, /* an extrusion preview (model 0): preview_seconds */
} ag_task_kind;
/* Runs run(user, budget) on the lane of model (tasks of one model run in order, other
 * models' beside them), or drop(user) if the queue stops first. AG_ERR_BUSY when too much is
 * waiting, AG_ERR_CANCELLED while stopping: then neither is called. */
ag_status ag_app_run_task(ag_app *app, ag_task_kind kind, int64_t model,
                          void (*run)(void *user, ag_task_budget *budget),
                          void (*drop)(void *user), void *user, ag_error *err);

/* Checks a name given to a model or a user: 1..200 characters of valid UTF-8 without control
 * characters. */
ag_status ag_app_check_name(const char *name, ag_error *err);
/* Checks that s[0..len) is valid UTF-8: AG_ERR_INVALID naming `what` and the first bad byte
 * (1-based, in err->element) otherwise. */
ag_status ag_app_check_utf8(const char *what, const char *s, size_t len, ag_error *err);

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
