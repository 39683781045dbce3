/* What one extrusion may spend: events, wall-clock time, memory, and a cancel callback.
 *
 * Every extrusion (the CLI, a job, a REST preview) runs under a budget; when it runs out
 * the extrusion stops with a message that names the budget and where the sweep was:
 * AG_ERR_TOO_LARGE for the event, memory and time budgets (the plan needs more than it
 * was given), AG_ERR_CANCELLED when the callback asks. Nothing is added to the output.
 *
 * The service wires it like this (one extrusion, e.g. a REST preview or one building of
 * a job):
 *
 *     ag_extrude_budget b = {0};          // defaults: events and memory by plan size, 60 s
 *     b.max_seconds = 10;                 // the request's or the job's share
 *     b.cancelled = my_cancelled;         // job cancelled, client gone, SIGTERM seen
 *     b.user = ctx;
 *     ag_extrude_options o = {.budget = b};
 *     ag_extrude_plan_with(plan, &o, mesh, group, &result, NULL, &err);
 *
 * The callback is polled every AG_BUDGET_POLL_EVENTS events (a few microseconds each)
 * and between the stages of an extrusion, so a cancel takes effect within milliseconds.
 * It may be called from the thread running the extrusion only; it must be cheap and
 * thread-safe with respect to whoever sets the condition it reads (an atomic flag). */
#ifndef AG_EXTRUDE_BUDGET_H
#define AG_EXTRUDE_BUDGET_H

#include <stddef.h>

#include "../status.h"

typedef struct {
    /* events taken from and put into the sweep's queue, valid or not (the nested sweeps of
     * inside boundaries included); 0: AG_BUDGET_EVENTS_PER_CORNER per plan corner plus
     * AG_BUDGET_EVENTS_BASE */
    size_t max_events;
    /* wall-clock seconds from the start of the extrusion; 0: AG_BUDGET_SECONDS, negative:
     * no limit */
    double max_seconds;
    /* bytes of the sweep's state and the shell; 0: AG_BUDGET_BYTES_BASE plus
     * AG_BUDGET_BYTES_PER_CORNER per plan corner */
    size_t max_bytes;
    /* polled often; non-zero stops the extrusion with AG_ERR_CANCELLED */
    int (*cancelled)(void *user);
    void *user;
} ag_extrude_budget;

#define AG_BUDGET_SECONDS 60.0
#define AG_BUDGET_EVENTS_PER_CORNER 4000
#define AG_BUDGET_EVENTS_BASE 100000
#define AG_BUDGET_BYTES_PER_CORNER (128 * 1024)
#define AG_BUDGET_BYTES_BASE ((size_t)64 << 20)
#define AG_BUDGET_POLL_EVENTS 256
#define AG_BUDGET_POLL_WORK 65536

/* The running account of one extrusion against its budget. */
typedef struct {
    size_t events, max_events;
    size_t max_bytes;
    double start, deadline; /* monotonic seconds; deadline INFINITY: none */
    int (*cancelled)(void *user);
    void *user;
    unsigned since_poll;
    size_t work_since_poll;
    ag_status st; /* AG_OK until a budget runs out */
    char why[160];
} ag_budget;

/* Starts the account for a plan of `corners` corners (b may be NULL: defaults). */
void ag_budget_start(ag_budget *m, const ag_extrude_budget *b, size_t corners);
/* Counts n events and, every AG_BUDGET_POLL_EVENTS, checks the clock, the callback and
 * `bytes` (the current state's size, 0: not known). Returns m->st. */
ag_status ag_budget_spend(ag_budget *m, size_t n, size_t bytes);
/* Counts n units of other work (e.g. candidate pairs tested) and polls the clock, the
 * callback and `bytes` every AG_BUDGET_POLL_WORK of them. Returns m->st. */
ag_status ag_budget_work(ag_budget *m, size_t n, size_t bytes);
/* Checks the clock and the callback now (between stages). */
ag_status ag_budget_poll(ag_budget *m, size_t bytes);
/* Seconds since ag_budget_start. */
double ag_budget_elapsed(const ag_budget *m);

#endif
