/* Threads beside the caller (app/threads.h) and core's parallel parts (core/base/parallel.h):
 * without a runner the parts run in turn on the caller's thread; with the installed one every
 * part runs exactly once, part 0 on the caller's thread, the others on threads of their own
 * (more parts than threads included), and a task started beside is done once joined. */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "app/threads.h"
#include "core/base/parallel.h"

#define MAX_PARTS 20

typedef struct {
    pthread_t caller;
    int runs[MAX_PARTS];
    int on_caller[MAX_PARTS];
    size_t order[MAX_PARTS];
    size_t nrun;
    pthread_mutex_t lock;
} record;

static void note(void *ctx, size_t part)
{
    record *r = ctx;
    pthread_mutex_lock(&r->lock);
    r->runs[part]++;
    r->on_caller[part] = pthread_equal(pthread_self(), r->caller) != 0;
    r->order[r->nrun++] = part;
    pthread_mutex_unlock(&r->lock);
}

static void record_init(record *r)
{
    memset(r, 0, sizeof *r);
    r->caller = pthread_self();
    pthread_mutex_init(&r->lock, NULL);
}

static void test_without_runner_parts_run_in_turn_on_the_caller(void **state)
{
    (void)state;
    ag_parallel_install(NULL, 0);
    assert_int_equal(ag_parallel_threads(), 1);
    record r;
    record_init(&r);
    ag_parallel_run(5, note, &r);
    assert_int_equal(r.nrun, 5);
    for (size_t i = 0; i < 5; i++) {
        assert_int_equal(r.runs[i], 1);
        assert_true(r.on_caller[i]);
        assert_int_equal(r.order[i], i); /* in turn */
    }
    pthread_mutex_destroy(&r.lock);
}

static void test_installed_runner_runs_every_part_once(void **state)
{
    (void)state;
    ag_threads_install();
    assert_true(ag_parallel_threads() >= 1);
    const size_t counts[] = {1, 2, 3, MAX_PARTS};
    for (size_t k = 0; k < sizeof counts / sizeof *counts; k++) {
        size_t n = counts[k];
        record r;
        record_init(&r);
        ag_parallel_run(n, note, &r);
        assert_int_equal(r.nrun, n);
        for (size_t i = 0; i < n; i++)
            assert_int_equal(r.runs[i], 1);
        assert_true(r.on_caller[0]);
        if (n > 1)
            assert_false(r.on_caller[1]); /* a thread of its own */
        pthread_mutex_destroy(&r.lock);
    }
    ag_parallel_install(NULL, 0);
}

static void *set_flag(void *arg)
{
    *(int *)arg = 42;
    return NULL;
}

static void test_beside_is_done_once_joined(void **state)
{
    (void)state;
    int flag = 0;
    ag_beside b;
    ag_beside_start(&b, set_flag, &flag);
    ag_beside_join(&b);
    assert_int_equal(flag, 42);
    ag_beside_join(&b); /* a second join waits for nothing */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_without_runner_parts_run_in_turn_on_the_caller),
        cmocka_unit_test(test_installed_runner_runs_every_part_once),
        cmocka_unit_test(test_beside_is_done_once_joined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
