/* The live protocol (schema/websocket.md): one table from message type to handler, and the
 * handlers. Fast things (hello, presence, watch, rename and note ops) are answered on the
 * websocket service thread; structural ops and drag previews (rows of the op table with lane
 * AG_OP_STRUCTURAL, app/optable.h) run on the model's task lane (one model's in arrival
 * order, other models' beside them) under the op budget, and
 * their answers come back through the live layer's pending list. */
#ifndef AG_LIVE_PROTOCOL_H
#define AG_LIVE_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#include "../app/app.h"
#include "live_rooms.h"

#define AG_LIVE_MAX_MESSAGE (1u << 20)

typedef struct ag_live ag_live;

/* One whole message of a session (the bytes received; overflow: it was longer than
 * AG_LIVE_MAX_MESSAGE; binary: a binary frame). */
void ag_live_protocol_message(ag_live *live, ag_live_session *s, const char *data, size_t len,
                              int binary, int overflow);
/* The session's preview timer fired: the preview kept waiting is sent to be solved. */
void ag_live_protocol_timer(ag_live *live, ag_live_session *s);

/* The message types, for a test: the i-th type, NULL past the last. */
const char *ag_live_protocol_type(size_t i);

/* Provided by live.c: the app, the rooms, and posting an answer computed on another thread
 * (to one session, or to everyone in a room) to the service thread. */
ag_app *ag__live_app(ag_live *live);
struct ag_ratelimit *ag__live_message_limit(ag_live *live);
ag_live_rooms *ag__live_rooms(ag_live *live);
void ag__live_post_to_session(ag_live *live, uint64_t session, const char *text);
void ag__live_post_to_room(ag_live *live, int64_t model, const char *text);

#endif
