/* The live layer: websocket rooms per model on their own port (libwebsockets), fed by the
 * app's event bus. The protocol is documented in schema/websocket.md; its handlers are in
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
} ag_live_options;

ag_status ag_live_start(ag_app *app, const ag_live_options *opt, ag_live **out, ag_error *err);
/* Closes every connection and stops the service thread. */
void ag_live_stop(ag_live *live);

#endif
