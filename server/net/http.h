/* The REST server (libmicrohttpd): routes /api/v1 to the handlers and serves the web client.
 * Every route's need (routes.h) is checked before its body is read: the caller's bearer token
 * (401 without one: so a cross-site form or text/plain POST, which cannot send the header,
 * changes nothing), then its account role or its role on the model. CORS is off unless
 * origins are allowed; preflight requests (OPTIONS) are answered here. */
#ifndef AG_HTTP_H
#define AG_HTTP_H

#include <stddef.h>

#include "../app/app.h"
#include "ratelimit.h"
#include "request.h"

typedef struct ag_http ag_http;

typedef struct {
    const char *bind;    /* NULL = 127.0.0.1 */
    int port;
    int ws_port;         /* reported by /api/v1/health */
    const char *web_dir; /* NULL: no web client */
    size_t max_body;     /* 0 = 512 MiB */
    int threads;         /* 0 = 2 × cores, at least 4 */
    /* rate limits per client (net/ratelimit.h; rate 0: none) */
    ag_rate rest_rate;   /* every request */
    ag_rate job_rate;    /* requests that submit a job (uploads, proceduralize, extrusions) */
    ag_rate_key_fn rate_key; /* NULL: by client address */
    /* slow and many clients */
    unsigned max_connections;  /* 0 = 4096 */
    unsigned max_per_address;  /* open connections of one client address; 0 = 64 */
    double header_timeout;     /* seconds to send a request's headers; 0 = 10 */
    unsigned idle_timeout;     /* seconds a connection may stay silent; 0 = 60 */
    int no_auth;         /* no accounts: everyone is the local admin; refused unless bind is a
                            loopback address */
    const char *const *cors; /* origins a browser may call the API from ("*": any); copied */
    int ncors;
} ag_http_options;

/* Is addr (IPv4 text; NULL = the default) a loopback address (127.0.0.0/8)? */
int ag_http_is_loopback(const char *addr);

ag_status ag_http_start(ag_app *app, const ag_http_options *opt, ag_http **out, ag_error *err);
/* Stops accepting connections; the open ones are still served (a shutdown answers what
 * waits on the task lanes before the request threads go). */
void ag_http_quiesce(ag_http *http);
/* Stops accepting and waits for the request threads. Call it once no task works for a
 * request (ag_app_shutdown returned 1). */
void ag_http_stop(ag_http *http);

#endif
