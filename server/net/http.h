/* The REST server (libmicrohttpd): routes /api/v1 to the handlers and serves the web client. */
#ifndef AG_HTTP_H
#define AG_HTTP_H

#include <stddef.h>

#include "../app/app.h"

typedef struct ag_http ag_http;

typedef struct {
    const char *bind;    /* NULL = 127.0.0.1 */
    int port;
    int ws_port;         /* reported by /api/v1/health */
    const char *web_dir; /* NULL: no web client */
    size_t max_body;     /* 0 = 512 MiB */
    int threads;         /* 0 = 2 × cores, at least 4 */
} ag_http_options;

ag_status ag_http_start(ag_app *app, const ag_http_options *opt, ag_http **out, ag_error *err);
/* Stops accepting and waits for the request threads. */
void ag_http_stop(ag_http *http);

#endif
