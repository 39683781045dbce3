/* The live layer's plumbing: the libwebsockets context and its service thread, assembling
 * each connection's messages, writing its outbox, and the pending list through which other
 * threads (the app's event bus, fast-lane answers) hand work to the service thread. Rooms and
 * presence: live_rooms.c; the protocol: live_protocol.c. */
#include "live.h"

#include <jansson.h>
#include <libwebsockets.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "live_protocol.h"
#include "live_rooms.h"
#include "request.h"

typedef enum {
    PENDING_EVENT,      /* an event of the app's bus (ev_kind) */
    PENDING_TO_SESSION, /* text to the session `origin` */
    PENDING_TO_ROOM,    /* text to everyone in the room `model` */
} pending_kind;

typedef struct pending {
    struct pending *next;
    pending_kind kind;
    ag_event_kind ev_kind;
    int64_t model, version, job;
    uint64_t origin;
    char *author, *cid, *json;
} pending;

struct ag_live {
    ag_app *app;
    int http_port, no_auth;
    char **origins; /* owned copies */
    int norigins;
    struct lws_context *context;
    pthread_t thread;
    atomic_int stop;
    pthread_mutex_t lock; /* guards the pending list */
    pending *head, *tail;
    ag_live_rooms rooms;  /* service thread only */
    ag_ratelimit *messages;
};

ag_app *ag__live_app(ag_live *live) { return live->app; }
ag_ratelimit *ag__live_message_limit(ag_live *live) { return live->messages; }
ag_live_rooms *ag__live_rooms(ag_live *live) { return &live->rooms; }

static void pending_free(pending *p)
{
    free(p->author);
    free(p->cid);
    free(p->json);
    free(p);
}

static void post(ag_live *live, pending *p)
{
    pthread_mutex_lock(&live->lock);
    if (live->tail)
        live->tail->next = p;
    else
        live->head = p;
    live->tail = p;
    pthread_mutex_unlock(&live->lock);
    lws_cancel_service(live->context);
}

static void post_text(ag_live *live, pending_kind kind, int64_t model, uint64_t session,
                      const char *text)
{
    pending *p = calloc(1, sizeof *p);
    if (!p || !(p->json = strdup(text))) {
        free(p);
        return;
    }
    p->kind = kind;
    p->model = model;
    p->origin = session;
    post(live, p);
}

void ag__live_post_to_session(ag_live *live, uint64_t session, const char *text)
{
    post_text(live, PENDING_TO_SESSION, 0, session, text);
}

void ag__live_post_to_room(ag_live *live, int64_t model, const char *text)
{
    post_text(live, PENDING_TO_ROOM, model, 0, text);
}

/* Called on the publishing thread: only queues. */
static void on_event(void *user, const ag_event *ev)
{
    ag_live *live = user;
    pending *p = calloc(1, sizeof *p);
    if (!p)
        return;
    p->kind = PENDING_EVENT;
    p->ev_kind = ev->kind;
    p->model = ev->model;
    p->version = ev->version;
    p->job = ev->job;
    p->origin = ev->origin;
    p->author = ev->author ? strdup(ev->author) : NULL;
    p->cid = ev->cid ? strdup(ev->cid) : NULL;
    p->json = ev->json ? strdup(ev->json) : NULL;
    post(live, p);
}

static ag_model_role role_of(void *user, ag_live_session *s)
{
    ag_live *live = user;
    ag_model_role role = AG_ROLE_NONE;
    if (ag_auth_check(live->app, &s->who, AG_NEED_MODEL_VIEWER, s->model, &role, NULL) != AG_OK)
        role = AG_ROLE_NONE;
    return role;
}

static void deliver(ag_live *live, pending *p)
{
    ag_live_rooms *r = &live->rooms;
    if (p->kind == PENDING_TO_SESSION) {
        ag_live_session *s = ag_live_rooms_find(r, p->origin);
        if (s && p->json)
            ag_live_rooms_send(s, p->json);
    } else if (p->kind == PENDING_TO_ROOM) {
        if (p->json)
            ag_live_rooms_broadcast(r, p->model, NULL, p->json);
    } else if (p->ev_kind == AG_EVENT_OP) {
        ag_live_rooms_deliver_op(r, p->model, p->version, p->author, p->cid, p->json, p->origin);
    } else if (p->ev_kind == AG_EVENT_JOB) {
        ag_live_rooms_deliver_job(r, p->job, p->json);
    } else if (p->ev_kind == AG_EVENT_MODEL_GONE) {
        ag_live_rooms_deliver_gone(r, p->model);
    } else if (p->ev_kind == AG_EVENT_ACCESS) {
        ag_live_rooms_deliver_access(r, p->model, role_of, live);
    }
}

static void drain(ag_live *live)
{
    pthread_mutex_lock(&live->lock);
    pending *p = live->head;
    live->head = live->tail = NULL;
    pthread_mutex_unlock(&live->lock);
    while (p) {
        pending *next = p->next;
        deliver(live, p);
        pending_free(p);
        p = next;
    }
}

/* --- the handshake -------------------------------------------------------------------------- */

#define BEARER_PROTOCOL "archgram.bearer."

/* A header's text into buf ("" when absent or longer than buf). */
static const char *header(struct lws *wsi, enum lws_token_indexes h, char *buf, int len)
{
    buf[0] = '\0';
    if (lws_hdr_total_length(wsi, h) >= len || lws_hdr_copy(wsi, buf, len, h) < 0)
        buf[0] = '\0';
    return buf;
}

/* The token of the handshake: Authorization: Bearer, else the subprotocol list's
 * "archgram.bearer.<token>" (a browser cannot set headers on a websocket); NULL when none. */
static const char *handshake_token(struct lws *wsi, char *buf, int len)
{
    const char *bearer = ag_request_bearer(header(wsi, WSI_TOKEN_HTTP_AUTHORIZATION, buf, len));
    if (bearer)
        return bearer;
    header(wsi, WSI_TOKEN_PROTOCOL, buf, len);
    for (char *save = NULL, *item = strtok_r(buf, ",", &save); item;
         item = strtok_r(NULL, ",", &save)) {
        while (*item == ' ')
            item++;
        char *end = item + strlen(item);
        while (end > item && end[-1] == ' ')
            *--end = '\0';
        if (strncmp(item, BEARER_PROTOCOL, strlen(BEARER_PROTOCOL)) == 0)
            return item + strlen(BEARER_PROTOCOL);
    }
    return NULL;
}

/* The default port of an origin's scheme, 0 for schemes a web client is not served over. */
static int scheme_port(const char *scheme, size_t n)
{
    if (n == 4 && strncasecmp(scheme, "http", 4) == 0)
        return 80;
    if (n == 5 && strncasecmp(scheme, "https", 5) == 0)
        return 443;
    return 0;
}

/* Is origin the web client's: scheme://host[:port] with the host the socket was opened on
 * (its Host header without the port) and the HTTP port? */
static int served_origin(const ag_live *live, const char *origin, const char *host)
{
    const char *sep = strstr(origin, "://");
    if (!sep)
        return 0;
    int port = scheme_port(origin, (size_t)(sep - origin));
    const char *ohost = sep + 3, *ocolon = strrchr(ohost, ':');
    if (ocolon && strchr(ocolon, ']'))
        ocolon = NULL; /* an IPv6 literal without a port */
    size_t ohost_len = ocolon ? (size_t)(ocolon - ohost) : strlen(ohost);
    if (ocolon) {
        char *end;
        long p = strtol(ocolon + 1, &end, 10);
        port = *end || p < 1 || p > 65535 ? 0 : (int)p;
    }
    const char *hcolon = strrchr(host, ':');
    if (hcolon && strchr(hcolon, ']'))
        hcolon = NULL;
    size_t host_len = hcolon ? (size_t)(hcolon - host) : strlen(host);
    return port == live->http_port && host_len && ohost_len == host_len &&
           strncasecmp(ohost, host, host_len) == 0 && !strpbrk(ohost, "/?#@");
}

static int origin_allowed(const ag_live *live, struct lws *wsi)
{
    char origin[256], host[256];
    if (lws_hdr_total_length(wsi, WSI_TOKEN_ORIGIN) == 0)
        return 1; /* not a browser: the token alone decides */
    header(wsi, WSI_TOKEN_ORIGIN, origin, sizeof origin);
    header(wsi, WSI_TOKEN_HOST, host, sizeof host);
    if (origin[0] && served_origin(live, origin, host))
        return 1;
    for (int i = 0; origin[0] && i < live->norigins; i++)
        if (strcmp(live->origins[i], "*") == 0 || strcmp(live->origins[i], origin) == 0)
            return 1;
    return 0;
}

/* Before the handshake is answered: a foreign Origin or a missing or unknown token refuses
 * the connection; otherwise the token's account is the session's identity. */
static int admit(ag_live *live, ag_live_session *s, struct lws *wsi)
{
    const char *why = NULL;
    char buf[1024];
    if (!origin_allowed(live, wsi)) {
        why = "origin not allowed";
    } else if (live->no_auth) {
        ag_auth_local(&s->who);
    } else {
        const char *token = handshake_token(wsi, buf, sizeof buf);
        if (!token || ag_auth_token(live->app, token, &s->who, NULL) != AG_OK)
            why = "no valid token";
    }
    if (why) {
        memset(&s->who, 0, sizeof s->who);
        lws_return_http_status(wsi, why[0] == 'o' ? HTTP_STATUS_FORBIDDEN : HTTP_STATUS_UNAUTHORIZED,
                               why);
        return -1;
    }
    snprintf(s->user, sizeof s->user, "%s", s->who.name);
    return 0;
}

/* --- libwebsockets ------------------------------------------------------------------------ */

static int receive(ag_live *live, ag_live_session *s, struct lws *wsi, const void *in, size_t len)
{
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
        ag_live_protocol_message(live, s, s->rx, s->rx_len, s->rx_binary, s->rx_overflow);
        free(s->rx);
        s->rx = NULL;
        s->rx_len = 0;
        s->rx_overflow = 0;
    }
    return 0;
}

static int writable(ag_live_session *s, struct lws *wsi)
{
    if (s->closing) {
        lws_close_reason(wsi, LWS_CLOSE_STATUS_POLICY_VIOLATION,
                         (unsigned char *)"too many unread messages", 24);
        return -1;
    }
    ag_live_outmsg *m = s->out_head;
    if (!m)
        return 0;
    if (lws_write(wsi, m->data + LWS_PRE, m->len, LWS_WRITE_TEXT) < (int)m->len)
        return -1;
    s->out_head = m->next;
    if (!s->out_head)
        s->out_tail = NULL;
    s->out_count--;
    free(m);
    if (s->out_head)
        lws_callback_on_writable(wsi);
    return 0;
}

static int on_lws(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in,
                  size_t len)
{
    struct lws_context *ctx = lws_get_context(wsi);
    ag_live *live = ctx ? lws_context_user(ctx) : NULL;
    ag_live_session *s = user;
    switch (reason) {
    case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
        return live && s ? admit(live, s, wsi) : -1;
    case LWS_CALLBACK_ESTABLISHED: {
        ag_live_rooms_add(&live->rooms, s, wsi);
        char peer[48] = "?";
        lws_get_peer_simple(wsi, peer, sizeof peer);
        /* an account's messages count together, wherever it connects from */
        if (s->who.user)
            snprintf(s->rate_key, sizeof s->rate_key, "user:%lld", (long long)s->who.user);
        else
            snprintf(s->rate_key, sizeof s->rate_key, "addr:%s", peer);
        break;
    }
    case LWS_CALLBACK_RECEIVE:
        return receive(live, s, wsi, in, len);
    case LWS_CALLBACK_SERVER_WRITEABLE:
        return writable(s, wsi);
    case LWS_CALLBACK_CLOSED:
        ag_live_rooms_remove(&live->rooms, s);
        break;
    case LWS_CALLBACK_TIMER:
        ag_live_protocol_timer(live, s);
        break;
    case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
        if (live)
            drain(live);
        break;
    default:
        break;
    }
    return 0;
}

static const struct lws_protocols protocols[] = {
    {"archgram", on_lws, sizeof(ag_live_session), 64 * 1024, 0, NULL, 0},
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

static void log_lws(int level, const char *line)
{
    (void)level;
    fprintf(stderr, "archgramd: websocket: %s", line);
}

static void free_origins(ag_live *live)
{
    for (int i = 0; i < live->norigins; i++)
        free(live->origins[i]);
    free(live->origins);
}

ag_status ag_live_start(ag_app *app, const ag_live_options *opt, ag_live **out, ag_error *err)
{
    *out = NULL;
    ag_live *live = calloc(1, sizeof *live);
    if (!live)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    live->app = app;
    if (!(live->messages = ag_ratelimit_create(opt->message_rate, 8192))) {
        free(live);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    live->http_port = opt->http_port;
    live->no_auth = opt->no_auth;
    if (opt->norigins > 0 && !(live->origins = calloc((size_t)opt->norigins, sizeof *live->origins))) {
        ag_ratelimit_free(live->messages);
        free(live);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (int i = 0; i < opt->norigins; i++, live->norigins++)
        if (!(live->origins[i] = strdup(opt->origins[i]))) {
            free_origins(live);
            ag_ratelimit_free(live->messages);
            free(live);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
    pthread_mutex_init(&live->lock, NULL);
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
        ag_ratelimit_free(live->messages);
        free_origins(live);
        free(live);
        return ag_error_set(err, AG_ERR_IO, 0,
                            "cannot listen for websockets on %s:%d (is the port in use?)",
                            opt->bind ? opt->bind : "127.0.0.1", opt->port);
    }
    ag_events_subscribe(ag_app_events(app), on_event, live);
    if (pthread_create(&live->thread, NULL, service_main, live) != 0) {
        ag_events_unsubscribe(ag_app_events(app), on_event, live);
        lws_context_destroy(live->context);
        pthread_mutex_destroy(&live->lock);
        ag_ratelimit_free(live->messages);
        free_origins(live);
        free(live);
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "cannot start the websocket thread");
    }
    *out = live;
    return AG_OK;
}

void ag_live_stop(ag_live *live)
{
    if (!live)
        return;
    ag_events_unsubscribe(ag_app_events(live->app), on_event, live);
    atomic_store(&live->stop, 1);
    lws_cancel_service(live->context);
    pthread_join(live->thread, NULL);
    lws_context_destroy(live->context);
    for (pending *p = live->head, *next; p; p = next) {
        next = p->next;
        pending_free(p);
    }
    pthread_mutex_destroy(&live->lock);
    ag_ratelimit_free(live->messages);
    free_origins(live);
    free(live);
}
