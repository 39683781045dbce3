#include "live_protocol.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../app/app_change.h"
#include "../app/app_query.h"
#include "../app/auth.h"
#include "../app/optable.h"
#include "../app/problem.h"
#include "ratelimit.h"

#define AG_LIVE_MAX_PRESENCE (16u << 10)
#define AG_LIVE_WELCOME_OPS 5000
/* Live drag previews solved per connection per second at most; extra ones wait, the newest
 * replacing the one waiting. */
#define AG_LIVE_PREVIEW_HZ 30

static double mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* --- hello, presence, watch ----------------------------------------------------------------- */

static void on_hello(ag_live *live, ag_live_session *s, json_t *msg)
{
    json_t *jmodel = json_object_get(msg, "model");
    json_t *jsince = json_object_get(msg, "since");
    json_t *juser = json_object_get(msg, "user");
    ag_error err;
    if (!json_is_integer(jmodel) || json_integer_value(jmodel) < 1)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "hello needs \"model\", a model id%s",
                                        "");
    if (jsince && !json_is_null(jsince) &&
        (!json_is_integer(jsince) || json_integer_value(jsince) < 0))
        return ag_live_rooms_send_error(s, AG_ERR_INVALID,
                                        "\"since\" must be a version (0 or more)%s", "");
    /* identity comes from the handshake's token: a "user" the client names is ignored */
    if (juser && !json_is_string(juser))
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "\"user\" must be a string%s", "");

    ag_app *app = ag__live_app(live);
    int64_t model = json_integer_value(jmodel), version;
    ag_model_role role;
    ag_status st = ag_auth_check(app, &s->who, AG_NEED_MODEL_VIEWER, model, &role, &err);
    if (st == AG_OK)
        st = ag_app_query_version(app, model, &version, &err);
    if (st != AG_OK)
        return ag_live_rooms_send_problem(s, st, &err);
    json_t *ops = NULL;
    int more = 0;
    if (jsince && json_is_integer(jsince)) {
        int64_t since = json_integer_value(jsince), v2;
        if (since > version) {
            char detail[128];
            snprintf(detail, sizeof detail, "%lld", (long long)version);
            return ag_live_rooms_send_error(
                s, AG_ERR_INVALID, "\"since\" is ahead of the model, which is at version %s",
                detail);
        }
        if ((st = ag_app_query_ops(app, model, since, AG_LIVE_WELCOME_OPS, &ops, &v2, &err)) !=
            AG_OK)
            return ag_live_rooms_send_problem(s, st, &err);
        more = version - since > AG_LIVE_WELCOME_OPS;
    }
    if (!ops)
        ops = json_array();
    json_t *peers = ag_live_rooms_join(ag__live_rooms(live), s, model, version);
    s->role = role;
    char you[32];
    ag_live_rooms_peer_name(s, you, sizeof you);
    ag_live_rooms_send_json(s, json_pack("{s:s, s:I, s:I, s:s, s:o, s:b, s:o, s:s, s:s}", "type",
                                         "welcome", "model", (json_int_t)model, "version",
                                         (json_int_t)version, "you", you, "ops", ops, "more",
                                         more, "peers", peers, "user", s->who.name, "role",
                                         ag_auth_model_role_name(role)));
}

static void on_presence(ag_live *live, ag_live_session *s, json_t *msg)
{
    if (!s->model)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "send hello before presence%s", "");
    json_t *state = json_object_get(msg, "state");
    if (!json_is_object(state))
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "presence needs a \"state\" object%s",
                                        "");
    /* the name others see is the account's, whatever the state says */
    if (json_object_get(state, "name"))
        json_object_set_new(state, "name", json_string(s->who.name));
    char *text = json_dumps(state, JSON_COMPACT);
    if (!text)
        return;
    if (strlen(text) > AG_LIVE_MAX_PRESENCE) {
        free(text);
        return ag_live_rooms_send_error(s, AG_ERR_TOO_LARGE,
                                        "a presence state holds at most 16 KiB%s", "");
    }
    ag_live_rooms_presence(ag__live_rooms(live), s, text, state);
}

static void on_watch(ag_live *live, ag_live_session *s, json_t *msg)
{
    json_t *jjob = json_object_get(msg, "job");
    if (!json_is_integer(jjob) || json_integer_value(jjob) < 1)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "watch needs \"job\", a job id%s", "");
    ag_error err;
    json_t *view = NULL;
    int done = 0;
    int64_t id = json_integer_value(jjob);
    ag_status st = ag_auth_check(ag__live_app(live), &s->who, AG_NEED_JOB, id, NULL, &err);
    if (st == AG_OK)
        st = ag_app_query_job(ag__live_app(live), id, &view, &done, &err);
    if (st == AG_OK && !done)
        st = ag_live_rooms_watch(s, id, json_number_value(json_object_get(view, "progress")),
                                 &err);
    if (st != AG_OK) {
        json_decref(view);
        return ag_live_rooms_send_problem(s, st, &err);
    }
    ag_live_rooms_send_json(s, ag_live_rooms_job_message(view));
    json_decref(view);
}

/* --- ops ----------------------------------------------------------------------------------- */

/* The ack or nack of an op (any thread). */
static json_t *op_reply(ag_app *app, int64_t model, const char *user, uint64_t origin,
                        json_t *msg, ag_task_budget *budget)
{
    json_t *jcid = json_object_get(msg, "cid");
    const char *cid = json_string_value(jcid);
    json_t *jbase = json_object_get(msg, "base");
    ag_error err;
    ag_error_clear(&err);
    ag_status st = AG_OK;
    if (!cid)
        st = ag_error_set(&err, AG_ERR_INVALID, 0, "an op needs a string \"cid\"");
    else if (!json_is_integer(jbase))
        st = ag_error_set(&err, AG_ERR_INVALID, 0,
                          "an op needs \"base\", the version it was made on");
    int64_t version = 0;
    int dup = 0;
    if (st == AG_OK) {
        ag_op_request rq = {.model = model,
                            .base = json_integer_value(jbase),
                            .author = user,
                            .cid = cid,
                            .op = json_object_get(msg, "op"),
                            .origin = origin,
                            .budget = budget,
                            .rebase = 1};
        st = ag_app_change_op(app, &rq, &version, &dup, &err);
    }
    if (st == AG_OK)
        return json_pack("{s:s, s:s, s:I, s:b}", "type", "ack", "cid", cid, "version",
                         (json_int_t)version, "duplicate", dup);
    int64_t current = 0;
    if (st == AG_ERR_STALE) {
        current = err.element;
        err.element = 0;
    } else if (ag_app_query_version(app, model, &current, NULL) != AG_OK) {
        current = 0;
    }
    return json_pack("{s:s, s:o, s:I, s:o}", "type", "nack", "cid",
                     cid ? json_string(cid) : json_null(), "version", (json_int_t)current,
                     "problem", ag_problem_json(st, &err));
}

/* The nack of an op whose answer could not be built (out of memory), written without
 * allocating: the cid is kept when it can go into JSON as it is. */
static void nack_fallback(const json_t *msg, char *buf, size_t cap)
{
    const char *cid = json_string_value(json_object_get(msg, "cid"));
    int plain = cid && strlen(cid) <= 100;
    for (const char *c = cid; plain && *c; c++)
        plain = *c >= 0x20 && *c < 0x7f && *c != '"' && *c != '\\';
    char problem[AG_PROBLEM_FALLBACK_MAX];
    ag_problem_fallback(AG_ERR_NOMEM, problem, sizeof problem);
    snprintf(buf, cap, "{\"type\":\"nack\",\"cid\":%s%s%s,\"version\":0,\"problem\":%s}",
             plain ? "\"" : "", plain ? cid : "null", plain ? "\"" : "", problem);
}
#define NACK_FALLBACK_MAX (AG_PROBLEM_FALLBACK_MAX + 160)

/* The text of an op's answer (reply stolen): its JSON, or, when that could not be built, the
 * fallback nack written into buf. *heap is what to free afterwards (NULL when buf is used). */
static const char *answer_text(json_t *reply, const json_t *msg, char *buf, size_t cap,
                               char **heap)
{
    *heap = reply ? json_dumps(reply, JSON_COMPACT) : NULL;
    json_decref(reply);
    if (*heap)
        return *heap;
    nack_fallback(msg, buf, cap);
    return buf;
}

/* A nack refused before any model was read. */
static json_t *nack_json(const json_t *msg, ag_status st, const ag_error *err)
{
    return json_pack("{s:s, s:O?, s:I, s:o}", "type", "nack", "cid", json_object_get(msg, "cid"),
                     "version", (json_int_t)0, "problem", ag_problem_json(st, err));
}

/* Solves a drag preview (any thread): the message for the whole room (the author too: the
 * server's solve is what everyone sees), or with *to_room = 0 a problem for the author only.
 * Nothing is stored. */
static json_t *preview_message(ag_app *app, int64_t model, const char *user, const char *peer,
                               json_t *msg, int *to_room)
{
    *to_room = 0;
    json_t *jbase = json_object_get(msg, "base");
    ag_error err;
    ag_error_clear(&err);
    json_t *boxes = NULL;
    double solve_ms = 0;
    ag_status st = json_is_integer(jbase)
                       ? ag_app_change_preview(app, model, json_integer_value(jbase),
                                               json_object_get(msg, "op"), &boxes, &solve_ms,
                                               &err)
                       : ag_error_set(&err, AG_ERR_INVALID, 0,
                                      "a preview needs \"base\", the version it was made on");
    if (st != AG_OK) {
        int64_t current = st == AG_ERR_STALE ? err.element : 0;
        if (st == AG_ERR_STALE)
            err.element = 0;
        return json_pack("{s:s, s:O?, s:I, s:o}", "type", "preview.error", "base", jbase,
                         "version", (json_int_t)current, "problem", ag_problem_json(st, &err));
    }
    *to_room = 1;
    return json_pack("{s:s, s:s, s:s, s:O, s:o, s:f}", "type", "preview", "peer", peer, "author",
                     user, "base", jbase, "boxes", boxes, "solve_ms", solve_ms);
}

/* A structural op or a preview, computed on the model's task lane (app.h). */
typedef struct {
    ag_live *live;
    uint64_t session;
    int64_t model;
    char *user, *peer;
    json_t *msg;
    int preview;
} task;

static void task_free(void *user)
{
    task *t = user;
    json_decref(t->msg);
    free(t->user);
    free(t->peer);
    free(t);
}

static void task_run(void *user, ag_task_budget *budget)
{
    task *t = user;
    ag_app *app = ag__live_app(t->live);
    int to_room = 0;
    json_t *reply = t->preview ? preview_message(app, t->model, t->user, t->peer, t->msg, &to_room)
                               : op_reply(app, t->model, t->user, t->session, t->msg, budget);
    char fallback[NACK_FALLBACK_MAX], *heap;
    if (!reply && t->preview) {
        task_free(t); /* a preview is only worth its newest position */
        return;
    }
    const char *text = answer_text(reply, t->msg, fallback, sizeof fallback, &heap);
    if (to_room)
        ag__live_post_to_room(t->live, t->model, text);
    else
        ag__live_post_to_session(t->live, t->session, text); /* an op is always answered */
    free(heap);
    task_free(t);
}

/* Sends the answer to an op from the service thread. */
static void send_answer(ag_live_session *s, const json_t *msg, json_t *reply /* stolen */)
{
    char fallback[NACK_FALLBACK_MAX], *heap;
    ag_live_rooms_send(s, answer_text(reply, msg, fallback, sizeof fallback, &heap));
    free(heap);
}

/* A task the queue dropped at a stop: an op is still answered. */
static void task_drop(void *user)
{
    task *t = user;
    if (!t->preview) {
        ag_error err;
        ag_error_set(&err, AG_ERR_CANCELLED, 0,
                     "archgramd is shutting down; the op was not applied");
        char fallback[NACK_FALLBACK_MAX], *heap;
        ag__live_post_to_session(t->live, t->session,
                                 answer_text(nack_json(t->msg, AG_ERR_CANCELLED, &err), t->msg,
                                             fallback, sizeof fallback, &heap));
        free(heap);
    }
    task_free(t);
}

static void run_on_task_lane(ag_live *live, ag_live_session *s, json_t *msg, int preview)
{
    task *t = calloc(1, sizeof *t);
    char peer[32];
    ag_live_rooms_peer_name(s, peer, sizeof peer);
    if (t && (!(t->user = strdup(s->user)) || !(t->peer = strdup(peer)))) {
        free(t->user);
        free(t);
        t = NULL;
    }
    if (!t)
        return ag_live_rooms_send_error(s, AG_ERR_NOMEM, "out of memory%s", "");
    t->live = live;
    t->session = s->id;
    t->model = s->model;
    t->msg = json_incref(msg);
    t->preview = preview;
    ag_error err;
    ag_status st = ag_app_run_task(ag__live_app(live), AG_TASK_OP, s->model, task_run,
                                   task_drop, t, &err);
    if (st == AG_OK)
        return;
    task_free(t);
    if (preview)
        return; /* a preview is only worth its newest position: drop it */
    if (st == AG_ERR_BUSY)
        ag_error_set(&err, AG_ERR_BUSY, 0, "too many edits are waiting; send it again later");
    send_answer(s, msg, nack_json(msg, st, &err));
}

/* May s change its room's model now? Checked on every op and preview, so a role taken away
 * counts at once; otherwise the problem is in err. */
static ag_status may_edit(ag_live *live, ag_live_session *s, ag_error *err)
{
    return ag_auth_check(ag__live_app(live), &s->who, AG_NEED_MODEL_EDITOR, s->model, &s->role,
                         err);
}

static void on_op(ag_live *live, ag_live_session *s, json_t *msg)
{
    if (!s->model)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "send hello before ops%s", "");
    ag_error err;
    ag_status st = may_edit(live, s, &err);
    if (st != AG_OK) {
        int64_t current = 0;
        if (ag_app_query_version(ag__live_app(live), s->model, &current, NULL) != AG_OK)
            current = 0;
        return send_answer(s, msg,
                           json_pack("{s:s, s:O?, s:I, s:o}", "type", "nack", "cid",
                                     json_object_get(msg, "cid"), "version",
                                     (json_int_t)current, "problem", ag_problem_json(st, &err)));
    }
    const ag_op_kind *row =
        ag_optable_find(json_string_value(json_object_get(json_object_get(msg, "op"), "kind")));
    /* structural kinds a client may send go to the model's task lane; the rest (and every
     * refusal that needs no model) is answered here */
    if (row && row->lane == AG_OP_STRUCTURAL && (row->flags & AG_OP_CLIENT) &&
        json_is_string(json_object_get(msg, "cid")))
        return run_on_task_lane(live, s, msg, 0);
    send_answer(s, msg, op_reply(ag__live_app(live), s->model, s->user, s->id, msg, NULL));
}

/* --- previews ------------------------------------------------------------------------------ */

static void send_preview(ag_live *live, ag_live_session *s, json_t *msg)
{
    s->preview_at = mono_ms();
    run_on_task_lane(live, s, msg, 1);
}

static void on_preview(ag_live *live, ag_live_session *s, json_t *msg)
{
    if (!s->model)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID, "send hello before previews%s", "");
    json_t *jm = json_object_get(msg, "model");
    if (jm && (!json_is_integer(jm) || json_integer_value(jm) != s->model))
        return ag_live_rooms_send_error(
            s, AG_ERR_INVALID, "a preview is for the model of the connection's room%s", "");
    ag_error err;
    ag_status st = may_edit(live, s, &err);
    if (st != AG_OK)
        return ag_live_rooms_send_json(
            s, json_pack("{s:s, s:O?, s:I, s:o}", "type", "preview.error", "base",
                         json_object_get(msg, "base"), "version", (json_int_t)0, "problem",
                         ag_problem_json(st, &err)));
    double wait = s->preview_at + 1000.0 / AG_LIVE_PREVIEW_HZ - mono_ms();
    if (wait <= 0 && !s->preview_next)
        return send_preview(live, s, msg);
    /* too soon: keep the newest, solve it when its turn comes */
    if (!s->preview_next)
        lws_set_timer_usecs(s->wsi, wait > 0 ? (lws_usec_t)(wait * 1000) : 1);
    json_decref(s->preview_next);
    s->preview_next = json_incref(msg);
}

static void on_preview_end(ag_live *live, ag_live_session *s, json_t *msg)
{
    (void)msg;
    if (!s->model)
        return;
    json_decref(s->preview_next);
    s->preview_next = NULL;
    char peer[32];
    ag_live_rooms_peer_name(s, peer, sizeof peer);
    ag_live_rooms_broadcast_json(ag__live_rooms(live), s->model, s,
                                 json_pack("{s:s, s:s, s:s}", "type", "preview.end", "peer", peer,
                                           "author", s->user));
}

void ag_live_protocol_timer(ag_live *live, ag_live_session *s)
{
    if (!s->preview_next)
        return;
    json_t *msg = s->preview_next;
    s->preview_next = NULL;
    if (s->model)
        send_preview(live, s, msg);
    json_decref(msg);
}

/* --- dispatch ------------------------------------------------------------------------------ */

static const struct {
    const char *type;
    void (*handle)(ag_live *live, ag_live_session *s, json_t *msg);
} handlers[] = {
    {"hello", on_hello},
    {"op", on_op},
    {"presence", on_presence},
    {"watch", on_watch},
    {"preview", on_preview},
    {"preview.end", on_preview_end},
};

const char *ag_live_protocol_type(size_t i)
{
    return i < sizeof handlers / sizeof handlers[0] ? handlers[i].type : NULL;
}

/* Past the client's message rate: an op is nacked (its sender waits for an answer), a drag
 * preview dropped (a newer one follows), anything else answered with an error. */
static void refuse_rate(ag_live_session *s, const char *data, size_t len, double wait)
{
    long seconds = (long)wait + ((double)(long)wait < wait);
    if (seconds < 1)
        seconds = 1;
    json_t *msg = data && len ? json_loadb(data, len, 0, NULL) : NULL;
    const char *type = json_string_value(json_object_get(msg, "type"));
    if (type && strcmp(type, "preview") == 0) {
        json_decref(msg);
        return;
    }
    ag_error err;
    ag_error_set(&err, AG_ERR_RATE_LIMITED, 0,
                 "too many messages from this client; try again in %ld s", seconds);
    json_t *reply =
        type && strcmp(type, "op") == 0
            ? json_pack("{s:s, s:O?, s:I, s:o, s:I}", "type", "nack", "cid",
                        json_object_get(msg, "cid"), "version", (json_int_t)0, "problem",
                        ag_problem_json(AG_ERR_RATE_LIMITED, &err), "retry_after",
                        (json_int_t)seconds)
            : json_pack("{s:s, s:o, s:I}", "type", "error", "problem",
                        ag_problem_json(AG_ERR_RATE_LIMITED, &err), "retry_after",
                        (json_int_t)seconds);
    if (reply)
        ag_live_rooms_send_json(s, reply);
    else
        ag_live_rooms_send_problem(s, AG_ERR_RATE_LIMITED, &err);
    json_decref(msg);
}

void ag_live_protocol_message(ag_live *live, ag_live_session *s, const char *data, size_t len,
                              int binary, int overflow)
{
    double wait = 0;
    if (!ag_ratelimit_take(ag__live_message_limit(live), s->rate_key, &wait))
        return refuse_rate(s, overflow || binary ? NULL : data, len, wait);
    if (overflow) {
        char limit[32];
        snprintf(limit, sizeof limit, "%u", AG_LIVE_MAX_MESSAGE);
        return ag_live_rooms_send_error(s, AG_ERR_TOO_LARGE, "a message holds at most %s bytes",
                                        limit);
    }
    if (binary)
        return ag_live_rooms_send_error(s, AG_ERR_INVALID,
                                        "messages are JSON text frames, not binary%s", "");
    json_error_t je;
    json_t *msg = json_loadb(data ? data : "", len, 0, &je);
    if (!msg) {
        ag_error err;
        ag_error_set(&err, AG_ERR_INVALID, je.column, "the message is not JSON: %s (column %d)",
                     je.text, je.column);
        return ag_live_rooms_send_problem(s, AG_ERR_INVALID, &err);
    }
    const char *type = json_string_value(json_object_get(msg, "type"));
    size_t i = 0, n = sizeof handlers / sizeof handlers[0];
    while (type && i < n && strcmp(type, handlers[i].type) != 0)
        i++;
    if (!json_is_object(msg) || !type)
        ag_live_rooms_send_error(s, AG_ERR_INVALID,
                                 "a message is a JSON object with a string \"type\"%s", "");
    else if (i == n)
        ag_live_rooms_send_error(s, AG_ERR_INVALID, "unknown message type \"%s\"", type);
    else
        handlers[i].handle(live, s, msg);
    json_decref(msg);
}
