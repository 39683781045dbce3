/* The bounded job queue and its worker threads.
 *
 * A job is a row in the jobs table plus an entry here. A kind's run function does the work
 * on a worker thread, reports progress through its ag_jobctx and honours cancellation; on
 * success it must call ag_jobs_finish(..., "succeeded", ...) inside the same transaction that
 * makes its result visible, after a last ag_jobctx_cancelled() check, so a job never
 * succeeds half-way. Failures and cancellations are recorded by the queue. */
#ifndef AG_JOBQUEUE_H
#define AG_JOBQUEUE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "app.h"

typedef struct ag_jobctx ag_jobctx;
typedef struct ag_jobqueue ag_jobqueue;

typedef struct {
    const char *kind;
    ag_status (*run)(ag_app *app, ag_jobctx *ctx, int64_t job, const char *params_json,
                     ag_error *err);
    /* Frees what params point at (e.g. an uploaded file), whatever the outcome. May be NULL. */
    void (*cleanup)(ag_app *app, const char *params_json);
} ag_job_kind;

/* A cleanup for kinds whose params name an uploaded file as "upload": removes that file. */
void ag_jobqueue_remove_upload(ag_app *app, const char *params_json);

ag_jobqueue *ag_jobqueue_create(ag_app *app, int workers, size_t capacity);
ag_status ag_jobqueue_register(ag_jobqueue *q, const ag_job_kind *kind);
/* Stops accepting, cancels queued and running jobs, joins the workers. */
void ag_jobqueue_stop(ag_jobqueue *q);
void ag_jobqueue_free(ag_jobqueue *q);

/* Stores the job (status queued) and queues it: AG_ERR_BUSY when the queue is full,
 * AG_ERR_CANCELLED when the queue is stopping. */
ag_status ag_jobqueue_submit(ag_app *app, const char *kind, const char *params_json,
                             int64_t *job, ag_error *err);
/* A queued job is cancelled at once, a running one at its next progress report; a finished
 * job is left as it is. AG_ERR_NOT_FOUND for an unknown id. */
ag_status ag_jobqueue_cancel(ag_app *app, int64_t job, ag_error *err);

/* Returns non-zero when the job should stop (cancelled or shutting down). Progress is
 * stored and published at most every 2% or on a stage change. */
int ag_jobctx_progress(ag_jobctx *ctx, double fraction, const char *stage);
int ag_jobctx_cancelled(const ag_jobctx *ctx);

/* Publishes the job's stored state as an AG_EVENT_JOB. */
void ag_jobqueue_publish(ag_app *app, int64_t job);

#endif
