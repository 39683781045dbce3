/* Threads for work beside the caller's: one helper for a task on a thread of its own, and
 * the runner of core's parallel parts (core/base/parallel.h) on threads. */
#ifndef AG_THREADS_H
#define AG_THREADS_H

#include <pthread.h>
#include <stddef.h>

/* fn(arg) on a thread of its own (ag_beside_start), or on the caller's when no thread can
 * start: then at once, so ag_beside_join always finds it done. */
typedef struct {
    pthread_t thread;
    int started;
} ag_beside;

void ag_beside_start(ag_beside *b, void *(*fn)(void *), void *arg);
/* Waits for the task (done at once when it ran on the caller's thread). */
void ag_beside_join(ag_beside *b);

/* Installs a runner of core's parallel parts with one thread per online processor (at most
 * 8): part 0 on the caller's thread, the others each on a thread of its own. */
void ag_threads_install(void);

#endif
