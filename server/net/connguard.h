/* Slow clients: a connection gets `header_timeout` seconds to send each request's headers,
 * however slowly the bytes trickle in (libmicrohttpd's own timeout only counts idle time, so
 * a client sending a byte every few seconds would hold its connection forever). A reaper
 * thread shuts down the sockets of connections past their deadline; libmicrohttpd then closes
 * them. With the per-address and total connection limits (libmicrohttpd options set by
 * http.c) this keeps a flood of partial requests from locking other clients out.
 *
 * A connection's clock runs from its start, and again from the end of each request (a
 * keep-alive connection waiting for the next one); it stops when the headers are in (the body
 * and a deferred request's work are not timed here). */
#ifndef AG_CONNGUARD_H
#define AG_CONNGUARD_H

#include <microhttpd.h>
#include <stddef.h>

typedef struct ag_connguard ag_connguard;

/* header_timeout <= 0: connections are counted but never cut. NULL when out of memory or
 * the thread cannot start. */
ag_connguard *ag_connguard_start(double header_timeout);
void ag_connguard_stop(ag_connguard *g);

/* libmicrohttpd's MHD_OPTION_NOTIFY_CONNECTION callback (cls: the guard). */
void ag_connguard_notify(void *cls, struct MHD_Connection *conn, void **socket_context,
                         enum MHD_ConnectionNotificationCode code);
/* The connection's current request has its headers / has ended. */
void ag_connguard_headers_in(ag_connguard *g, struct MHD_Connection *conn);
void ag_connguard_request_done(ag_connguard *g, struct MHD_Connection *conn);

/* Connections open now, and connections cut for being slow since the start. */
size_t ag_connguard_open(ag_connguard *g);
size_t ag_connguard_cut(ag_connguard *g);

#endif
