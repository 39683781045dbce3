/* The budget one piece of interactive work runs under (a structural op, a grammar edit, a
 * drag preview, an extrusion preview): a deadline, a stop flag the job queue raises when the
 * service shuts down, and optionally a check that whoever asked is still there (a REST
 * client that closed its connection). The work polls ag_task_budget_exhausted — the callback
 * core budgets take (ag_edit_budget, the extrusion budget) — and when it stops early, the
 * AG_ERR_CANCELLED it returns is explained by ag_task_budget_explain: AG_ERR_DEADLINE when the
 * time ran out, AG_ERR_CANCELLED naming the shutdown or the client that went away. */
#ifndef AG_TASK_BUDGET_H
#define AG_TASK_BUDGET_H

#include <stdatomic.h>

#include "../core/status.h"

typedef struct ag_task_budget {
    double seconds;          /* the time given; 0 = no deadline */
    double deadline;         /* monotonic seconds */
    const atomic_int *stop;  /* non-zero: stop (may be NULL) */
    int (*gone)(void *user); /* non-zero: the asker is gone (may be NULL) */
    void *gone_user;
    int why;                 /* 0, or what stopped it first: AG_ERR_DEADLINE, AG_ERR_CANCELLED */
    int gone_seen;           /* it stopped because the asker went away */
} ag_task_budget;

/* Starts the clock: seconds from now (0: none), stop may be NULL. */
void ag_task_budget_start(ag_task_budget *b, double seconds, const atomic_int *stop);
/* Polled by the work (b is an ag_task_budget *; NULL never stops): non-zero once the
 * deadline passed, the stop flag is up or the asker is gone, and from then on. */
int ag_task_budget_exhausted(void *b);
/* Seconds left before the deadline (a large number without one, 0 once passed). */
double ag_task_budget_left(const ag_task_budget *b);
/* The status work stopped by this budget reports: s unchanged unless it is AG_ERR_CANCELLED
 * and the budget is exhausted, then the reason, with err's text saying so. */
ag_status ag_task_budget_explain(const ag_task_budget *b, ag_status s, const char *what,
                                 ag_error *err);

#endif
