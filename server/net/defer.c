#include "defer.h"

#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/app.h"

/* The client closed (or reset) its connection: nothing will read the answer. */
static int client_gone(void *user)
{
    ag_request *r = user;
    if (r->fd < 0)
        return 0;
    struct pollfd p = {.fd = r->fd, .events = POLLRDHUP};
    return poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL));
}

static void resume(ag_request *r)
{
    r->answer.ready = 1;
    r->deferred = 0;
    MHD_resume_connection(r->conn); /* r belongs to the HTTP thread again */
}

static void task_run(void *user, ag_task_budget *budget)
{
    ag_request *r = user;
    budget->gone = client_gone;
    budget->gone_user = r;
    if (ag_task_budget_exhausted(budget)) {
        ag_error err;
        ag_error_clear(&err);
        ag_status s = ag_task_budget_explain(budget, AG_ERR_CANCELLED, "the request", &err);
        ag_defer_answer_problem(r, s, &err);
    } else {
        r->work(r, budget);
    }
    /* the client left before its answer: the work was skipped or stopped */
    if (budget->gone_seen && r->cfg->abandoned)
        atomic_fetch_add(r->cfg->abandoned, 1);
    resume(r);
}

static void task_drop(void *user)
{
    ag_request *r = user;
    ag_error err;
    ag_error_set(&err, AG_ERR_CANCELLED, 0, "archgramd is shutting down; the request was not run");
    ag_defer_answer_problem(r, AG_ERR_CANCELLED, &err);
    resume(r);
}

enum MHD_Result ag_defer_run(ag_request *r, ag_task_kind kind, int64_t model, ag_defer_work work)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CONNECTION_FD);
    r->fd = ci ? ci->connect_fd : -1;
    r->work = work;
    r->deferred = 1;
    /* suspended first: the task may resume it at once */
    MHD_suspend_connection(r->conn);
    ag_error err;
    ag_error_clear(&err);
    ag_status s = ag_app_run_task(r->cfg->app, kind, model, task_run, task_drop, r, &err);
    if (s != AG_OK) {
        ag_defer_answer_problem(r, s, &err);
        resume(r); /* answered on the next call */
    }
    return MHD_YES;
}

enum MHD_Result ag_defer_inline(ag_request *r, ag_defer_work work)
{
    work(r, NULL);
    r->answer.ready = 1;
    enum MHD_Result rc = MHD_NO;
    ag_defer_reply(r, &rc);
    return rc;
}

void ag_defer_answer_problem(ag_request *r, ag_status s, const ag_error *err)
{
    r->answer.problem = s == AG_OK ? AG_ERR_INTERNAL : s;
    if (err)
        r->answer.err = *err;
    else
        ag_error_clear(&r->answer.err);
}

void ag_defer_answer_bytes(ag_request *r, unsigned status, const char *content_type,
                           void *data, size_t len, const char *etag)
{
    free(r->answer.body);
    r->answer.problem = AG_OK;
    r->answer.status = status;
    r->answer.content_type = content_type;
    r->answer.body = data;
    r->answer.len = len;
    snprintf(r->answer.etag, sizeof r->answer.etag, "%s", etag ? etag : "");
}

void ag_defer_answer_json(ag_request *r, unsigned status, json_t *body, const char *etag)
{
    char *text = body ? json_dumps(body, JSON_COMPACT) : NULL;
    json_decref(body);
    if (!text) {
        ag_error err;
        ag_error_set(&err, AG_ERR_NOMEM, 0, "out of memory writing the answer");
        ag_defer_answer_problem(r, AG_ERR_NOMEM, &err);
        return;
    }
    ag_defer_answer_bytes(r, status, "application/json", text, strlen(text), etag);
}

int ag_defer_reply(ag_request *r, enum MHD_Result *rc)
{
    if (!r->answer.ready)
        return 0;
    ag_defer_answer *a = &r->answer;
    a->ready = 0;
    if (a->problem == AG_OK && !a->status) {
        ag_error_set(&a->err, AG_ERR_INTERNAL, 0, "the work gave no answer");
        a->problem = AG_ERR_INTERNAL;
    }
    if (a->problem != AG_OK) {
        *rc = ag_reply_problem(r, a->problem, &a->err);
    } else {
        void *body = a->body;
        a->body = NULL;
        *rc = ag_reply_bytes(r, a->status, a->content_type, body, a->len,
                             a->etag[0] ? a->etag : NULL);
    }
    return 1;
}
