/* The job queue: success recorded by the job, failures and cancellations by the queue,
 * a full queue refuses, and shutdown cancels what runs. */
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

#include "app/app.h"
#include "app/jobqueue.h"
#include "store/jobs.h"

static char dir[64];
static char dbpath[128];

static atomic_int started;

/* Runs until cancelled, reporting progress. */
static ag_status run_until_cancelled(ag_app *app, ag_jobctx *ctx, int64_t job,
                                     const char *params, ag_error *err)
{
    (void)app, (void)job, (void)params;
    atomic_store(&started, 1);
    for (int i = 0; i < 4000; i++) {
        if (ag_jobctx_progress(ctx, (i % 100) / 100.0, i % 2 ? "odd" : "even"))
            return ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled at step %d", i);
        usleep(1000);
    }
    return ag_error_set(err, AG_ERR_INTERNAL, 0, "never cancelled");
}

static ag_status run_and_succeed(ag_app *app, ag_jobctx *ctx, int64_t job, const char *params,
                                 ag_error *err)
{
    (void)ctx, (void)params;
    ag_db *db = ag_app_db(app, err);
    ag_status s = ag_db_begin(db, err);
    if (s == AG_OK)
        s = ag_jobs_finish(db, job, "succeeded", "{\"answer\":42}", NULL, 0, err);
    return s == AG_OK ? ag_db_commit(db, err) : s;
}

static ag_status run_and_fail(ag_app *app, ag_jobctx *ctx, int64_t job, const char *params,
                              ag_error *err)
{
    (void)app, (void)ctx, (void)job, (void)params;
    return ag_error_set(err, AG_ERR_PARSE, 7, "line 7: broken");
}

static const ag_job_kind slow = {.kind = "slow", .run = run_until_cancelled};
static const ag_job_kind good = {.kind = "good", .run = run_and_succeed};
static const ag_job_kind bad = {.kind = "bad", .run = run_and_fail};

static ag_app *make_app(int workers, size_t capacity)
{
    snprintf(dir, sizeof dir, "/tmp/archgram-jobs-XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(dbpath, sizeof dbpath, "%s/t.db", dir);
    ag_app *app = NULL;
    ag_error err;
    ag_app_options opt = {.db_path = dbpath, .workers = workers, .queue_capacity = capacity};
    assert_int_equal(ag_app_create(&opt, &app, &err), AG_OK);
    ag_jobqueue *q = (ag_jobqueue *)ag__app_jobqueue(app);
    ag_jobqueue_register(q, &slow);
    ag_jobqueue_register(q, &good);
    ag_jobqueue_register(q, &bad);
    return app;
}

static void drop_app(ag_app *app)
{
    ag_app_shutdown(app);
    ag_app_free(app);
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void wait_status(ag_app *app, int64_t job, const char *want, ag_job_row *row)
{
    ag_db *db = ag_app_db(app, NULL);
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
    ag_app *app = make_app(2, 0);
    int64_t ok_job, bad_job;
    ag_error err;
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &ok_job, &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(app, "bad", "{}", &bad_job, &err), AG_OK);
    ag_job_row row;
    wait_status(app, ok_job, "succeeded", &row);
    assert_string_equal(row.result_json, "{\"answer\":42}");
    assert_true(row.progress == 1.0);
    ag_jobs_row_clear(&row);
    wait_status(app, bad_job, "failed", &row);
    assert_non_null(strstr(row.error_json, "urn:archgram:problem:parse"));
    assert_non_null(strstr(row.error_json, "\"line\":7"));
    assert_null(row.result_json);
    ag_jobs_row_clear(&row);
    drop_app(app);
}

static void running_and_queued_jobs_cancel(void **state)
{
    (void)state;
    ag_app *app = make_app(1, 0);
    int64_t running, queued;
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(app, "slow", "{}", &running, &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &queued, &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    /* The one worker is busy: the second job waits and is cancelled before it starts. */
    assert_int_equal(ag_jobqueue_cancel(app, queued, &err), AG_OK);
    ag_job_row row;
    wait_status(app, queued, "cancelled", &row);
    assert_non_null(strstr(row.error_json, "before it started"));
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_cancel(app, running, &err), AG_OK);
    wait_status(app, running, "cancelled", &row);
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_cancel(app, 9999, &err), AG_ERR_NOT_FOUND);
    drop_app(app);
}

static void full_queue_refuses(void **state)
{
    (void)state;
    ag_app *app = make_app(1, 2);
    int64_t ids[3];
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(app, "slow", "{}", &ids[0], &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &ids[1], &err), AG_OK);
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &ids[2], &err), AG_OK);
    int64_t extra = 0;
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &extra, &err), AG_ERR_BUSY);
    assert_int_equal(extra, 0);
    drop_app(app);
}

static void shutdown_cancels_running_jobs(void **state)
{
    (void)state;
    ag_app *app = make_app(1, 0);
    int64_t job;
    ag_error err;
    atomic_store(&started, 0);
    assert_int_equal(ag_jobqueue_submit(app, "slow", "{}", &job, &err), AG_OK);
    while (!atomic_load(&started))
        usleep(1000);
    ag_app_shutdown(app);
    ag_job_row row;
    assert_int_equal(ag_jobs_get(ag_app_db(app, NULL), job, &row, NULL), AG_OK);
    assert_string_equal(row.status, "cancelled");
    assert_non_null(strstr(row.error_json, "stopped before the job finished"));
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobqueue_submit(app, "good", "{}", &job, &err), AG_ERR_CANCELLED);
    drop_app(app);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(outcomes_are_recorded),
        cmocka_unit_test(running_and_queued_jobs_cancel),
        cmocka_unit_test(full_queue_refuses),
        cmocka_unit_test(shutdown_cancels_running_jobs),
    };
    return cmocka_run_group_tests_name("jobqueue", tests, NULL, NULL);
}
