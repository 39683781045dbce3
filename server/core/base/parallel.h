/* Work split in parts that may run at once, for the stages whose result cannot depend on the
 * split (each part writes only its own output; the caller merges them in part order).
 *
 * Core and io have no threads: a program that has them installs a runner (app/threads.h;
 * the CLI does), and without one the parts run in turn on the caller's thread. */
#ifndef AG_PARALLEL_H
#define AG_PARALLEL_H

#include <stddef.h>

/* One part: fn(ctx, part) for part in 0 .. nparts - 1. */
typedef void (*ag_parallel_part)(void *ctx, size_t part);

/* Runs fn(ctx, 0 .. nparts - 1) and returns when all are done; part 0 on the caller's
 * thread. */
typedef void (*ag_parallel_runner)(size_t nparts, ag_parallel_part fn, void *ctx);

/* Installs the process's runner (NULL: none); set once, before any work starts. */
void ag_parallel_install(ag_parallel_runner run, size_t threads);

/* How many parts are worth making: the threads the runner has (1 without a runner). */
size_t ag_parallel_threads(void);

/* Runs the parts through the installed runner, else in turn. */
void ag_parallel_run(size_t nparts, ag_parallel_part fn, void *ctx);

#endif
