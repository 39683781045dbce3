#include "live_rooms.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../app/problem.h"

void ag_live_rooms_add(ag_live_rooms *r, ag_live_session *s, struct lws *wsi)
{
    s->wsi = wsi;
    s->id = ++r->next_id;
    s->next = r->sessions;
    if (r->sessions)
        r->sessions->prev = s;
    r->sessions = s;
}

ag_live_session *ag_live_rooms_find(ag_live_rooms *r, uint64_t id)
{
    for (ag_live_session *s = r->sessions; s; s = s->next)
        if (s->id == id)
            return s;
    return NULL;
}

void ag_live_rooms_send(ag_live_session *s, const char *text)
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
    ag_live_outmsg *m = malloc(sizeof *m + LWS_PRE + len);
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

void ag_live_rooms_send_json(ag_live_session *s, json_t *msg)
{
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    if (text)
        ag_live_rooms_send(s, text);
    free(text);
}

void ag_live_rooms_send_problem(ag_live_session *s, ag_status st, const ag_error *err)
{
    json_t *msg = json_pack("{s:s, s:o}", "type", "error", "problem", ag_problem_json(st, err));
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    if (text) {
        ag_live_rooms_send(s, text);
        free(text);
        return;
    }
    /* out of memory: the error still goes out, without its detail */
    char problem[AG_PROBLEM_FALLBACK_MAX], fallback[AG_PROBLEM_FALLBACK_MAX + 32];
    ag_problem_fallback(st, problem, sizeof problem);
    snprintf(fallback, sizeof fallback, "{\"type\":\"error\",\"problem\":%s}", problem);
    ag_live_rooms_send(s, fallback);
}

void ag_live_rooms_send_error(ag_live_session *s, ag_status st, const char *fmt, const char *arg)
{
    ag_error err;
    ag_error_set(&err, st, 0, fmt, arg);
    ag_live_rooms_send_problem(s, st, &err);
}

void ag_live_rooms_peer_name(const ag_live_session *s, char *buf, size_t len)
{
    snprintf(buf, len, "p%llu", (unsigned long long)s->id);
}

void ag_live_rooms_broadcast(ag_live_rooms *r, int64_t model, const ag_live_session *except,
                             const char *text)
{
    for (ag_live_session *s = r->sessions; s; s = s->next)
        if (s->model == model && s != except)
            ag_live_rooms_send(s, text);
}

void ag_live_rooms_broadcast_json(ag_live_rooms *r, int64_t model,
                                  const ag_live_session *except, json_t *msg)
{
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    if (text)
        ag_live_rooms_broadcast(r, model, except, text);
    free(text);
}

void ag_live_rooms_leave(ag_live_rooms *r, ag_live_session *s)
{
    if (!s->model)
        return;
    char peer[32];
    ag_live_rooms_peer_name(s, peer, sizeof peer);
    int64_t model = s->model;
    s->model = 0;
    free(s->presence);
    s->presence = NULL;
    json_decref(s->preview_next);
    s->preview_next = NULL;
    ag_live_rooms_broadcast_json(r, model, s,
                                 json_pack("{s:s, s:s}", "type", "leave", "peer", peer));
}

void ag_live_rooms_remove(ag_live_rooms *r, ag_live_session *s)
{
    ag_live_rooms_leave(r, s);
    if (s->prev)
        s->prev->next = s->next;
    else if (r->sessions == s)
        r->sessions = s->next;
    if (s->next)
        s->next->prev = s->prev;
    while (s->out_head) {
        ag_live_outmsg *next = s->out_head->next;
        free(s->out_head);
        s->out_head = next;
    }
    free(s->rx);
    free(s->presence);
    json_decref(s->preview_next);
    memset(s, 0, sizeof *s);
}

json_t *ag_live_rooms_join(ag_live_rooms *r, ag_live_session *s, int64_t model,
                           int64_t version)
{
    ag_live_rooms_leave(r, s);
    s->model = model;
    s->seen = version;
    snprintf(s->user, sizeof s->user, "%s", s->who.name);
    json_t *peers = json_array();
    for (ag_live_session *o = r->sessions; o; o = o->next) {
        if (o == s || o->model != model)
            continue;
        char peer[32];
        ag_live_rooms_peer_name(o, peer, sizeof peer);
        json_t *state = o->presence ? json_loads(o->presence, 0, NULL) : NULL;
        json_array_append_new(peers, json_pack("{s:s, s:s, s:o}", "peer", peer, "user", o->user,
                                               "state", state ? state : json_null()));
    }
    char you[32];
    ag_live_rooms_peer_name(s, you, sizeof you);
    ag_live_rooms_broadcast_json(
        r, model, s, json_pack("{s:s, s:s, s:s}", "type", "join", "peer", you, "user", s->user));
    return peers;
}

void ag_live_rooms_presence(ag_live_rooms *r, ag_live_session *s, char *state_text,
                            const json_t *state)
{
    free(s->presence);
    s->presence = state_text;
    char peer[32];
    ag_live_rooms_peer_name(s, peer, sizeof peer);
    ag_live_rooms_broadcast_json(r, s->model, s,
                                 json_pack("{s:s, s:s, s:s, s:O}", "type", "presence", "peer",
                                           peer, "user", s->user, "state", state));
}

ag_status ag_live_rooms_watch(ag_live_session *s, int64_t job, double progress, ag_error *err)
{
    int slot = -1;
    for (int i = 0; i < s->nwatch; i++)
        if (s->watch[i] == job)
            slot = i;
    if (slot < 0 && s->nwatch >= AG_LIVE_MAX_WATCH)
        return ag_error_set(err, AG_ERR_BUSY, 0, "a connection watches at most 16 jobs at once");
    if (slot < 0) {
        slot = s->nwatch++;
        s->watch[slot] = job;
    }
    /* Events queued before this snapshot may still arrive: older progress is dropped. */
    s->watch_progress[slot] = progress;
    return AG_OK;
}

static int job_finished(const char *status)
{
    return strcmp(status, "succeeded") == 0 || strcmp(status, "failed") == 0 ||
           strcmp(status, "cancelled") == 0;
}

json_t *ag_live_rooms_job_message(const json_t *job)
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

void ag_live_rooms_deliver_op(ag_live_rooms *r, int64_t model, int64_t version,
                              const char *author, const char *cid, const char *op_json,
                              uint64_t origin)
{
    json_t *op = op_json ? json_loads(op_json, 0, NULL) : NULL;
    json_t *msg = json_pack("{s:s, s:I, s:s, s:s, s:o}", "type", "op", "version",
                            (json_int_t)version, "author", author ? author : "", "cid",
                            cid ? cid : "", "op", op ? op : json_null());
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    json_decref(msg);
    /* A session that joined after the op was committed has it in its welcome already. */
    for (ag_live_session *s = r->sessions; text && s; s = s->next) {
        if (s->model != model || version <= s->seen)
            continue;
        s->seen = version;
        if (s->id != origin)
            ag_live_rooms_send(s, text);
    }
    free(text);
}

void ag_live_rooms_deliver_job(ag_live_rooms *r, int64_t jobid, const char *job_json)
{
    json_t *job = job_json ? json_loads(job_json, 0, NULL) : NULL;
    json_t *msg = job ? ag_live_rooms_job_message(job) : NULL;
    char *text = msg ? json_dumps(msg, JSON_COMPACT) : NULL;
    const char *status = json_string_value(json_object_get(job, "status"));
    int done = status && job_finished(status);
    double progress = json_number_value(json_object_get(job, "progress"));
    for (ag_live_session *s = r->sessions; text && s; s = s->next) {
        for (int i = 0; i < s->nwatch; i++) {
            if (s->watch[i] != jobid)
                continue;
            if (done) {
                ag_live_rooms_send(s, text);
                s->nwatch--;
                s->watch[i] = s->watch[s->nwatch];
                s->watch_progress[i] = s->watch_progress[s->nwatch];
            } else if (progress > s->watch_progress[i]) {
                ag_live_rooms_send(s, text);
                s->watch_progress[i] = progress;
            }
            break;
        }
    }
    free(text);
    json_decref(msg);
    json_decref(job);
}

void ag_live_rooms_deliver_gone(ag_live_rooms *r, int64_t model)
{
    for (ag_live_session *s = r->sessions; s; s = s->next) {
        if (s->model != model)
            continue;
        s->model = 0;
        ag_live_rooms_send_json(s, json_pack("{s:s, s:I}", "type", "gone", "model",
                                             (json_int_t)model));
    }
}

void ag_live_rooms_deliver_access(ag_live_rooms *r, int64_t model,
                                  ag_model_role (*role_of)(void *user, ag_live_session *s),
                                  void *user)
{
    for (ag_live_session *s = r->sessions; s; s = s->next) {
        if (s->model != model)
            continue;
        s->role = role_of(user, s);
        ag_live_rooms_send_json(s, json_pack("{s:s, s:I, s:s}", "type", "access", "model",
                                             (json_int_t)model, "role",
                                             ag_auth_model_role_name(s->role)));
        if (s->role == AG_ROLE_NONE)
            ag_live_rooms_leave(r, s);
    }
}
