/* Rooms and presence of the live layer: the connections (sessions), the room (model) each is
 * in, the last presence state of each peer, the jobs each watches, and delivering what
 * happened (ops, job progress, a model's end) to the sessions it concerns. Everything here
 * runs on the websocket service thread. */
#ifndef AG_LIVE_ROOMS_H
#define AG_LIVE_ROOMS_H

#include <jansson.h>
#include <libwebsockets.h>
#include <stddef.h>
#include <stdint.h>

#include "../app/auth.h"
#include "../core/status.h"

#define AG_LIVE_MAX_OUTBOX 4096
#define AG_LIVE_MAX_WATCH 16

typedef struct ag_live_outmsg {
    struct ag_live_outmsg *next;
    size_t len;
    unsigned char data[]; /* LWS_PRE bytes of headroom, then the text */
} ag_live_outmsg;

typedef struct ag_live_session {
    struct lws *wsi;
    uint64_t id;
    int64_t model; /* 0: in no room */
    int64_t seen;  /* the newest model version this session has been told of */
    ag_identity who;    /* from the handshake's token, for the session's life */
    ag_model_role role; /* who's role on the room's model, as last checked */
    char user[801];     /* the name the room sees: the account's */
    char rate_key[64];  /* what its message rate counts under: "user:<id>" or "addr:<peer>" */
    char *presence; /* last state, JSON text */
    char *rx;
    size_t rx_len;
    int rx_overflow, rx_binary;
    ag_live_outmsg *out_head, *out_tail;
    size_t out_count;
    int closing;
    int64_t watch[AG_LIVE_MAX_WATCH];
    double watch_progress[AG_LIVE_MAX_WATCH]; /* the last progress sent for that job */
    int nwatch;
    double preview_at;    /* when the last preview was sent to be solved (ms, monotonic) */
    json_t *preview_next; /* the newest preview waiting for its turn */
    struct ag_live_session *prev, *next;
} ag_live_session;

typedef struct {
    ag_live_session *sessions;
    uint64_t next_id;
} ag_live_rooms;

/* A new connection (s zeroed by libwebsockets) / one that closed (its memory is released). */
void ag_live_rooms_add(ag_live_rooms *r, ag_live_session *s, struct lws *wsi);
void ag_live_rooms_remove(ag_live_rooms *r, ag_live_session *s);
ag_live_session *ag_live_rooms_find(ag_live_rooms *r, uint64_t id);

/* Queues text for the session (a client that reads nothing is closed when its outbox is full). */
void ag_live_rooms_send(ag_live_session *s, const char *text);
void ag_live_rooms_send_json(ag_live_session *s, json_t *msg /* stolen */);
void ag_live_rooms_send_problem(ag_live_session *s, ag_status st, const ag_error *err);
/* {"type":"error"} with fmt formatted with one string argument. */
void ag_live_rooms_send_error(ag_live_session *s, ag_status st, const char *fmt, const char *arg);
/* Sends text to everyone in a room but `except` (may be NULL). */
void ag_live_rooms_broadcast(ag_live_rooms *r, int64_t model, const ag_live_session *except,
                             const char *text);
void ag_live_rooms_broadcast_json(ag_live_rooms *r, int64_t model,
                                  const ag_live_session *except, json_t *msg /* stolen */);
/* "p<id>", the name a session has for the others. */
void ag_live_rooms_peer_name(const ag_live_session *s, char *buf, size_t len);

/* Moves s into the room of model (told of versions up to `version`) under its account's
 * name: leaves its old room (announced), returns the others' {"peer","user","state"} and
 * announces the join. */
json_t *ag_live_rooms_join(ag_live_rooms *r, ag_live_session *s, int64_t model,
                           int64_t version);
void ag_live_rooms_leave(ag_live_rooms *r, ag_live_session *s);
/* Keeps s's presence state (JSON text, taken) and shows it to the room. */
void ag_live_rooms_presence(ag_live_rooms *r, ag_live_session *s, char *state_text,
                            const json_t *state);

/* Watches a job not finished yet, from the given progress on. AG_ERR_BUSY beyond
 * AG_LIVE_MAX_WATCH jobs. */
ag_status ag_live_rooms_watch(ag_live_session *s, int64_t job, double progress, ag_error *err);

/* What happened, to the sessions it concerns. */
void ag_live_rooms_deliver_op(ag_live_rooms *r, int64_t model, int64_t version,
                              const char *author, const char *cid, const char *op_json,
                              uint64_t origin);
void ag_live_rooms_deliver_job(ag_live_rooms *r, int64_t job, const char *job_json);
void ag_live_rooms_deliver_gone(ag_live_rooms *r, int64_t model);
/* Who may use model changed: each session in its room gets its role checked again by
 * role_of(user, session) and is told {"type":"access","model","role"}; one left without a role
 * leaves the room. */
void ag_live_rooms_deliver_access(ag_live_rooms *r, int64_t model,
                                  ag_model_role (*role_of)(void *user, ag_live_session *s),
                                  void *user);

/* job.progress or job.done from a job resource (NULL when it has no status). */
json_t *ag_live_rooms_job_message(const json_t *job);

#endif
