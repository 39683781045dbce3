#include "live.h"

#include <jansson.h>
#include <libwebsockets.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../app/edit_ops.h"
#include "../app/events.h"
#include "../app/modelops.h"
#include "../app/views.h"
#include "../store/jobs.h"
#include "../store/models.h"
#include "../store/ops.h"

#define AG_LIVE_MAX_MESSAGE (1u << 20)
#define AG_LIVE_MAX_PRESENCE (16u << 10)
#define AG_LIVE_MAX_OUTBOX 4096
#define AG_LIVE_MAX_WATCH 16
#define AG_LIVE_WELCOME_OPS 5000
/* Live drag previews solved per connection per second at most; extra ones wait, the newest
 * replacing the one waiting. */
#define AG_LIVE_PREVIEW_HZ 30
/* Edits and previews waiting for the worker, over all connections. */
#define AG_LIVE_MAX_WORK 256

typedef struct outmsg {
    struct outmsg *next;
    size_t len;
    unsigned char data[]; /* LWS_PRE bytes of headroom, then the text */
} outmsg;

typedef struct session {
    struct lws *wsi;
    uint64_t id;
    int64_t model; /* 0: in no room */
    int64_t seen;  /* the newest model version this session has been told of */
    char user[801];
    char *presence; /* last state, JSON text */
    char *rx;
    size_t rx_len;
    int rx_overflow, rx_binary;
    outmsg *out_head, *out_tail;
    size_t out_count;
    int closing;
    int64_t watch[AG_LIVE_MAX_WATCH];
    double watch_progress[AG_LIVE_MAX_WATCH]; /* the last progress sent for that job */
    int nwatch;
    double preview_at;      /* when the last preview was solved (ms, monotonic) */
    json_t *preview_next;   /* the newest preview waiting for its turn */
    struct session *prev, *next;
} session;

typedef struct pending {
    struct pending *next;
    ag_event_kind kind;
    int64_t model, version, job;
    uint64_t origin;
    char *author, *cid, *json;
} pending;

/* Structural edits and drag previews can take a while (a model is proceduralized when it is
 * first edited), so one worker thread computes them, in arrival order, off the service thread;
 * its replies come back through the pending list. */
typedef struct work {
    struct work *next;
    uint64_t session;
    int64_t model;
    char *user, *peer;
    json_t *msg; /* the op or preview message */
    int preview;
} work;

/* Pending kinds of the live layer itself, beside the app's events. */
#define LIVE_TO_SESSION ((ag_event_kind)100) /* json to the session `origin` */
#define LIVE_TO_ROOM ((ag_event_kind)101)    /* json to everyone in the room `model` */

struct ag_live {
    ag_app *app;
    struct lws_context *context;
    pthread_t thread;
    atomic_int stop;
    pthread_mutex_t lock; /* guards the pending list */
    pending *head, *tail;
    session *sessions;    /* service thread only */
    uint64_t next_id;
    pthread_t worker;
    int worker_started;
    pthread_mutex_t work_lock;
    pthread_cond_t work_cond;
    work *work_head, *work_tail;
    size_t work_count;    /* guarded by work_lock */
    int work_stop;        /* guarded by work_lock */
};

/* --- sending ------------------------------------------------------------------------------ */

static void send_text(session *s, const char *text)
{
    if (s->closing)
        return;
    if (s->out_count >= AG_LIVE_MAX_OUTBOX) {
        /* A client that reads nothing must not hold the server's memory hostage. */
        s->closing = 1;
        lws_callback_on_writable(s->wsi);
        return;
    }
    size_t len = strlen(text);
    outmsg *m = malloc(sizeof *m + LWS_PRE + len);
    if (!m)
        return;
    m->next = NULL;
    m->len = len;
    memcpy(m->data + LWS_PRE, text, len);
    if (s->out_tail)
        s->out_tail->next = m;
    else
        s->out_head = m;
    s->out_tail = m;
    s->out_count++;
    lws_callback_on_writable(s->wsi);
}

static void send_json(session *s, json_t *msg /* stolen */)
{
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    if (text)
        send_text(s, text);
    free(text);
}

static void send_problem(session *s, ag_status st, const ag_error *err)
{
    send_json(s, json_pack("{s:s, s:o}", "type", "error", "problem", ag_view_problem(st, err)));
}

static void send_error(session *s, ag_status st, const char *fmt, const char *arg)
{
    ag_error err;
    ag_error_set(&err, st, 0, fmt, arg);
    send_problem(s, st, &err);
}

static void peer_name(const session *s, char *buf, size_t len)
{
    snprintf(buf, len, "p%llu", (unsigned long long)s->id);
}

/* Sends text to everyone in a room but `except`. */
static void broadcast(ag_live *live, int64_t model, const session *except, const char *text)
{
    for (session *s = live->sessions; s; s = s->next)
        if (s->model == model && s != except)
            send_text(s, text);
}

static void broadcast_json(ag_live *live, int64_t model, const session *except, json_t *msg)
{
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    if (text)
        broadcast(live, model, except, text);
    free(text);
}

/* --- rooms ----------------------------------------------------------------------------- */

static void leave_room(ag_live *live, session *s)
{
    if (!s->model)
        return;
    char peer[32];
    peer_name(s, peer, sizeof peer);
    int64_t model = s->model;
    s->model = 0;
    free(s->presence);
    s->presence = NULL;
    json_decref(s->preview_next);
    s->preview_next = NULL;
    broadcast_json(live, model, s, json_pack("{s:s, s:s}", "type", "leave", "peer", peer));
}

static void collect_op(void *user, const ag_op_row *op)
{
    json_array_append_new(user, ag_view_op(op));
}

static void on_hello(ag_live *live, session *s, json_t *msg)
{
    json_t *jmodel = json_object_get(msg, "model");
    json_t *jsince = json_object_get(msg, "since");
    json_t *juser = json_object_get(msg, "user");
    ag_error err;
    if (!json_is_integer(jmodel) || json_integer_value(jmodel) < 1)
        return send_error(s, AG_ERR_INVALID, "hello needs \"model\", a model id%s", "");
    if (jsince && !json_is_null(jsince) &&
        (!json_is_integer(jsince) || json_integer_value(jsince) < 0))
        return send_error(s, AG_ERR_INVALID, "\"since\" must be a version (0 or more)%s", "");
    const char *user = juser ? json_string_value(juser) : "guest";
    if (!user)
        return send_error(s, AG_ERR_INVALID, "\"user\" must be a string%s", "");
    ag_status st = ag_models_check_name(user, &err);
    if (st != AG_OK)
        return send_problem(s, st, &err);

    ag_db *db = ag_app_db(live->app, &err);
    if (!db)
        return send_problem(s, err.code, &err);
    ag_model_row row;
    int64_t model = json_integer_value(jmodel);
    if ((st = ag_models_get(db, model, &row, &err)) != AG_OK)
        return send_problem(s, st, &err);
    int64_t version = row.version;
    ag_models_row_clear(&row);

    json_t *ops = json_array();
    int more = 0;
    if (jsince && json_is_integer(jsince)) {
        int64_t since = json_integer_value(jsince);
        if (since > version) {
            json_decref(ops);
            char detail[128];
            snprintf(detail, sizeof detail, "%lld", (long long)version);
            return send_error(s, AG_ERR_INVALID,
                              "\"since\" is ahead of the model, which is at version %s", detail);
        }
        st = ag_ops_each_since(db, model, since, AG_LIVE_WELCOME_OPS, collect_op, ops, &err);
        if (st != AG_OK) {
            json_decref(ops);
            return send_problem(s, st, &err);
        }
        more = version - since > AG_LIVE_WELCOME_OPS;
    }

    leave_room(live, s);
    s->model = model;
    s->seen = version;
    snprintf(s->user, sizeof s->user, "%s", user);

    json_t *peers = json_array();
    for (session *o = live->sessions; o; o = o->next) {
        if (o == s || o->model != model)
            continue;
        char peer[32];
        peer_name(o, peer, sizeof peer);
        json_t *state = o->presence ? json_loads(o->presence, 0, NULL) : NULL;
        json_array_append_new(peers, json_pack("{s:s, s:s, s:o}", "peer", peer, "user", o->user,
                                               "state", state ? state : json_null()));
    }
    char you[32];
    peer_name(s, you, sizeof you);
    send_json(s, json_pack("{s:s, s:I, s:I, s:s, s:o, s:b, s:o}", "type", "welcome", "model",
                           (json_int_t)model, "version", (json_int_t)version, "you", you, "ops",
                           ops, "more", more, "peers", peers));
    broadcast_json(live, model, s,
                   json_pack("{s:s, s:s, s:s}", "type", "join", "peer", you, "user", s->user));
}

static void on_presence(ag_live *live, session *s, json_t *msg)
{
    if (!s->model)
        return send_error(s, AG_ERR_INVALID, "send hello before presence%s", "");
    json_t *state = json_object_get(msg, "state");
    if (!json_is_object(state))
        return send_error(s, AG_ERR_INVALID, "presence needs a \"state\" object%s", "");
    char *text = json_dumps(state, JSON_COMPACT);
    if (!text)
        return;
    if (strlen(text) > AG_LIVE_MAX_PRESENCE) {
        free(text);
        return send_error(s, AG_ERR_TOO_LARGE, "a presence state holds at most 16 KiB%s", "");
    }
    free(s->presence);
    s->presence = text;
    char peer[32];
    peer_name(s, peer, sizeof peer);
    broadcast_json(live, s->model, s,
                   json_pack("{s:s, s:s, s:s, s:O}", "type", "presence", "peer", peer, "user",
                             s->user, "state", state));
}

/* The ack or nack of an op (any thread). */
static json_t *op_reply(ag_app *app, int64_t model, const char *user, uint64_t origin,
                        json_t *msg)
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
        st = ag_error_set(&err, AG_ERR_INVALID, 0, "an op needs \"base\", the version it was made on");
    int64_t version = 0;
    int dup = 0;
    if (st == AG_OK)
        st = ag_modelops_apply(app, model, json_integer_value(jbase), user, cid,
                               json_object_get(msg, "op"), origin, &version, &dup, &err);
    if (st == AG_OK)
        return json_pack("{s:s, s:s, s:I, s:b}", "type", "ack", "cid", cid, "version",
                         (json_int_t)version, "duplicate", dup);
    int64_t current = 0;
    if (st == AG_ERR_STALE) {
        current = err.element;
        err.element = 0;
    } else {
        ag_db *db = ag_app_db(app, NULL);
        ag_model_row row;
        if (db && ag_models_get(db, model, &row, NULL) == AG_OK) {
            current = row.version;
            ag_models_row_clear(&row);
        }
    }
    return json_pack("{s:s, s:o, s:I, s:o}", "type", "nack", "cid",
                     cid ? json_string(cid) : json_null(), "version", (json_int_t)current,
                     "problem", ag_view_problem(st, &err));
}

static void enqueue_work(ag_live *live, session *s, json_t *msg, int preview)
{
    pthread_mutex_lock(&live->work_lock);
    int full = live->work_count >= AG_LIVE_MAX_WORK;
    pthread_mutex_unlock(&live->work_lock);
    if (full && preview)
        return; /* a preview is only worth its newest position: drop it */
    if (full) {
        ag_error err;
        ag_error_set(&err, AG_ERR_BUSY, 0, "too many edits are waiting; send it again later");
        json_t *cid = json_object_get(msg, "cid");
        return send_json(s, json_pack("{s:s, s:O?, s:I, s:o}", "type", "nack", "cid", cid,
                                      "version", (json_int_t)0, "problem",
                                      ag_view_problem(AG_ERR_BUSY, &err)));
    }
    work *w = calloc(1, sizeof *w);
    char peer[32];
    peer_name(s, peer, sizeof peer);
    if (w && (!(w->user = strdup(s->user)) || !(w->peer = strdup(peer)))) {
        free(w->user);
        free(w);
        w = NULL;
    }
    if (!w)
        return send_error(s, AG_ERR_NOMEM, "out of memory%s", "");
    w->session = s->id;
    w->model = s->model;
    w->msg = json_incref(msg);
    w->preview = preview;
    pthread_mutex_lock(&live->work_lock);
    if (live->work_tail)
        live->work_tail->next = w;
    else
        live->work_head = w;
    live->work_tail = w;
    live->work_count++;
    pthread_cond_signal(&live->work_cond);
    pthread_mutex_unlock(&live->work_lock);
}

static void on_op(ag_live *live, session *s, json_t *msg)
{
    if (!s->model)
        return send_error(s, AG_ERR_INVALID, "send hello before ops%s", "");
    const char *kind = json_string_value(json_object_get(json_object_get(msg, "op"), "kind"));
    if (ag_edit_ops_handles(kind) && json_is_string(json_object_get(msg, "cid")))
        return enqueue_work(live, s, msg, 0);
    send_json(s, op_reply(live->app, s->model, s->user, s->id, msg));
}

static double mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
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
                       ? ag_edit_ops_preview(app, model, json_integer_value(jbase),
                                             json_object_get(msg, "op"), &boxes, &solve_ms, &err)
                       : ag_error_set(&err, AG_ERR_INVALID, 0,
                                      "a preview needs \"base\", the version it was made on");
    if (st != AG_OK) {
        int64_t current = st == AG_ERR_STALE ? err.element : 0;
        if (st == AG_ERR_STALE)
            err.element = 0;
        return json_pack("{s:s, s:O?, s:I, s:o}", "type", "preview.error", "base", jbase,
                         "version", (json_int_t)current, "problem", ag_view_problem(st, &err));
    }
    *to_room = 1;
    return json_pack("{s:s, s:s, s:s, s:O, s:o, s:f}", "type", "preview", "peer", peer, "author",
                     user, "base", jbase, "boxes", boxes, "solve_ms", solve_ms);
}

static void run_preview(ag_live *live, session *s, json_t *msg)
{
    s->preview_at = mono_ms();
    enqueue_work(live, s, msg, 1);
}

static void on_preview(ag_live *live, session *s, json_t *msg)
{
    if (!s->model)
        return send_error(s, AG_ERR_INVALID, "send hello before previews%s", "");
    json_t *jm = json_object_get(msg, "model");
    if (jm && (!json_is_integer(jm) || json_integer_value(jm) != s->model))
        return send_error(s, AG_ERR_INVALID,
                          "a preview is for the model of the connection's room%s", "");
    double wait = s->preview_at + 1000.0 / AG_LIVE_PREVIEW_HZ - mono_ms();
    if (wait <= 0 && !s->preview_next)
        return run_preview(live, s, msg);
    /* too soon: keep the newest, solve it when its turn comes */
    if (!s->preview_next)
        lws_set_timer_usecs(s->wsi, wait > 0 ? (lws_usec_t)(wait * 1000) : 1);
    json_decref(s->preview_next);
    s->preview_next = json_incref(msg);
}

static void on_preview_end(ag_live *live, session *s)
{
    if (!s->model)
        return;
    json_decref(s->preview_next);
    s->preview_next = NULL;
    char peer[32];
    peer_name(s, peer, sizeof peer);
    broadcast_json(live, s->model, s,
                   json_pack("{s:s, s:s, s:s}", "type", "preview.end", "peer", peer, "author",
                             s->user));
}

static int job_finished(const char *status)
{
    return strcmp(status, "succeeded") == 0 || strcmp(status, "failed") == 0 ||
           strcmp(status, "cancelled") == 0;
}

/* job.progress or job.done from a job resource. */
static json_t *job_message(const json_t *job)
{
    const char *status = json_string_value(json_object_get(job, "status"));
    if (!status)
        return NULL;
    if (job_finished(status))
        return json_pack("{s:s, s:O, s:s, s:O, s:O}", "type", "job.done", "job",
                         json_object_get(job, "id"), "status", status, "result",
                         json_object_get(job, "result"), "error", json_object_get(job, "error"));
    return json_pack("{s:s, s:O, s:s, s:O, s:O}", "type", "job.progress", "job",
                     json_object_get(job, "id"), "status", status, "progress",
                     json_object_get(job, "progress"), "stage", json_object_get(job, "stage"));
}

static void on_watch(ag_live *live, session *s, json_t *msg)
{
    json_t *jjob = json_object_get(msg, "job");
    if (!json_is_integer(jjob) || json_integer_value(jjob) < 1)
        return send_error(s, AG_ERR_INVALID, "watch needs \"job\", a job id%s", "");
    ag_error err;
    ag_db *db = ag_app_db(live->app, &err);
    if (!db)
        return send_problem(s, err.code, &err);
    ag_job_row row;
    int64_t id = json_integer_value(jjob);
    ag_status st = ag_jobs_get(db, id, &row, &err);
    if (st != AG_OK)
        return send_problem(s, st, &err);
    json_t *view = ag_view_job(&row);
    int done = job_finished(row.status);
    double progress = row.progress;
    ag_jobs_row_clear(&row);
    if (!done) {
        int slot = -1;
        for (int i = 0; i < s->nwatch; i++)
            if (s->watch[i] == id)
                slot = i;
        if (slot < 0 && s->nwatch >= AG_LIVE_MAX_WATCH) {
            json_decref(view);
            return send_error(s, AG_ERR_BUSY, "a connection watches at most 16 jobs at once%s", "");
        }
        if (slot < 0) {
            slot = s->nwatch++;
            s->watch[slot] = id;
        }
        /* Events queued before this snapshot may still arrive: older progress is dropped. */
        s->watch_progress[slot] = progress;
    }
    send_json(s, job_message(view));
    json_decref(view);
}

static void on_message(ag_live *live, session *s)
{
    if (s->rx_overflow) {
        char limit[32];
        snprintf(limit, sizeof limit, "%u", AG_LIVE_MAX_MESSAGE);
        return send_error(s, AG_ERR_TOO_LARGE, "a message holds at most %s bytes", limit);
    }
    if (s->rx_binary)
        return send_error(s, AG_ERR_INVALID, "messages are JSON text frames, not binary%s", "");
    json_error_t je;
    json_t *msg = json_loadb(s->rx ? s->rx : "", s->rx_len, 0, &je);
    if (!msg) {
        ag_error err;
        ag_error_set(&err, AG_ERR_INVALID, je.column, "the message is not JSON: %s (column %d)",
                     je.text, je.column);
        return send_problem(s, AG_ERR_INVALID, &err);
    }
    const char *type = json_string_value(json_object_get(msg, "type"));
    if (!json_is_object(msg) || !type)
        send_error(s, AG_ERR_INVALID, "a message is a JSON object with a string \"type\"%s", "");
    else if (strcmp(type, "hello") == 0)
        on_hello(live, s, msg);
    else if (strcmp(type, "op") == 0)
        on_op(live, s, msg);
    else if (strcmp(type, "presence") == 0)
        on_presence(live, s, msg);
    else if (strcmp(type, "watch") == 0)
        on_watch(live, s, msg);
    else if (strcmp(type, "preview") == 0)
        on_preview(live, s, msg);
    else if (strcmp(type, "preview.end") == 0)
        on_preview_end(live, s);
    else
        send_error(s, AG_ERR_INVALID, "unknown message type \"%s\"", type);
    json_decref(msg);
}

/* --- events from the app ------------------------------------------------------------------ */

static void on_event(void *user, const ag_event *ev)
{
    ag_live *live = user;
    pending *p = calloc(1, sizeof *p);
    if (!p)
        return;
    p->kind = ev->kind;
    p->model = ev->model;
    p->version = ev->version;
    p->job = ev->job;
    p->origin = ev->origin;
    p->author = ev->author ? strdup(ev->author) : NULL;
    p->cid = ev->cid ? strdup(ev->cid) : NULL;
    p->json = ev->json ? strdup(ev->json) : NULL;
    pthread_mutex_lock(&live->lock);
    if (live->tail)
        live->tail->next = p;
    else
        live->head = p;
    live->tail = p;
    pthread_mutex_unlock(&live->lock);
    lws_cancel_service(live->context);
}

static void deliver(ag_live *live, pending *p)
{
    if (p->kind == LIVE_TO_SESSION) {
        for (session *s = live->sessions; s; s = s->next)
            if (s->id == p->origin && p->json)
                send_text(s, p->json);
    } else if (p->kind == LIVE_TO_ROOM) {
        if (p->json)
            broadcast(live, p->model, NULL, p->json);
    } else if (p->kind == AG_EVENT_OP) {
        json_t *op = p->json ? json_loads(p->json, 0, NULL) : NULL;
        json_t *msg = json_pack("{s:s, s:I, s:s, s:s, s:o}", "type", "op", "version",
                                (json_int_t)p->version, "author", p->author ? p->author : "",
                                "cid", p->cid ? p->cid : "", "op", op ? op : json_null());
        char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
        json_decref(msg);
        /* A session that joined after the op was committed has it in its welcome already. */
        for (session *s = live->sessions; text && s; s = s->next) {
            if (s->model != p->model || p->version <= s->seen)
                continue;
            s->seen = p->version;
            if (s->id != p->origin)
                send_text(s, text);
        }
        free(text);
    } else if (p->kind == AG_EVENT_JOB) {
        json_t *job = p->json ? json_loads(p->json, 0, NULL) : NULL;
        json_t *msg = job ? job_message(job) : NULL;
        char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
        int done = job && job_finished(json_string_value(json_object_get(job, "status")) ?: "");
        double progress = json_number_value(json_object_get(job, "progress"));
        for (session *s = live->sessions; text && s; s = s->next) {
            for (int i = 0; i < s->nwatch; i++) {
                if (s->watch[i] != p->job)
                    continue;
                if (done) {
                    send_text(s, text);
                    s->nwatch--;
                    s->watch[i] = s->watch[s->nwatch];
                    s->watch_progress[i] = s->watch_progress[s->nwatch];
                } else if (progress > s->watch_progress[i]) {
                    send_text(s, text);
                    s->watch_progress[i] = progress;
                }
                break;
            }
        }
        free(text);
        json_decref(msg);
        json_decref(job);
    } else if (p->kind == AG_EVENT_MODEL_GONE) {
        for (session *s = live->sessions; s; s = s->next) {
            if (s->model != p->model)
                continue;
            s->model = 0;
            send_json(s, json_pack("{s:s, s:I}", "type", "gone", "model", (json_int_t)p->model));
        }
    }
}

static void free_work(work *w)
{
    json_decref(w->msg);
    free(w->user);
    free(w->peer);
    free(w);
}

static void *worker_main(void *arg)
{
    ag_live *live = arg;
    for (;;) {
        pthread_mutex_lock(&live->work_lock);
        while (!live->work_head && !live->work_stop)
            pthread_cond_wait(&live->work_cond, &live->work_lock);
        work *w = live->work_head;
        int stop = live->work_stop;
        if (w && !(live->work_head = w->next))
            live->work_tail = NULL;
        if (w)
            live->work_count--;
        pthread_mutex_unlock(&live->work_lock);
        if (!w)
            break;
        if (!stop) {
            int to_room = 0;
            json_t *reply = w->preview ? preview_message(live->app, w->model, w->user, w->peer,
                                                         w->msg, &to_room)
                                       : op_reply(live->app, w->model, w->user, w->session,
                                                  w->msg);
            char *text = reply ? json_dumps(reply, JSON_COMPACT) : NULL;
            json_decref(reply);
            ag_event ev = {.kind = to_room ? LIVE_TO_ROOM : LIVE_TO_SESSION,
                           .model = w->model,
                           .json = text,
                           .origin = w->session};
            if (text)
                on_event(live, &ev);
            free(text);
        }
        free_work(w);
    }
    return NULL;
}

static void drain_events(ag_live *live)
{
    pthread_mutex_lock(&live->lock);
    pending *p = live->head;
    live->head = live->tail = NULL;
    pthread_mutex_unlock(&live->lock);
    while (p) {
        pending *next = p->next;
        deliver(live, p);
        free(p->author);
        free(p->cid);
        free(p->json);
        free(p);
        p = next;
    }
}

/* --- libwebsockets plumbing --------------------------------------------------------------- */

static int on_lws(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                  size_t len)
{
    struct lws_context *ctx = lws_get_context(wsi);
    ag_live *live = ctx ? lws_context_user(ctx) : NULL;
    session *s = user;
    switch (reason) {
    case LWS_CALLBACK_ESTABLISHED:
        s->wsi = wsi;
        s->id = ++live->next_id;
        s->next = live->sessions;
        if (live->sessions)
            live->sessions->prev = s;
        live->sessions = s;
        break;
    case LWS_CALLBACK_RECEIVE:
        if (lws_is_first_fragment(wsi)) {
            s->rx_len = 0;
            s->rx_overflow = 0;
            s->rx_binary = lws_frame_is_binary(wsi);
        }
        if (!s->rx_overflow) {
            if (s->rx_len + len > AG_LIVE_MAX_MESSAGE) {
                s->rx_overflow = 1;
                free(s->rx);
                s->rx = NULL;
                s->rx_len = 0;
            } else {
                char *grown = realloc(s->rx, s->rx_len + len + 1);
                if (!grown)
                    return -1;
                s->rx = grown;
                memcpy(s->rx + s->rx_len, in, len);
                s->rx_len += len;
            }
        }
        if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0) {
            on_message(live, s);
            free(s->rx);
            s->rx = NULL;
            s->rx_len = 0;
            s->rx_overflow = 0;
        }
        break;
    case LWS_CALLBACK_SERVER_WRITEABLE: {
        if (s->closing) {
            lws_close_reason(wsi, LWS_CLOSE_STATUS_POLICY_VIOLATION,
                             (unsigned char *)"too many unread messages", 24);
            return -1;
        }
        outmsg *m = s->out_head;
        if (!m)
            break;
        if (lws_write(wsi, m->data + LWS_PRE, m->len, LWS_WRITE_TEXT) < (int)m->len)
            return -1;
        s->out_head = m->next;
        if (!s->out_head)
            s->out_tail = NULL;
        s->out_count--;
        free(m);
        if (s->out_head)
            lws_callback_on_writable(wsi);
        break;
    }
    case LWS_CALLBACK_CLOSED:
        leave_room(live, s);
        if (s->prev)
            s->prev->next = s->next;
        else if (live->sessions == s)
            live->sessions = s->next;
        if (s->next)
            s->next->prev = s->prev;
        while (s->out_head) {
            outmsg *next = s->out_head->next;
            free(s->out_head);
            s->out_head = next;
        }
        free(s->rx);
        free(s->presence);
        json_decref(s->preview_next);
        memset(s, 0, sizeof *s);
        break;
    case LWS_CALLBACK_TIMER:
        if (s->preview_next) {
            json_t *msg = s->preview_next;
            s->preview_next = NULL;
            if (s->model)
                run_preview(live, s, msg);
            json_decref(msg);
        }
        break;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        if (live)
            drain_events(live);
        break;
    default:
        break;
    }
    return 0;
}

static const struct lws_protocols protocols[] = {
    {"archgram", on_lws, sizeof(session), 64 * 1024, 0, NULL, 0},
    {NULL, NULL, 0, 0, 0, NULL, 0},
};

static void *service_main(void *arg)
{
    ag_live *live = arg;
    while (!atomic_load(&live->stop))
        if (lws_service(live->context, 0) < 0)
            break;
    return NULL;
}

/* Lets the worker finish what it is computing, drops what waits, joins it. */
static void stop_worker(ag_live *live)
{
    pthread_mutex_lock(&live->work_lock);
    live->work_stop = 1;
    pthread_cond_signal(&live->work_cond);
    pthread_mutex_unlock(&live->work_lock);
    if (live->worker_started)
        pthread_join(live->worker, NULL);
    live->worker_started = 0;
    for (work *w = live->work_head, *next; w; w = next) {
        next = w->next;
        free_work(w);
    }
    live->work_head = live->work_tail = NULL;
}

static void log_lws(int level, const char *line)
{
    (void)level;
    fprintf(stderr, "archgramd: websocket: %s", line);
}

ag_status ag_live_start(ag_app *app, const ag_live_options *opt, ag_live **out, ag_error *err)
{
    *out = NULL;
    ag_live *live = calloc(1, sizeof *live);
    if (!live)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    live->app = app;
    pthread_mutex_init(&live->lock, NULL);
    pthread_mutex_init(&live->work_lock, NULL);
    pthread_cond_init(&live->work_cond, NULL);
    lws_set_log_level(LLL_ERR, log_lws);
    struct lws_context_creation_info info;
    memset(&info, 0, sizeof info);
    info.port = opt->port;
    info.iface = opt->bind ? opt->bind : "127.0.0.1";
    info.protocols = protocols;
    info.user = live;
    info.gid = (gid_t)-1;
    info.uid = (uid_t)-1;
    info.options = LWS_SERVER_OPTION_DISABLE_IPV6 | LWS_SERVER_OPTION_VALIDATE_UTF8;
    live->context = lws_create_context(&info);
    if (!live->context) {
        pthread_mutex_destroy(&live->lock);
        pthread_mutex_destroy(&live->work_lock);
        pthread_cond_destroy(&live->work_cond);
        free(live);
        return ag_error_set(err, AG_ERR_IO, 0,
                            "cannot listen for websockets on %s:%d (is the port in use?)",
                            opt->bind ? opt->bind : "127.0.0.1", opt->port);
    }
    ag_events_subscribe(ag_app_events(app), on_event, live);
    live->worker_started = pthread_create(&live->worker, NULL, worker_main, live) == 0;
    if (!live->worker_started ||
        pthread_create(&live->thread, NULL, service_main, live) != 0) {
        stop_worker(live);
        ag_events_unsubscribe(ag_app_events(app), on_event, live);
        lws_context_destroy(live->context);
        pthread_mutex_destroy(&live->lock);
        pthread_mutex_destroy(&live->work_lock);
        pthread_cond_destroy(&live->work_cond);
        free(live);
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot start the websocket threads");
    }
    *out = live;
    return AG_OK;
}

void ag_live_stop(ag_live *live)
{
    if (!live)
        return;
    stop_worker(live);
    ag_events_unsubscribe(ag_app_events(live->app), on_event, live);
    atomic_store(&live->stop, 1);
    lws_cancel_service(live->context);
    pthread_join(live->thread, NULL);
    lws_context_destroy(live->context);
    pending *p = live->head;
    while (p) {
        pending *next = p->next;
        free(p->author);
        free(p->cid);
        free(p->json);
        free(p);
        p = next;
    }
    pthread_mutex_destroy(&live->lock);
    pthread_mutex_destroy(&live->work_lock);
    pthread_cond_destroy(&live->work_cond);
    free(live);
}
