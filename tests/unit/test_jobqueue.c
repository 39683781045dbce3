/* The job queue: success recorded by the job, failures and cancellations by the queue,
 * a full queue refuses, and shutdown cancels what runs; a job past its time budget fails as
 * such; the task lanes run tasks while a long job holds every normal worker, refuse beyond
 * their capacity and drop what waits at a stop; one model's tasks run in order while another
 * model's run beside them; a task's budget runs out at its deadline and at a stop; a stop with
 * a grace period comes back in time even when a task ignores its budget;
 * typed params are stored as the one encoding and read back the same, and an upload they name
 * is removed after the job. The queue is built from its parts, without an app. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/dbpool.h"
#include "app/job_params.h"
#include "app/jobqueue.h"
#include "app/sequencer.h"
#include "store/jobs.h"

static char dir[64];
static char dbpath[128];

static atomic_int started;
static atomic_int stop_slow;

typedef struct {
    ag_dbpool *pool;
    ag_events *events;
    ag_sequencer *seq;
    ag_jobqueue *q;
} fixture;

/* Runs until cancelled (or told to stop), reporting progress. */
static ag_status run_until_cancelled(void *env, ag_jobctx *ctx, int64_t job,
                                     const ag_job_params *params, ag_error *err)
{
    (void)env, (void)job, (void)params;
    atomic_store(&started, 1);
    for (int i = 0; i < 4000 && !atomic_load(&stop_slow); i++) {
        if (ag_jobctx_progress(ctx, (i % 100) / 100.0, i % 2 ? "odd" : "even"))
            return ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled at step %d", i);
        usleep(1000);
    }
    return ag_error_set(err, AG_ERR_INTERNAL, 0, "never cancelled");
}

static ag_status run_and_succeed(void *env, ag_jobctx *ctx, int64_t job,
                                 const ag_job_params *params, ag_error *err)
{
    (void)ctx, (void)params;
    ag_db *db = ag_dbpool_get(env, err);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK)
        s = ag_jobs_finish(db, job, "succeeded", "{\"answer\":42}", NULL, 0, err);
    return s == AG_OK ? ag_db_commit(db, err) : s;
}

static ag_status run_and_fail(void *env, ag_jobctx *ctx, int64_t job, const ag_job_params *params,
                              ag_error *err)
{
    (void)env, (void)ctx, (void)job, (void)params;
    return ag_error_set(err, AG_ERR_PARSE, 7, "line 7: broken");
}

static const ag_job_kind slow = {.kind = "slow", .run = run_until_cancelled};
static const ag_job_kind good = {.kind = "good", .run = run_and_succeed};
static const ag_job_kind bad = {.kind = "bad", .run = run_and_fail};
/* an import that reads nothing: it only checks its params arrived typed */
static const ag_job_kind import_probe = {.kind = "import", .run = run_and_fail};

static fixture *make_queue_ex(int workers, size_t capacity, size_t task_capacity,
                             int task_workers, double job_seconds)
{
    snprintf(dir, sizeof dir, "/tmp/archgram-jobs-XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(dbpath, sizeof dbpath, "%s/t.db", dir);
    fixture *f = calloc(1, sizeof *f);
    ag_error err;
    assert_int_equal(ag_dbpool_create(dbpath, &f->pool, &err), AG_OK);
    f->events = ag_events_create();
    f->seq = ag_sequencer_create(f->events);
    ag_jobqueue_options o = {.db = f->pool, .seq = f->seq, .workers = workers,
                             .capacity = capacity, .task_capacity = task_capacity,
                             .task_workers = task_workers, .job_seconds = job_seconds};
    assert_non_null(f->q = ag_jobqueue_create(&o));
    ag_jobqueue_register(f->q, &slow, f->pool);
    ag_jobqueue_register(f->q, &good, f->pool);
    ag_jobqueue_register(f->q, &bad, f->pool);
    ag_jobqueue_register(f->q, &import_probe, f->pool);
    atomic_store(&stop_slow, 0);
    return f;
}

static fixture *make_queue(int workers, size_t capacity, size_t task_capacity)
{
    return make_queue_ex(workers, capacity, task_capacity, 1, 0);
}

static void drop_queue(fixture *f)
{
    ag_jobqueue_free(f->q);
    ag_sequencer_free(f->seq);
    ag_events_free(f->events);
    ag_dbpool_free(f->pool);
    free(f);
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void wait_status(fixture *f, int64_t job, const char *want, ag_job_row *row)
{
    ag_db *db = ag_dbpool_get(f->pool, NULL);
    for (int i = 0; i < 500; i++) {
        assert_int_equal(ag_jobs_get(db, job, row, NULL), AG_OK);
        if (strcmp(row->status, want) == 0)
            return;
        ag_jobs_row_clear(row);
        usleep(10000);
    }
    fail_msg("job %lld never became %s", (long long)job, want);
}

static void outcomes_are_recorded(void **state)
{
    (void)state;
    fixture *f = make_queue(2, 0, 0);
    int64_t ok_job, bad_job;
    ag_error err;
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &ok_job, &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(f->q, "bad", NULL, &bad_job, &err), AG_OK);
    ag_job_row row;
    wait_status(f, ok_job, "succeeded", &row);
    assert_string_equal(row.result_json, "{\"answer\":42}");
    assert_true(row.progress == 1.0);
    ag_jobs_row_clear(&row);
    wait_status(f, bad_job, "failed", &row);
    assert_non_null(strstr(row.error_json, "urn:archgram:problem:parse"));
    assert_non_null(strstr(row.error_json, "\"line\":7"));
    assert_null(row.result_json);
    ag_jobs_row_clear(&row);
    drop_queue(f);
}

static void running_and_queued_jobs_cancel(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 0, 0);
    int64_t running, queued;
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(f->q, "slow", NULL, &running, &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &queued, &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    /* The one worker is busy: the second job waits and is cancelled before it starts. */
    assert_int_equal(ag_jobqueue_cancel(f->q, queued, &err), AG_OK);
    ag_job_row row;
    wait_status(f, queued, "cancelled", &row);
    assert_non_null(strstr(row.error_json, "before it started"));
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_cancel(f->q, running, &err), AG_OK);
    wait_status(f, running, "cancelled", &row);
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_cancel(f->q, 9999, &err), AG_ERR_NOT_FOUND);
    drop_queue(f);
}

static void full_queue_refuses(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 2, 0);
    int64_t ids[3];
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(f->q, "slow", NULL, &ids[0], &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &ids[1], &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &ids[2], &err), AG_OK);
    int64_t extra = 0;
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &extra, &err), AG_ERR_BUSY);
    assert_int_equal(extra, 0);
    drop_queue(f);
}

static void shutdown_cancels_running_jobs(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 0, 0);
    int64_t job;
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(f->q, "slow", NULL, &job, &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    assert_int_equal(ag_jobqueue_stop(f->q, -1), 1);
    ag_job_row row;
    assert_int_equal(ag_jobs_get(ag_dbpool_get(f->pool, NULL), job, &row, NULL), AG_OK);
    assert_string_equal(row.status, "cancelled");
    assert_non_null(strstr(row.error_json, "stopped before the job finished"));
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_submit(f->q, "good", NULL, &job, &err), AG_ERR_CANCELLED);
    drop_queue(f);
}

static void a_job_past_its_budget_fails_as_such(void **state)
{
    (void)state;
    fixture *f = make_queue_ex(1, 0, 0, 1, 0.2);
    int64_t job;
    ag_error err;
    assert_int_equal(ag_jobqueue_submit(f->q, "slow", NULL, &job, &err), AG_OK);
    ag_job_row row;
    wait_status(f, job, "failed", &row); /* 4 s if left alone */
    assert_non_null(strstr(row.error_json, "urn:archgram:problem:deadline"));
    assert_non_null(strstr(row.error_json, "budget of 0.2 s"));
    ag_jobs_row_clear(&row);
    drop_queue(f);
}

/* --- the task lanes ------------------------------------------------------------------------ */

static atomic_int ran, dropped;
static atomic_int gate; /* a blocking task waits until it is set */

static void count_run(void *user, ag_task_budget *b)
{
    (void)user, (void)b;
    atomic_fetch_add(&ran, 1);
}

static void block_run(void *user, ag_task_budget *b)
{
    (void)user, (void)b;
    while (!atomic_load(&gate))
        usleep(1000);
    atomic_fetch_add(&ran, 1);
}

static void count_drop(void *user)
{
    (void)user;
    atomic_fetch_add(&dropped, 1);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void a_long_job_does_not_delay_the_task_lanes(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 0, 0);
    ag_error err;
    int64_t job;
    atomic_store(&started, 0);
    atomic_store(&ran, 0);
    assert_int_equal(ag_jobqueue_submit(f->q, "slow", NULL, &job, &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    /* the only normal worker runs the slow job (4 s if left alone); tasks still run */
    double t0 = now_s();
    for (int i = 0; i < 10; i++)
        assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, count_run, count_drop, NULL, &err), AG_OK);
    while (atomic_load(&ran) < 10 && now_s() - t0 < 2.0)
        usleep(1000);
    assert_int_equal(atomic_load(&ran), 10);
    ag_job_row row;
    assert_int_equal(ag_jobs_get(ag_dbpool_get(f->pool, NULL), job, &row, NULL), AG_OK);
    assert_string_equal(row.status, "running");
    ag_jobs_row_clear(&row);
    drop_queue(f);
}

static void the_task_lanes_are_bounded_and_drop_at_a_stop(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 0, 3);
    ag_error err;
    atomic_store(&ran, 0);
    atomic_store(&dropped, 0);
    atomic_store(&gate, 0);
    assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, block_run, count_drop, NULL, &err), AG_OK);
    /* the blocking task is taken by the worker; three more wait, the fourth is refused */
    double t0 = now_s();
    int queued = 0;
    while (queued < 3 && now_s() - t0 < 2.0)
        if (ag_jobqueue_run_task(f->q, 0, 0, count_run, count_drop, NULL, &err) == AG_OK)
            queued++;
    assert_int_equal(queued, 3);
    usleep(20000);
    assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, count_run, count_drop, NULL, &err), AG_ERR_BUSY);
    assert_int_equal(err.code, AG_ERR_BUSY);
    atomic_store(&gate, 1);
    assert_int_equal(ag_jobqueue_stop(f->q, -1), 1);
    /* the running task finished; the waiting ones either ran before the stop or were dropped */
    assert_int_equal(atomic_load(&ran) + atomic_load(&dropped), 4);
    assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, count_run, count_drop, NULL, &err),
                     AG_ERR_CANCELLED);
    drop_queue(f);
}

/* One model's tasks run one at a time in order; another model's run beside them. */
typedef struct {
    int id;
    atomic_int *open; /* the task waits until *open (NULL: does not wait) */
} ordered_task;

static atomic_int order_log[8], order_n, gate2;

static void ordered_run(void *user, ag_task_budget *b)
{
    (void)b;
    ordered_task *t = user;
    while (t->open && !atomic_load(t->open))
        usleep(1000);
    order_log[atomic_fetch_add(&order_n, 1)] = t->id;
}

static void wait_count(atomic_int *n, int want)
{
    double t0 = now_s();
    while (atomic_load(n) < want && now_s() - t0 < 5.0)
        usleep(1000);
    assert_true(atomic_load(n) >= want);
}

static void one_models_tasks_run_in_order_beside_another_models(void **state)
{
    (void)state;
    fixture *f = make_queue_ex(1, 0, 0, 3, 0);
    ag_error err;
    atomic_store(&order_n, 0);
    atomic_store(&gate, 0);
    atomic_store(&gate2, 0);
    ordered_task a = {1, &gate}, b = {2, NULL}, c = {3, NULL}, d = {4, &gate2}, e = {5, NULL};
    /* model 7: a (held), then b; model 8: c; model 9: d (held), then e */
    assert_int_equal(ag_jobqueue_run_task(f->q, 7, 0, ordered_run, NULL, &a, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 7, 0, ordered_run, NULL, &b, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 9, 0, ordered_run, NULL, &d, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 9, 0, ordered_run, NULL, &e, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 8, 0, ordered_run, NULL, &c, &err), AG_OK);
    /* models 7 and 9 hold two workers: model 8's task runs on the third meanwhile */
    wait_count(&order_n, 1);
    usleep(50000);
    assert_int_equal(atomic_load(&order_n), 1);
    assert_int_equal(order_log[0], 3);
    /* releasing model 9 runs d then e, while model 7 still waits on a */
    atomic_store(&gate2, 1);
    wait_count(&order_n, 3);
    usleep(20000);
    assert_int_equal(atomic_load(&order_n), 3);
    assert_int_equal(order_log[1], 4);
    assert_int_equal(order_log[2], 5);
    atomic_store(&gate, 1);
    wait_count(&order_n, 5);
    assert_int_equal(order_log[3], 1);
    assert_int_equal(order_log[4], 2);
    drop_queue(f);
}

/* Tasks without a key leave a worker for the models' tasks. */
static void unkeyed_tasks_leave_a_worker_for_models(void **state)
{
    (void)state;
    fixture *f = make_queue_ex(1, 0, 0, 2, 0);
    ag_error err;
    atomic_store(&order_n, 0);
    atomic_store(&gate, 0);
    ordered_task p1 = {1, &gate}, p2 = {2, &gate}, m = {3, NULL};
    assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, ordered_run, NULL, &p1, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 0, 0, ordered_run, NULL, &p2, &err), AG_OK);
    assert_int_equal(ag_jobqueue_run_task(f->q, 5, 0, ordered_run, NULL, &m, &err), AG_OK);
    wait_count(&order_n, 1);
    assert_int_equal(order_log[0], 3);
    atomic_store(&gate, 1);
    wait_count(&order_n, 3);
    drop_queue(f);
}

/* A task's budget: its deadline, and the queue's stop. */
static atomic_int why_seen;
static double budget_elapsed;

static void until_exhausted(void *user, ag_task_budget *b)
{
    (void)user;
    double t0 = now_s();
    while (!ag_task_budget_exhausted(b) && now_s() - t0 < 5.0)
        usleep(1000);
    budget_elapsed = now_s() - t0;
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_task_budget_explain(b, AG_ERR_CANCELLED, "the test task", &err);
    atomic_fetch_add(&ran, s == b->why && strstr(err.text, "the test task") ? 1 : 0);
    atomic_store(&why_seen, b->why); /* last: the test reads ran once it sees this */
}

static void a_task_budget_runs_out_at_its_deadline_and_at_a_stop(void **state)
{
    (void)state;
    fixture *f = make_queue_ex(1, 0, 0, 2, 0);
    ag_error err;
    atomic_store(&ran, 0);
    atomic_store(&why_seen, 0);
    assert_int_equal(ag_jobqueue_run_task(f->q, 3, 0.15, until_exhausted, NULL, NULL, &err), AG_OK);
    double t0 = now_s();
    while (!atomic_load(&why_seen) && now_s() - t0 < 5.0)
        usleep(1000);
    assert_int_equal(atomic_load(&why_seen), AG_ERR_DEADLINE);
    assert_true(budget_elapsed >= 0.14 && budget_elapsed < 1.0);
    assert_int_equal(atomic_load(&ran), 1);
    /* without a deadline, the stop ends it */
    atomic_store(&why_seen, 0);
    assert_int_equal(ag_jobqueue_run_task(f->q, 3, 0, until_exhausted, NULL, NULL, &err), AG_OK);
    usleep(50000);
    t0 = now_s();
    assert_int_equal(ag_jobqueue_stop(f->q, 2.0), 1);
    assert_true(now_s() - t0 < 0.5);
    assert_int_equal(atomic_load(&why_seen), AG_ERR_CANCELLED);
    assert_int_equal(atomic_load(&ran), 2);
    drop_queue(f);
}

/* A task that never looks at its budget cannot hold a stop past its grace period. */
static void a_stop_with_grace_comes_back_in_time(void **state)
{
    (void)state;
    fixture *f = make_queue_ex(1, 0, 0, 1, 0);
    ag_error err;
    atomic_store(&ran, 0);
    atomic_store(&gate, 0);
    assert_int_equal(ag_jobqueue_run_task(f->q, 4, 0, block_run, NULL, NULL, &err), AG_OK);
    usleep(30000);
    double t0 = now_s();
    assert_int_equal(ag_jobqueue_stop(f->q, 0.2), 0);
    double took = now_s() - t0;
    assert_true(took >= 0.19 && took < 0.6);
    atomic_store(&gate, 1);
    assert_int_equal(ag_jobqueue_stop(f->q, -1), 1); /* now everything has stopped */
    assert_int_equal(atomic_load(&ran), 1);
    drop_queue(f);
}

/* --- typed params -------------------------------------------------------------------------- */

static void typed_params_are_stored_once_and_uploads_removed(void **state)
{
    (void)state;
    fixture *f = make_queue(1, 0, 0);
    char upload[160];
    snprintf(upload, sizeof upload, "%s/upload-x", dir);
    FILE *u = fopen(upload, "w");
    assert_non_null(u);
    fputs("v 0 0 0\n", u);
    fclose(u);
    ag_job_params p = {.type = AG_JOB_IMPORT,
                       .u.import = {.upload = upload, .name = "Hall", .format = "obj", .up = "z"}};
    ag_error err;
    int64_t job;
    assert_int_equal(ag_jobqueue_submit(f->q, "import", &p, &job, &err), AG_OK);
    ag_job_row row;
    wait_status(f, job, "failed", &row); /* the probe fails, the params were stored */
    ag_job_params back;
    assert_int_equal(ag_job_params_decode(row.kind, row.params_json, &back, &err), AG_OK);
    assert_int_equal(back.type, AG_JOB_IMPORT);
    assert_string_equal(back.u.import.upload, upload);
    assert_string_equal(back.u.import.name, "Hall");
    assert_string_equal(back.u.import.format, "obj");
    assert_string_equal(back.u.import.up, "z");
    assert_null(back.u.import.filename);
    ag_job_params_clear(&back);
    ag_jobs_row_clear(&row);
    assert_int_equal(access(upload, F_OK), -1); /* removed whatever the outcome */

    /* every kind round-trips through its encoding */
    ag_job_params e = {.type = AG_JOB_EXTRUDE,
                       .u.extrude = {.upload = "/u", .name = "Street", .style = "gable",
                                     .height_property = "h", .seed = 7, .lonlat = -1}};
    char *text = ag_job_params_encode(&e);
    assert_non_null(text);
    assert_int_equal(ag_job_params_decode("extrude", text, &back, &err), AG_OK);
    assert_string_equal(back.u.extrude.style, "gable");
    assert_string_equal(back.u.extrude.height_property, "h");
    assert_null(back.u.extrude.format);
    assert_int_equal(back.u.extrude.seed, 7);
    assert_int_equal(back.u.extrude.lonlat, -1);
    ag_job_params_clear(&back);
    free(text);
    ag_job_params q = {.type = AG_JOB_PROCEDURALIZE,
                       .u.proceduralize = {.model = 3, .base = 5, .author = "ana"}};
    text = ag_job_params_encode(&q);
    assert_int_equal(ag_job_params_decode("proceduralize", text, &back, &err), AG_OK);
    assert_int_equal(back.u.proceduralize.model, 3);
    assert_int_equal(back.u.proceduralize.base, 5);
    assert_string_equal(back.u.proceduralize.author, "ana");
    ag_job_params_clear(&back);
    free(text);
    /* and what is incomplete is refused, naming the kind */
    assert_int_equal(ag_job_params_decode("proceduralize", "{\"model\":3}", &back, &err),
                     AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "proceduralize"));
    assert_int_equal(ag_job_params_decode("import", "[1]", &back, &err), AG_ERR_INVALID);
    drop_queue(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(outcomes_are_recorded),
        cmocka_unit_test(running_and_queued_jobs_cancel),
        cmocka_unit_test(full_queue_refuses),
        cmocka_unit_test(shutdown_cancels_running_jobs),
        cmocka_unit_test(a_job_past_its_budget_fails_as_such),
        cmocka_unit_test(a_long_job_does_not_delay_the_task_lanes),
        cmocka_unit_test(the_task_lanes_are_bounded_and_drop_at_a_stop),
        cmocka_unit_test(one_models_tasks_run_in_order_beside_another_models),
        cmocka_unit_test(unkeyed_tasks_leave_a_worker_for_models),
        cmocka_unit_test(a_task_budget_runs_out_at_its_deadline_and_at_a_stop),
        cmocka_unit_test(a_stop_with_grace_comes_back_in_time),
        cmocka_unit_test(typed_params_are_stored_once_and_uploads_removed),
    };
    return cmocka_run_group_tests_name("jobqueue", tests, NULL, NULL);
}
