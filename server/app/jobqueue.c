#include "jobqueue.h"

#include <jansson.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../store/jobs.h"
#include "views.h"

#define AG_JOBQUEUE_MAX_KINDS 16

struct ag_jobctx {
    ag_jobqueue *q;
    int64_t job;
    atomic_int cancel;
    double last_progress;
    char last_stage[32];
    struct ag_jobctx *next_running;
};

typedef struct queued {
    int64_t job;
    const ag_job_kind *kind;
    char *params;
    struct queued *next;
} queued;

struct ag_jobqueue {
    ag_app *app;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    queued *head, *tail;
    size_t length, capacity;
    int stopping;
    ag_jobctx *running; /* list of jobs on workers, for cancel */
    pthread_t *threads;
    int nthreads;
    ag_job_kind kinds[AG_JOBQUEUE_MAX_KINDS];
    int nkinds;
};

void ag_jobqueue_publish(ag_app *app, int64_t job)
{
    ag_db *db = ag_app_db(app, NULL);
    if (!db)
        return;
    ag_job_row row;
    if (ag_jobs_get(db, job, &row, NULL) != AG_OK)
        return;
    json_t *v = ag_view_job(&row);
    char *text = v ? json_dumps(v, JSON_COMPACT) : NULL;
    if (text) {
        ag_event ev = {.kind = AG_EVENT_JOB, .job = job, .model = row.model, .json = text};
        ag_events_publish(ag_app_events(app), &ev);
    }
    free(text);
    json_decref(v);
    ag_jobs_row_clear(&row);
}

static void finish_unsuccessful(ag_app *app, int64_t job, ag_status s, const ag_error *err)
{
    ag_db *db = ag_app_db(app, NULL);
    if (!db)
        return;
    char *problem = ag_view_problem_text(s, err);
    /* The run function may have left a transaction open on its way out. */
    ag_db_rollback(db);
    if (ag_db_begin(db, NULL) == AG_OK) {
        ag_jobs_finish(db, job, s == AG_ERR_CANCELLED ? "cancelled" : "failed", NULL, problem, 0,
                       NULL);
        ag_db_commit(db, NULL);
    }
    free(problem);
}

static void run_one(ag_jobqueue *q, queued *item)
{
    ag_jobctx ctx = {.q = q, .job = item->job, .last_progress = -1};
    pthread_mutex_lock(&q->lock);
    if (q->stopping)
        atomic_store(&ctx.cancel, 1);
    ctx.next_running = q->running;
    q->running = &ctx;
    pthread_mutex_unlock(&q->lock);

    ag_error err;
    ag_error_clear(&err);
    ag_status s;
    ag_db *db = ag_app_db(q->app, &err);
    if (!db) {
        s = err.code;
    } else if (ag_jobctx_progress(&ctx, 0, "start")) {
        s = ag_error_set(&err, AG_ERR_CANCELLED, 0, "the job was cancelled before it started");
    } else {
        /* On success the run function has recorded the outcome itself. */
        s = item->kind->run(q->app, &ctx, item->job, item->params, &err);
    }
    pthread_mutex_lock(&q->lock);
    int stopping = q->stopping;
    pthread_mutex_unlock(&q->lock);
    if (s == AG_ERR_CANCELLED && stopping)
        ag_error_set(&err, AG_ERR_CANCELLED, 0, "archgramd stopped before the job finished");
    if (s != AG_OK)
        finish_unsuccessful(q->app, item->job, s, &err);
    if (item->kind->cleanup)
        item->kind->cleanup(q->app, item->params);

    pthread_mutex_lock(&q->lock);
    for (ag_jobctx **p = &q->running; *p; p = &(*p)->next_running) {
        if (*p == &ctx) {
            *p = ctx.next_running;
            break;
        }
    }
    pthread_mutex_unlock(&q->lock);
    ag_jobqueue_publish(q->app, item->job);
}

static void *worker_main(void *arg)
{
    ag_jobqueue *q = arg;
    for (;;) {
        pthread_mutex_lock(&q->lock);
        while (!q->head && !q->stopping)
            pthread_cond_wait(&q->wake, &q->lock);
        if (!q->head) { /* stopping and nothing left */
            pthread_mutex_unlock(&q->lock);
            break;
        }
        queued *item = q->head;
        q->head = item->next;
        if (!q->head)
            q->tail = NULL;
        q->length--;
        pthread_mutex_unlock(&q->lock);
        run_one(q, item);
        free(item->params);
        free(item);
    }
    return NULL;
}

ag_jobqueue *ag_jobqueue_create(ag_app *app, int workers, size_t capacity)
{
    ag_jobqueue *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    q->app = app;
    q->capacity = capacity ? capacity : 256;
    pthread_mutex_init(&q->lock, NULL);
    pthread_cond_init(&q->wake, NULL);
    q->threads = calloc((size_t)(workers > 0 ? workers : 1), sizeof *q->threads);
    if (!q->threads) {
        ag_jobqueue_free(q);
        return NULL;
    }
    for (int i = 0; i < (workers > 0 ? workers : 1); i++) {
        if (pthread_create(&q->threads[i], NULL, worker_main, q) != 0)
            break;
        q->nthreads++;
    }
    if (q->nthreads == 0) {
        ag_jobqueue_free(q);
        return NULL;
    }
    return q;
}

ag_status ag_jobqueue_register(ag_jobqueue *q, const ag_job_kind *kind)
{
    if (q->nkinds >= AG_JOBQUEUE_MAX_KINDS)
        return AG_ERR_INTERNAL;
    q->kinds[q->nkinds++] = *kind;
    return AG_OK;
}

void ag_jobqueue_stop(ag_jobqueue *q)
{
    if (!q)
        return;
    pthread_mutex_lock(&q->lock);
    q->stopping = 1;
    /* Queued jobs never start: they are cancelled by the workers as they drain the queue
     * (run_one sees `stopping`), which keeps the store writes on worker connections. */
    for (ag_jobctx *c = q->running; c; c = c->next_running)
        atomic_store(&c->cancel, 1);
    pthread_cond_broadcast(&q->wake);
    pthread_mutex_unlock(&q->lock);
    for (int i = 0; i < q->nthreads; i++)
        pthread_join(q->threads[i], NULL);
    q->nthreads = 0;
}

void ag_jobqueue_free(ag_jobqueue *q)
{
    if (!q)
        return;
    ag_jobqueue_stop(q);
    while (q->head) {
        queued *next = q->head->next;
        free(q->head->params);
        free(q->head);
        q->head = next;
    }
    pthread_mutex_destroy(&q->lock);
    pthread_cond_destroy(&q->wake);
    free(q->threads);
    free(q);
}

ag_status ag_jobqueue_submit(ag_app *app, const char *kind, const char *params_json,
                             int64_t *job, ag_error *err)
{
    ag_jobqueue *q = ag__app_jobqueue(app);
    const ag_job_kind *k = NULL;
    for (int i = 0; i < q->nkinds; i++)
        if (strcmp(q->kinds[i].kind, kind) == 0)
            k = &q->kinds[i];
    if (!k)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no job kind %s", kind);
    queued *item = calloc(1, sizeof *item);
    if (!item || !(item->params = strdup(params_json ? params_json : "{}"))) {
        free(item);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory queueing a job");
    }
    item->kind = k;

    pthread_mutex_lock(&q->lock);
    ag_status s = AG_OK;
    if (q->stopping)
        s = ag_error_set(err, AG_ERR_CANCELLED, 0, "archgramd is shutting down");
    else if (q->length >= q->capacity)
        s = ag_error_set(err, AG_ERR_BUSY, 0,
                         "%zu jobs are waiting already; try again when some have finished",
                         q->length);
    if (s == AG_OK) {
        /* Stored and queued under the lock, so a worker cannot pick up a job whose row
         * does not exist yet and shutdown cannot miss it. */
        ag_db *db = ag_app_db(app, err);
        if (!db)
            s = err ? err->code : AG_ERR_DB;
        else if ((s = ag_db_begin(db, err)) == AG_OK) {
            s = ag_jobs_insert(db, kind, item->params, &item->job, err);
            s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
        }
    }
    if (s == AG_OK) {
        if (q->tail)
            q->tail->next = item;
        else
            q->head = item;
        q->tail = item;
        q->length++;
        *job = item->job;
        pthread_cond_signal(&q->wake);
    }
    pthread_mutex_unlock(&q->lock);
    if (s != AG_OK) {
        free(item->params);
        free(item);
    }
    return s;
}

ag_status ag_jobqueue_cancel(ag_app *app, int64_t job, ag_error *err)
{
    ag_jobqueue *q = ag__app_jobqueue(app);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_job_row row;
    ag_status s = ag_jobs_get(db, job, &row, err);
    if (s != AG_OK)
        return s;
    ag_jobs_row_clear(&row);

    queued *removed = NULL;
    pthread_mutex_lock(&q->lock);
    for (queued **p = &q->head; *p; p = &(*p)->next) {
        if ((*p)->job == job) {
            removed = *p;
            *p = removed->next;
            if (q->tail == removed) {
                q->tail = NULL;
                for (queued *t = q->head; t; t = t->next)
                    q->tail = t;
            }
            q->length--;
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
        finish_unsuccessful(app, job, AG_ERR_CANCELLED, &e);
        if (removed->kind->cleanup)
            removed->kind->cleanup(app, removed->params);
        free(removed->params);
        free(removed);
        ag_jobqueue_publish(app, job);
    }
    return AG_OK;
}

int ag_jobctx_cancelled(const ag_jobctx *ctx)
{
    return atomic_load(&((ag_jobctx *)ctx)->cancel) != 0;
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
    ag_db *db = ag_app_db(ctx->q->app, NULL);
    if (db && ag_db_begin(db, NULL) == AG_OK) {
        ag_jobs_update(db, ctx->job, "running", fraction, stage, NULL);
        ag_db_commit(db, NULL);
    }
    ag_jobqueue_publish(ctx->q->app, ctx->job);
    return ag_jobctx_cancelled(ctx);
}

void ag_jobqueue_remove_upload(ag_app *app, const char *params_json)
{
    (void)app;
    json_t *params = json_loads(params_json, 0, NULL);
    const char *upload = json_string_value(json_object_get(params, "upload"));
    if (upload)
        unlink(upload);
    json_decref(params);
}
