#include "jobqueue.h"

#include <jansson.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "../store/jobs.h"
#include "problem.h"
#include "views.h"

#define AG_JOBQUEUE_MAX_KINDS 16

typedef struct {
    ag_job_kind kind;
    void *env;
} kind_entry;

struct ag_jobctx {
    ag_jobqueue *q;
    int64_t job;
    atomic_int cancel;
    double deadline;      /* monotonic seconds, 0 = none */
    atomic_int timed_out; /* the deadline passed while it ran */
    double last_progress;
    char last_stage[32];
    struct ag_jobctx *next_running;
};

typedef struct queued {
    struct queued *next;
    /* a stored job */
    int64_t job;
    const kind_entry *kind;
    ag_job_params params;
    /* or a task */
    int64_t key;
    double seconds;
    void (*run)(void *user, ag_task_budget *budget);
    void (*drop)(void *user);
    void *user;
} queued;

typedef struct {
    pthread_cond_t wake;
    queued *head, *tail;
    size_t length, capacity;
    pthread_t *threads;
    int nthreads;
    atomic_int *finished; /* per thread: its main returned (for a bounded stop) */
} lane;

/* What a task worker is running: its key, while busy. */
typedef struct {
    int busy;
    int64_t key;
} task_slot;

struct ag_jobqueue {
    ag_dbpool *db;
    ag_sequencer *seq;
    pthread_mutex_t lock;
    lane normal, tasks;
    int stopping;
    atomic_int stop_tasks; /* the running tasks' budgets stop */
    double job_seconds;
    ag_jobctx *running; /* jobs on workers, for cancel */
    task_slot *slots;   /* per task worker */
    int unkeyed_running, unkeyed_max;
    int abandoned;      /* a stop left workers running: never free */
    kind_entry kinds[AG_JOBQUEUE_MAX_KINDS];
    int nkinds;
};

static double mono_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void ag_jobqueue_publish(ag_jobqueue *q, int64_t job)
{
    ag_db *db = ag_dbpool_get(q->db, NULL);
    if (!db)
        return;
    ag_job_row row;
    if (ag_jobs_get(db, job, &row, NULL) != AG_OK)
        return;
    json_t *v = ag_view_job(&row);
    char *text = v ? json_dumps(v, JSON_COMPACT) : NULL;
    if (text) {
        ag_event ev = {.kind = AG_EVENT_JOB, .job = job, .model = row.model, .json = text};
        ag_sequencer_publish(q->seq, &ev);
    }
    free(text);
    json_decref(v);
    ag_jobs_row_clear(&row);
}

static void finish_unsuccessful(ag_jobqueue *q, int64_t job, ag_status s, const ag_error *err)
{
    ag_db *db = ag_dbpool_get(q->db, NULL);
    if (!db)
        return;
    char *problem = ag_problem_text(s, err);
    /* The run function may have left a transaction open on its way out. */
    ag_db_rollback(db);
    if (ag_db_begin(db, NULL) == AG_OK) {
        ag_jobs_finish(db, job, s == AG_ERR_CANCELLED ? "cancelled" : "failed", NULL, problem, 0,
                       NULL);
        ag_db_commit(db, NULL);
    }
    free(problem);
}

/* What a job leaves behind goes whatever its outcome: the upload it read. */
static void cleanup(queued *item)
{
    const char *upload = ag_job_params_upload(&item->params);
    if (upload)
        unlink(upload);
    ag_job_params_clear(&item->params);
}

static void run_job(ag_jobqueue *q, queued *item)
{
    ag_jobctx ctx = {.q = q,
                     .job = item->job,
                     .last_progress = -1,
                     .deadline = q->job_seconds > 0 ? mono_now() + q->job_seconds : 0};
    pthread_mutex_lock(&q->lock);
    if (q->stopping)
        atomic_store(&ctx.cancel, 1);
    ctx.next_running = q->running;
    q->running = &ctx;
    pthread_mutex_unlock(&q->lock);

    ag_error err;
    ag_error_clear(&err);
    ag_status s;
    ag_db *db = ag_dbpool_get(q->db, &err);
    if (!db) {
        s = err.code;
    } else if (ag_jobctx_progress(&ctx, 0, "start")) {
        s = ag_error_set(&err, AG_ERR_CANCELLED, 0, "the job was cancelled before it started");
    } else {
        /* On success the run function has recorded the outcome itself. */
        s = item->kind->kind.run(item->kind->env, &ctx, item->job, &item->params, &err);
    }
    pthread_mutex_lock(&q->lock);
    int stopping = q->stopping;
    pthread_mutex_unlock(&q->lock);
    if (s == AG_ERR_CANCELLED && stopping)
        ag_error_set(&err, AG_ERR_CANCELLED, 0, "archgramd stopped before the job finished");
    else if (s == AG_ERR_CANCELLED && atomic_load(&ctx.timed_out) && !atomic_load(&ctx.cancel))
        s = ag_error_set(&err, AG_ERR_DEADLINE, 0,
                         "the job ran longer than its budget of %g s (archgramd --job-seconds) "
                         "and was stopped; nothing was stored",
                         q->job_seconds);
    if (s != AG_OK)
        finish_unsuccessful(q, item->job, s, &err);
    cleanup(item);

    pthread_mutex_lock(&q->lock);
    for (ag_jobctx **p = &q->running; *p; p = &(*p)->next_running) {
        if (*p == &ctx) {
            *p = ctx.next_running;
            break;
        }
    }
    pthread_mutex_unlock(&q->lock);
    ag_jobqueue_publish(q, item->job);
}

static queued *pop(lane *l)
{
    queued *item = l->head;
    if (item) {
        l->head = item->next;
        if (!l->head)
            l->tail = NULL;
        l->length--;
    }
    return item;
}

typedef struct {
    ag_jobqueue *q;
    int index;
} worker_arg;

/* Workers run below the threads that answer requests: a busy machine still answers
 * GET /api/v1/health and small requests at once (jobs lowest, interactive tasks between). */
static void lower_priority(int steps)
{
    setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), steps);
}

static void *normal_main(void *arg)
{
    worker_arg *w = arg;
    ag_jobqueue *q = w->q;
    lower_priority(10);
    for (;;) {
        pthread_mutex_lock(&q->lock);
        while (!q->normal.head && !q->stopping)
            pthread_cond_wait(&q->normal.wake, &q->lock);
        queued *item = pop(&q->normal); /* stopping: drained, each cancelled by run_job */
        pthread_mutex_unlock(&q->lock);
        if (!item)
            break;
        run_job(q, item);
        free(item);
    }
    atomic_store(&q->normal.finished[w->index], 1);
    free(w);
    return NULL;
}

static int key_running(const ag_jobqueue *q, int64_t key)
{
    for (int i = 0; i < q->tasks.nthreads; i++)
        if (q->slots[i].busy && q->slots[i].key == key)
            return 1;
    return 0;
}

/* The oldest waiting task that may start: unkeyed ones while a keyed one would still find a
 * worker, keyed ones when no task of their key runs. Under the lock. */
static queued *take_task(ag_jobqueue *q)
{
    lane *l = &q->tasks;
    queued *prev = NULL;
    for (queued *t = l->head; t; prev = t, t = t->next) {
        if (t->key ? key_running(q, t->key) : q->unkeyed_running >= q->unkeyed_max)
            continue;
        if (prev)
            prev->next = t->next;
        else
            l->head = t->next;
        if (l->tail == t)
            l->tail = prev;
        l->length--;
        t->next = NULL;
        return t;
    }
    return NULL;
}

static void *task_main(void *arg)
{
    worker_arg *w = arg;
    ag_jobqueue *q = w->q;
    lower_priority(5);
    task_slot *slot = &q->slots[w->index];
    for (;;) {
        pthread_mutex_lock(&q->lock);
        queued *item = NULL;
        while (!q->stopping && !(item = take_task(q)))
            pthread_cond_wait(&q->tasks.wake, &q->lock);
        if (item) {
            slot->busy = 1;
            slot->key = item->key;
            q->unkeyed_running += !item->key;
        }
        pthread_mutex_unlock(&q->lock);
        if (!item)
            break;
        ag_task_budget budget;
        ag_task_budget_start(&budget, item->seconds, &q->stop_tasks);
        item->run(item->user, &budget);
        pthread_mutex_lock(&q->lock);
        slot->busy = 0;
        q->unkeyed_running -= !item->key;
        /* a task of this key (or an unkeyed one) may start now on any worker */
        pthread_cond_broadcast(&q->tasks.wake);
        pthread_mutex_unlock(&q->lock);
        free(item);
    }
    atomic_store(&q->tasks.finished[w->index], 1);
    free(w);
    return NULL;
}

static int start_lane(ag_jobqueue *q, lane *l, int n, size_t capacity, void *(*fn)(void *))
{
    pthread_cond_init(&l->wake, NULL);
    l->capacity = capacity ? capacity : 256;
    l->threads = calloc((size_t)n, sizeof *l->threads);
    l->finished = calloc((size_t)n, sizeof *l->finished);
    if (!l->threads || !l->finished)
        return -1;
    for (int i = 0; i < n; i++) {
        worker_arg *w = malloc(sizeof *w);
        if (!w)
            break;
        w->q = q;
        w->index = i;
        if (pthread_create(&l->threads[i], NULL, fn, w) != 0) {
            free(w);
            break;
        }
        l->nthreads++;
    }
    return l->nthreads ? 0 : -1;
}

ag_jobqueue *ag_jobqueue_create(const ag_jobqueue_options *opt)
{
    ag_jobqueue *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    q->db = opt->db;
    q->seq = opt->seq;
    q->job_seconds = opt->job_seconds;
    pthread_mutex_init(&q->lock, NULL);
    int ntasks = opt->task_workers > 0 ? opt->task_workers : 1;
    q->unkeyed_max = ntasks > 1 ? ntasks - 1 : 1;
    /* the slots exist before the workers that use them start */
    int fail = !(q->slots = calloc((size_t)ntasks, sizeof *q->slots));
    fail = fail || start_lane(q, &q->normal, opt->workers > 0 ? opt->workers : 1, opt->capacity,
                              normal_main);
    fail = fail || start_lane(q, &q->tasks, ntasks, opt->task_capacity, task_main);
    if (fail) {
        ag_jobqueue_free(q);
        return NULL;
    }
    return q;
}

ag_status ag_jobqueue_register(ag_jobqueue *q, const ag_job_kind *kind, void *env)
{
    if (q->nkinds >= AG_JOBQUEUE_MAX_KINDS)
        return AG_ERR_INTERNAL;
    q->kinds[q->nkinds].kind = *kind;
    q->kinds[q->nkinds].env = env;
    q->nkinds++;
    return AG_OK;
}

/* Joins the lane's workers that finish before `until` (monotonic seconds; 0: waits for
 * all). Returns 1 when every one was joined. */
static int join_lane(lane *l, double until)
{
    int all = 1;
    for (int i = 0; i < l->nthreads; i++) {
        if (!l->threads[i])
            continue;
        while (until && !atomic_load(&l->finished[i]) && mono_now() < until) {
            struct timespec nap = {0, 2 * 1000 * 1000};
            nanosleep(&nap, NULL);
        }
        if (until && !atomic_load(&l->finished[i])) {
            all = 0;
            continue;
        }
        pthread_join(l->threads[i], NULL);
        l->threads[i] = 0;
    }
    return all;
}

int ag_jobqueue_stop(ag_jobqueue *q, double grace)
{
    if (!q)
        return 1;
    pthread_mutex_lock(&q->lock);
    q->stopping = 1;
    atomic_store(&q->stop_tasks, 1);
    for (ag_jobctx *c = q->running; c; c = c->next_running)
        atomic_store(&c->cancel, 1);
    pthread_cond_broadcast(&q->normal.wake);
    pthread_cond_broadcast(&q->tasks.wake);
    /* tasks that never ran: answered by their drop now, not after the running ones */
    queued *dropped = q->tasks.head;
    q->tasks.head = q->tasks.tail = NULL;
    q->tasks.length = 0;
    pthread_mutex_unlock(&q->lock);
    for (queued *t = dropped, *next; t; t = next) {
        next = t->next;
        if (t->drop)
            t->drop(t->user);
        free(t);
    }
    double until = grace >= 0 ? mono_now() + grace : 0;
    int all = join_lane(&q->tasks, until);
    all &= join_lane(&q->normal, until);
    q->abandoned = !all; /* a later stop that joins them all may free it again */
    return all;
}

size_t ag_jobqueue_running(ag_jobqueue *q, int64_t *ids, size_t n)
{
    size_t count = 0;
    pthread_mutex_lock(&q->lock);
    for (ag_jobctx *c = q->running; c; c = c->next_running, count++)
        if (count < n)
            ids[count] = c->job;
    pthread_mutex_unlock(&q->lock);
    return count;
}

void ag_jobqueue_free(ag_jobqueue *q)
{
    if (!q)
        return;
    if (!ag_jobqueue_stop(q, -1) || q->abandoned)
        return; /* workers still use it */
    for (queued *item; (item = pop(&q->normal));) {
        cleanup(item);
        free(item);
    }
    pthread_cond_destroy(&q->normal.wake);
    pthread_cond_destroy(&q->tasks.wake);
    pthread_mutex_destroy(&q->lock);
    free(q->normal.threads);
    free(q->tasks.threads);
    free(q->normal.finished);
    free(q->tasks.finished);
    free(q->slots);
    free(q);
}

static void append(lane *l, queued *item)
{
    if (l->tail)
        l->tail->next = item;
    else
        l->head = item;
    l->tail = item;
    l->length++;
    pthread_cond_signal(&l->wake);
}

ag_status ag_jobqueue_submit(ag_jobqueue *q, const char *kind, const ag_job_params *p,
                             int64_t *job, ag_error *err)
{
    const kind_entry *k = NULL;
    for (int i = 0; i < q->nkinds; i++)
        if (strcmp(q->kinds[i].kind.kind, kind) == 0)
            k = &q->kinds[i];
    if (!k)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no job kind %s", kind);
    queued *item = calloc(1, sizeof *item);
    char *text = NULL;
    ag_status s = item ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory queueing a job");
    if (s == AG_OK && p)
        s = ag_job_params_copy(&item->params, p, err);
    else if (s == AG_OK)
        item->params.type = AG_JOB_TEST;
    if (s == AG_OK && !(text = ag_job_params_encode(&item->params)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory queueing a job");
    if (s != AG_OK) {
        if (item)
            ag_job_params_clear(&item->params);
        free(item);
        return s;
    }
    item->kind = k;

    pthread_mutex_lock(&q->lock);
    if (q->stopping)
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "archgramd is shutting down");
    else if (q->normal.length >= q->normal.capacity)
        s = ag_error_set(err, AG_ERR_BUSY, 0,
                         "%zu jobs are waiting already; try again when some have finished",
                         q->normal.length);
    if (s == AG_OK) {
        /* Stored and queued under the lock, so a worker cannot pick up a job whose row
         * does not exist yet and shutdown cannot miss it. */
        ag_db *db = ag_dbpool_get(q->db, err);
        if (!db)
            s = err ? err->code : AG_ERR_DB;
        else if ((s = ag_db_begin(db, err)) == AG_OK) {
            s = ag_jobs_insert(db, kind, text, item->params.user, &item->job, err);
            s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
        }
    }
    if (s == AG_OK) {
        *job = item->job;
        append(&q->normal, item);
    }
    pthread_mutex_unlock(&q->lock);
    free(text);
    if (s != AG_OK) {
        ag_job_params_clear(&item->params);
        free(item);
    }
    return s;
}

ag_status ag_jobqueue_run_task(ag_jobqueue *q, int64_t key, double seconds,
                               void (*run)(void *user, ag_task_budget *budget),
                               void (*drop)(void *user), void *user, ag_error *err)
{
    queued *item = calloc(1, sizeof *item);
    if (!item)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    item->key = key;
    item->seconds = seconds;
    item->run = run;
    item->drop = drop;
    item->user = user;
    ag_status s = AG_OK;
    pthread_mutex_lock(&q->lock);
    if (q->stopping)
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "archgramd is shutting down");
    else if (q->tasks.length >= q->tasks.capacity)
        s = ag_error_set(err, AG_ERR_BUSY, 0, "%zu tasks are waiting already; send it again later",
                         q->tasks.length);
    else
        append(&q->tasks, item);
    pthread_mutex_unlock(&q->lock);
    if (s != AG_OK)
        free(item);
    return s;
}

ag_status ag_jobqueue_cancel(ag_jobqueue *q, int64_t job, ag_error *err)
{
    ag_db *db = ag_dbpool_get(q->db, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_job_row row;
    ag_status s = ag_jobs_get(db, job, &row, err);
    if (s != AG_OK)
        return s;
    ag_jobs_row_clear(&row);

    queued *removed = NULL;
    pthread_mutex_lock(&q->lock);
    lane *l = &q->normal;
    for (queued **p = &l->head; *p; p = &(*p)->next) {
        if ((*p)->job == job) {
            removed = *p;
            *p = removed->next;
            if (l->tail == removed) {
                l->tail = NULL;
                for (queued *t = l->head; t; t = t->next)
                    l->tail = t;
            }
            l->length--;
            break;
        }
    }
    for (ag_jobctx *c = q->running; c; c = c->next_running)
        if (c->job == job)
            atomic_store(&c->cancel, 1);
    pthread_mutex_unlock(&q->lock);

    if (removed) {
        ag_error e;
        ag_error_set(&e, AG_ERR_CANCELLED, 0, "the job was cancelled before it started");
        finish_unsuccessful(q, job, AG_ERR_CANCELLED, &e);
        cleanup(removed);
        free(removed);
        ag_jobqueue_publish(q, job);
    }
    return AG_OK;
}

ag_jobqueue_stats ag_jobqueue_stats_now(ag_jobqueue *q)
{
    ag_jobqueue_stats st = {0};
    pthread_mutex_lock(&q->lock);
    st.jobs_waiting = q->normal.length;
    for (ag_jobctx *c = q->running; c; c = c->next_running)
        st.jobs_running++;
    st.tasks_waiting = q->tasks.length;
    for (int i = 0; i < q->tasks.nthreads; i++)
        st.tasks_running += q->slots[i].busy != 0;
    pthread_mutex_unlock(&q->lock);
    return st;
}

int ag_jobctx_cancelled(const ag_jobctx *ctx)
{
    ag_jobctx *c = (ag_jobctx *)ctx;
    if (atomic_load(&c->cancel))
        return 1;
    if (c->deadline && mono_now() > c->deadline) {
        atomic_store(&c->timed_out, 1);
        return 1;
    }
    return 0;
}

int ag_jobctx_poll(void *ctx)
{
    return ag_jobctx_cancelled(ctx);
}

int ag_jobctx_progress(ag_jobctx *ctx, double fraction, const char *stage)
{
    if (ag_jobctx_cancelled(ctx))
        return 1;
    int stage_changed = stage && strncmp(stage, ctx->last_stage, sizeof ctx->last_stage) != 0;
    if (!stage_changed && fraction - ctx->last_progress < 0.02)
        return 0;
    ctx->last_progress = fraction;
    if (stage) {
        strncpy(ctx->last_stage, stage, sizeof ctx->last_stage - 1);
        ctx->last_stage[sizeof ctx->last_stage - 1] = '\0';
    }
    ag_db *db = ag_dbpool_get(ctx->q->db, NULL);
    if (db && ag_db_begin(db, NULL) == AG_OK) {
        ag_jobs_update(db, ctx->job, "running", fraction, stage, NULL);
        ag_db_commit(db, NULL);
    }
    ag_jobqueue_publish(ctx->q, ctx->job);
    return ag_jobctx_cancelled(ctx);
}
