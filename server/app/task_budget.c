#include "task_budget.h"

#include <stddef.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void ag_task_budget_start(ag_task_budget *b, double seconds, const atomic_int *stop)
{
    b->seconds = seconds > 0 ? seconds : 0;
    b->deadline = b->seconds ? now() + b->seconds : 0;
    b->stop = stop;
    b->gone = NULL;
    b->gone_user = NULL;
    b->why = 0;
    b->gone_seen = 0;
}

int ag_task_budget_exhausted(void *user)
{
    ag_task_budget *b = user;
    if (!b)
        return 0;
    if (b->why)
        return 1;
    if (b->stop && atomic_load(b->stop))
        b->why = AG_ERR_CANCELLED;
    else if (b->deadline && now() > b->deadline)
        b->why = AG_ERR_DEADLINE;
    else if (b->gone && b->gone(b->gone_user)) {
        b->why = AG_ERR_CANCELLED;
        b->gone_seen = 1;
    }
    return b->why != 0;
}

double ag_task_budget_left(const ag_task_budget *b)
{
    if (!b || !b->deadline)
        return 1e9;
    double left = b->deadline - now();
    return left > 0 ? left : 0;
}

ag_status ag_task_budget_explain(const ag_task_budget *b, ag_status s, const char *what,
                                 ag_error *err)
{
    if (s != AG_ERR_CANCELLED || !b || !b->why)
        return s;
    if (b->why == AG_ERR_DEADLINE)
        return ag_error_set(err, AG_ERR_DEADLINE, 0,
                            "%s ran longer than its budget of %g s and was stopped; nothing "
                            "was stored",
                            what, b->seconds);
    if (b->gone_seen)
        return ag_error_set(err, AG_ERR_CANCELLED, 0,
                            "%s was stopped: the client closed its connection", what);
    return ag_error_set(err, AG_ERR_CANCELLED, 0, "%s was stopped: archgramd is shutting down",
                        what);
}
