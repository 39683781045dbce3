/* The live layer: websocket rooms per model on their own port (libwebsockets), fed by the
 * app's event bus. The handshake carries the caller's token (an Authorization: Bearer header,
 * or from a browser a second subprotocol "archgram.bearer.<token>"), whose account is the
 * session's identity for good, and an Origin that must be the web client's (the HTTP port on
 * the host the socket was opened on) or one allowed by --cors; other handshakes are refused. The protocol is documented in schema/websocket.md; its handlers are in
 * live_protocol.c, rooms and presence in live_rooms.c, structural ops and previews run on the
 * models' task lanes. Stop the app (ag_app_shutdown, which answers the lanes' waiting work)
 * before the live layer. */
#ifndef AG_LIVE_H
#define AG_LIVE_H

#include "../app/app.h"
#include "ratelimit.h"

typedef struct ag_live ag_live;

typedef struct {
    const char *bind; /* NULL = 127.0.0.1 */
    int port;
    ag_rate message_rate; /* messages per client address (net/ratelimit.h); rate 0: none */
    int http_port;    /* the web client's origin is this port on the host the client named */
    int no_auth;      /* everyone is the local admin (loopback only, see net/http.h) */
    const char *const *origins; /* other origins allowed to connect ("*": any); copied */
    int norigins;
} ag_live_options;

ag_status ag_live_start(ag_app *app, const ag_live_options *opt, ag_live **out, ag_error *err);
/* Closes every connection and stops the service thread. */
void ag_live_stop(ag_live *live);

#endif
