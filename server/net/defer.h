/* Requests answered off the HTTP threads: a handler whose work may take long (a structural
 * op, a grammar edit, an extrusion preview) suspends its connection and hands the work to a
 * task lane of the app (app.h: one lane per model, under the op's time budget); the worker
 * fills the request's answer and resumes the connection, and the HTTP thread sends it. So a
 * long op never holds an HTTP thread (GET /api/v1/health stays fast), a client that closes
 * its connection stops the work (the budget sees the socket closed), and a shutdown answers
 * waiting requests with 503 instead of waiting for them.
 *
 * The request (its body, ids, headers) stays valid while the work runs: libmicrohttpd does not
 * end a suspended connection, and archgramd stops libmicrohttpd only once the task lanes have
 * stopped. */
#ifndef AG_DEFER_H
#define AG_DEFER_H

#include "request.h"

typedef void (*ag_defer_work)(ag_request *r, ag_task_budget *budget);

/* Suspends r's connection and runs work(r, budget) as a task of `kind` on model's lane. When
 * the task cannot be queued (too many waiting, shutting down) the problem is the answer. */
enum MHD_Result ag_defer_run(ag_request *r, ag_task_kind kind, int64_t model, ag_defer_work work);

/* Runs work(r, NULL) here and sends its answer: the same handler code for work that is
 * quick (a rename) and work that is deferred. */
enum MHD_Result ag_defer_inline(ag_request *r, ag_defer_work work);

/* For work functions: the answer, taken over (data) or copied (err). */
void ag_defer_answer_problem(ag_request *r, ag_status s, const ag_error *err);
void ag_defer_answer_bytes(ag_request *r, unsigned status, const char *content_type,
                           void *data /* stolen, malloc'd */, size_t len, const char *etag);
void ag_defer_answer_json(ag_request *r, unsigned status, json_t *body /* stolen */,
                          const char *etag);

/* On the HTTP thread, once the connection is back: sends the answer (1), or says there is
 * none yet (0, *rc untouched). */
int ag_defer_reply(ag_request *r, enum MHD_Result *rc);

#endif
