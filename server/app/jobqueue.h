/* The job queue: bounded lanes of work and their worker threads.
 *
 *   normal lane   stored jobs (imports, proceduralizations, extrusions): a row in the jobs
 *                 table plus an entry here. A kind's run function does the work on a worker,
 *                 reports progress through its ag_jobctx and honours cancellation; on success
 *                 it records the outcome itself (ag_jobs_finish(..., "succeeded", ...)) inside
 *                 the transaction that makes its result visible, after a last
 *                 ag_jobctx_cancelled() check, so a job never succeeds half-way. Failures and
 *                 cancellations are recorded by the queue; an uploaded file the params name
 *                 is removed whatever the outcome.
 *   fast lane     short interactive work that is not stored (live drag previews, structural
 *                 ops sent over websockets): tasks run in arrival order on threads of their
 *                 own, so a long job never delays a preview.
 *
 * Stopping refuses new work, cancels running jobs (at their next progress report), cancels
 * queued jobs (recorded as such by the workers, on their own connections) and drops queued
 * tasks; a running task finishes. */
#ifndef AG_JOBQUEUE_H
#define AG_JOBQUEUE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "dbpool.h"
#include "job_params.h"
#include "sequencer.h"

typedef struct ag_jobctx ag_jobctx;
typedef struct ag_jobqueue ag_jobqueue;

typedef struct {
    const char *kind;
    /* env: what the kind was registered with */
    ag_status (*run)(void *env, ag_jobctx *ctx, int64_t job, const ag_job_params *p,
                     ag_error *err);
} ag_job_kind;

typedef struct {
    ag_dbpool *db;          /* the workers' connections */
    ag_sequencer *seq;      /* job states are announced through it (AG_EVENT_JOB) */
    int workers;            /* normal lane threads, at least 1 */
    size_t capacity;        /* queued jobs; 0 = 256 */
    int fast_workers;       /* fast lane threads; 0 = 1 */
    size_t fast_capacity;   /* waiting tasks; 0 = 256 */
} ag_jobqueue_options;

ag_jobqueue *ag_jobqueue_create(const ag_jobqueue_options *opt);
ag_status ag_jobqueue_register(ag_jobqueue *q, const ag_job_kind *kind, void *env);
void ag_jobqueue_stop(ag_jobqueue *q);
void ag_jobqueue_free(ag_jobqueue *q);

/* Stores the job (status queued, params as ag_job_params_encode writes them; p may be NULL
 * for none) and queues it: AG_ERR_BUSY when the lane is full, AG_ERR_CANCELLED when the queue
 * is stopping. */
ag_status ag_jobqueue_submit(ag_jobqueue *q, const char *kind, const ag_job_params *p,
                             int64_t *job, ag_error *err);
/* A queued job is cancelled at once, a running one at its next progress report; a finished
 * job is left as it is. AG_ERR_NOT_FOUND for an unknown id. */
ag_status ag_jobqueue_cancel(ag_jobqueue *q, int64_t job, ag_error *err);

/* Queues a task on the fast lane: run(user) on a fast worker, or drop(user) if the queue
 * stops first (drop may be NULL). AG_ERR_BUSY when the lane is full, AG_ERR_CANCELLED when
 * the queue is stopping; then neither is called. */
ag_status ag_jobqueue_run_fast(ag_jobqueue *q, void (*run)(void *user), void (*drop)(void *user),
                               void *user, ag_error *err);

/* Returns non-zero when the job should stop (cancelled or shutting down). Progress is
 * stored and announced at most every 2% or on a stage change. */
int ag_jobctx_progress(ag_jobctx *ctx, double fraction, const char *stage);
int ag_jobctx_cancelled(const ag_jobctx *ctx);

/* Announces the job's stored state as an AG_EVENT_JOB. */
void ag_jobqueue_publish(ag_jobqueue *q, int64_t job);

#endif
