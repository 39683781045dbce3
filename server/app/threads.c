#include "threads.h"

#include <unistd.h>

#include "../core/base/parallel.h"

void ag_beside_start(ag_beside *b, void *(*fn)(void *), void *arg)
{
    b->started = pthread_create(&b->thread, NULL, fn, arg) == 0;
    if (!b->started)
        fn(arg);
}

void ag_beside_join(ag_beside *b)
{
    if (b->started)
        pthread_join(b->thread, NULL);
    b->started = 0;
}

typedef struct {
    ag_parallel_part fn;
    void *ctx;
    size_t part;
} part_task;

static void *run_part(void *arg)
{
    part_task *t = arg;
    t->fn(t->ctx, t->part);
    return NULL;
}

#define MAX_THREADS 8

static void run_parts(size_t nparts, ag_parallel_part fn, void *ctx)
{
    for (size_t base = 0; base < nparts; base += MAX_THREADS) {
        size_t n = nparts - base < MAX_THREADS ? nparts - base : MAX_THREADS;
        part_task task[MAX_THREADS];
        ag_beside beside[MAX_THREADS];
        for (size_t i = 1; i < n; i++) {
            task[i] = (part_task){fn, ctx, base + i};
            ag_beside_start(&beside[i], run_part, &task[i]);
        }
        fn(ctx, base);
        for (size_t i = 1; i < n; i++)
            ag_beside_join(&beside[i]);
    }
}

void ag_threads_install(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    ag_parallel_install(run_parts, n < 1 ? 1 : n > MAX_THREADS ? MAX_THREADS : (size_t)n);
}
