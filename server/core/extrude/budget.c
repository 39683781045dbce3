#include "budget.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

/* The one clock of the extrusion code (libc's monotonic clock). */
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void ag_budget_start(ag_budget *m, const ag_extrude_budget *b, size_t corners)
{
    memset(m, 0, sizeof *m);
    m->start = now();
    m->max_events = b && b->max_events ? b->max_events
                                       : AG_BUDGET_EVENTS_BASE + AG_BUDGET_EVENTS_PER_CORNER * corners;
    m->max_bytes = b && b->max_bytes ? b->max_bytes
                                     : AG_BUDGET_BYTES_BASE + AG_BUDGET_BYTES_PER_CORNER * corners;
    double seconds = b && b->max_seconds ? b->max_seconds : AG_BUDGET_SECONDS;
    m->deadline = seconds > 0 ? m->start + seconds : INFINITY;
    m->cancelled = b ? b->cancelled : NULL;
    m->user = b ? b->user : NULL;
    m->st = AG_OK;
}

double ag_budget_elapsed(const ag_budget *m)
{
    return now() - m->start;
}

ag_status ag_budget_poll(ag_budget *m, size_t bytes)
{
    if (m->st != AG_OK)
        return m->st;
    m->since_poll = 0;
    m->work_since_poll = 0;
    if (m->cancelled && m->cancelled(m->user)) {
        m->st = AG_ERR_CANCELLED;
        snprintf(m->why, sizeof m->why, "cancelled after %.3f s and %zu events",
                 now() - m->start, m->events);
    } else if (isfinite(m->deadline) && now() > m->deadline) {
        m->st = AG_ERR_TOO_LARGE;
        snprintf(m->why, sizeof m->why, "stopped by its time budget (%.3g s) after %zu events",
                 m->deadline - m->start, m->events);
    } else if (bytes > m->max_bytes) {
        m->st = AG_ERR_TOO_LARGE;
        snprintf(m->why, sizeof m->why,
                 "stopped by its memory budget (%zu MB) after %zu events", m->max_bytes >> 20,
                 m->events);
    }
    return m->st;
}

ag_status ag_budget_spend(ag_budget *m, size_t n, size_t bytes)
{
    if (m->st != AG_OK)
        return m->st;
    m->events += n;
    if (m->events > m->max_events) {
        m->st = AG_ERR_TOO_LARGE;
        snprintf(m->why, sizeof m->why, "stopped by its event budget (%zu events)",
                 m->max_events);
        return m->st;
    }
    m->since_poll += (unsigned)n;
    if (m->since_poll >= AG_BUDGET_POLL_EVENTS)
        return ag_budget_poll(m, bytes);
    return AG_OK;
}

ag_status ag_budget_work(ag_budget *m, size_t n, size_t bytes)
{
    if (m->st != AG_OK)
        return m->st;
    m->work_since_poll += n;
    if (m->work_since_poll < AG_BUDGET_POLL_WORK)
        return AG_OK;
    m->work_since_poll = 0;
    return ag_budget_poll(m, bytes);
}
