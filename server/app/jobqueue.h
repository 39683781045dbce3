/* The job queue: bounded lanes of work and their worker threads.
 *
 *   normal lane   stored jobs (imports, proceduralizations, extrusions): a row in the jobs
 *                 table plus an entry here. A kind's run function does the work on a worker,
 *                 reports progress through its ag_jobctx and honours cancellation; on success
 *                 it records the outcome itself (ag_jobs_finish(..., "succeeded", ...)) inside
 *                 the transaction that makes its result visible, after a last
 *                 ag_jobctx_cancelled() check, so a job never succeeds half-way. Failures and
 *                 cancellations are recorded by the queue; an uploaded file the params name
 *                 is removed whatever the outcome. Every job has a time budget
 *                 (job_seconds): past it ag_jobctx_cancelled() says stop and the job fails
 *                 with AG_ERR_DEADLINE.
 *   task lanes    interactive work that is not a stored job (structural ops, grammar edits,
 *                 drag previews, extrusion previews), each under an ag_task_budget: one lane
 *                 per key (a model id), so the tasks of one model run one at a time in
 *                 arrival order while other models' tasks run beside them on the other task
 *                 workers; a long job never delays them. Tasks without a key (0) run in any
 *                 order and leave one task worker free for the keyed ones.
 *
 * Stopping refuses new work, cancels running jobs (at their next progress report) and
 * running tasks (their budgets' stop flag), cancels queued jobs (recorded as such by the
 * workers, on their own connections) and drops queued tasks (their drop function answers for
 * them). */
#ifndef AG_JOBQUEUE_H
#define AG_JOBQUEUE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/status.h"
#include "dbpool.h"
#include "task_budget.h"
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
    double job_seconds;     /* time budget of one job; 0 = none */
    int task_workers;       /* task lane threads; 0 = 1 */
    size_t task_capacity;   /* waiting tasks; 0 = 256 */
} ag_jobqueue_options;

ag_jobqueue *ag_jobqueue_create(const ag_jobqueue_options *opt);
ag_status ag_jobqueue_register(ag_jobqueue *q, const ag_job_kind *kind, void *env);
/* Stops (see above) and waits at most grace seconds (< 0: as long as it takes) for the work
 * under way to notice. Returns 1 when every worker has stopped; 0 when some are still
 * running (a job inside a stage that cannot be interrupted): then the queue must not be freed
 * and the process should end without waiting for them (the store stays consistent: every
 * write is one transaction). */
int ag_jobqueue_stop(ag_jobqueue *q, double grace);
/* The jobs still running after a stop that did not finish: each id into ids (at most n);
 * returns how many there are. */
size_t ag_jobqueue_running(ag_jobqueue *q, int64_t *ids, size_t n);
void ag_jobqueue_free(ag_jobqueue *q);

/* Stores the job (status queued, params as ag_job_params_encode writes them; p may be NULL
 * for none) and queues it: AG_ERR_BUSY when the lane is full, AG_ERR_CANCELLED when the queue
 * is stopping. */
ag_status ag_jobqueue_submit(ag_jobqueue *q, const char *kind, const ag_job_params *p,
                             int64_t *job, ag_error *err);
/* A queued job is cancelled at once, a running one at its next progress report; a finished
 * job is left as it is. AG_ERR_NOT_FOUND for an unknown id. */
ag_status ag_jobqueue_cancel(ag_jobqueue *q, int64_t job, ag_error *err);

/* Queues a task on the lane of key (0: none): run(user, budget) on a task worker, under a
 * budget of `seconds` (0: none) whose stop flag the queue raises when it stops, or drop(user)
 * if the queue stops first (drop may be NULL). AG_ERR_BUSY when too many tasks wait,
 * AG_ERR_CANCELLED when the queue is stopping; then neither is called. */
ag_status ag_jobqueue_run_task(ag_jobqueue *q, int64_t key, double seconds,
                               void (*run)(void *user, ag_task_budget *budget),
                               void (*drop)(void *user), void *user, ag_error *err);

/* What the queue holds now (for GET /api/v1/health). */
typedef struct {
    size_t jobs_waiting, jobs_running, tasks_waiting, tasks_running;
} ag_jobqueue_stats;
ag_jobqueue_stats ag_jobqueue_stats_now(ag_jobqueue *q);

/* Returns non-zero when the job should stop (cancelled or shutting down). Progress is
 * stored and announced at most every 2% or on a stage change. */
int ag_jobctx_progress(ag_jobctx *ctx, double fraction, const char *stage);
/* Non-zero once the job is cancelled, the queue stops or the job's time budget is spent. */
int ag_jobctx_cancelled(const ag_jobctx *ctx);
/* ag_jobctx_cancelled as the callback core budgets take (user is the ag_jobctx). */
int ag_jobctx_poll(void *ctx);

/* Announces the job's stored state as an AG_EVENT_JOB. */
void ag_jobqueue_publish(ag_jobqueue *q, int64_t job);

#endif
