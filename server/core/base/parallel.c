#include "parallel.h"

static ag_parallel_runner runner;
static size_t runner_threads = 1;

void ag_parallel_install(ag_parallel_runner run, size_t threads)
{
    runner = run;
    runner_threads = run && threads > 1 ? threads : 1;
}

size_t ag_parallel_threads(void)
{
    return runner_threads;
}

void ag_parallel_run(size_t nparts, ag_parallel_part fn, void *ctx)
{
    if (runner && nparts > 1) {
        runner(nparts, fn, ctx);
        return;
    }
    for (size_t i = 0; i < nparts; i++)
        fn(ctx, i);
}
