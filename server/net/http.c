#include "http.h"

#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "connguard.h"
#include "defer.h"
#include "ratelimit.h"
#include "request.h"
#include "routes.h"
#include "static_files.h"
#include "upload.h"

#define AG_MAX_JSON_BODY (1u << 20)
/* A request line and headers libmicrohttpd keeps in a connection's memory (its own 414/431
 * answers, which are HTML, come only past this); below it archgram answers with problems
 * from the limits that follow. */
#define AG_MHD_MEMORY ((size_t)64 << 10)
#define AG_MAX_URL 8192
#define AG_MAX_HEADERS 16384
/* Distinct clients the rate limiters keep buckets for. */
#define AG_RATE_KEYS 8192
/* How much of a rejected body is read and dropped before the connection is cut. */
#define AG_DISCARD_LIMIT ((size_t)64 << 20)

struct ag_http {
    struct MHD_Daemon *daemon;
    ag_http_config cfg;
    char *web_dir;
    int listen_fd; /* after ag_http_quiesce: the listening socket, closed at the stop */
    ag_ratelimit *rest_limit, *job_limit;
    atomic_size_t abandoned;
    char **cors; /* owned copies of the allowed origins */
};

static void http_free(ag_http *http)
{
    ag_connguard_stop(http->cfg.guard);
    ag_ratelimit_free(http->rest_limit);
    ag_ratelimit_free(http->job_limit);
    for (int i = 0; i < http->cfg.ncors; i++)
        free(http->cors[i]);
    free(http->cors);
    free(http->web_dir);
    free(http);
}

int ag_http_is_loopback(const char *addr)
{
    struct in_addr a;
    if (inet_pton(AF_INET, addr ? addr : "127.0.0.1", &a) != 1)
        return 0;
    return (ntohl(a.s_addr) >> 24) == 127;
}

static int is_read(const char *method)
{
    return strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
}

/* Sets r->origin when the request's Origin is allowed to read the answer. */
static void cors_origin(const ag_http *http, ag_request *r)
{
    const char *origin = ag_request_header(r, "Origin");
    if (!origin || strlen(origin) >= sizeof r->origin)
        return;
    for (int i = 0; i < http->cfg.ncors; i++)
        if (strcmp(http->cfg.cors[i], "*") == 0 || strcmp(http->cfg.cors[i], origin) == 0) {
            snprintf(r->origin, sizeof r->origin, "%s", origin);
            return;
        }
}

/* OPTIONS: a CORS preflight (Access-Control-Request-Method) from an allowed origin gets the
 * methods and headers it may use; any other OPTIONS gets the path's methods in Allow. */
static enum MHD_Result preflight(ag_request *r)
{
    ag_error err;
    char allow[64], name[AG_USER_NAME_MAX + 1];
    const ag_route *route = NULL;
    int64_t ids[2];
    ag_match m = ag_routes_find("OPTIONS", r->url, &route, ids, name, allow, sizeof allow);
    if (m == AG_MATCH_NONE) {
        ag_error_set(&err, AG_ERR_NOT_FOUND, 0, "no resource at %s", r->url);
        return ag_reply_problem(r, AG_ERR_NOT_FOUND, &err);
    }
    const char *want = ag_request_header(r, MHD_HTTP_HEADER_ACCESS_CONTROL_REQUEST_METHOD);
    if (!want) {
        ag_reply_header(r, MHD_HTTP_HEADER_ALLOW, allow);
        return ag_reply_empty(r, 204, NULL);
    }
    if (!r->origin[0]) {
        const char *origin = ag_request_header(r, "Origin");
        ag_error_set(&err, AG_ERR_FORBIDDEN, 0,
                     "origin %.100s may not call this API (archgramd --cors ORIGIN allows one)",
                     origin ? origin : "(none)");
        return ag_reply_problem(r, AG_ERR_FORBIDDEN, &err);
    }
    ag_reply_header(r, MHD_HTTP_HEADER_ACCESS_CONTROL_ALLOW_METHODS, allow);
    ag_reply_header(r, MHD_HTTP_HEADER_ACCESS_CONTROL_ALLOW_HEADERS,
                    "Authorization, Content-Type, If-Match, If-None-Match");
    ag_reply_header(r, MHD_HTTP_HEADER_ACCESS_CONTROL_MAX_AGE, "600");
    return ag_reply_empty(r, 204, NULL);
}

/* Who asks, and may they: the route's need against the bearer token's account. */
static ag_status authorize(const ag_http *http, ag_request *r, ag_error *err)
{
    ag_need need = r->route->need;
    if (need == AG_NEED_NOTHING)
        return AG_OK;
    const char *header = ag_request_header(r, MHD_HTTP_HEADER_AUTHORIZATION);
    if (http->cfg.no_auth) {
        /* No accounts, yet a change still needs the header a cross-site page cannot send. */
        if (!header && !is_read(r->method))
            return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                                "a change needs an Authorization header, even without "
                                "accounts (any Bearer value): a cross-site form cannot send "
                                "one");
        ag_auth_local(&r->who);
    } else {
        if (!header)
            return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                                "sign in: send Authorization: Bearer <token>");
        const char *token = ag_request_bearer(header);
        if (!token)
            return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                                "Authorization must be \"Bearer <token>\"");
        ag_status s = ag_auth_token(http->cfg.app, token, &r->who, err);
        if (s != AG_OK)
            return s;
    }
    return ag_auth_check(http->cfg.app, &r->who, need, r->ids[0], &r->model_role, err);
}

static ag_request *request_new(ag_http *http, struct MHD_Connection *conn, const char *url,
                               const char *method)
{
    ag_request *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->cfg = &http->cfg;
    r->conn = conn;
    r->fd = -1;
    r->url = url;
    r->method = method;
    return r;
}

static void request_free(ag_request *r)
{
    if (!r)
        return;
    free(r->body);
    free(r->answer.body);
    if (r->work_input_free)
        r->work_input_free(r->work_input);
    ag_upload_free(r->upload);
    free(r);
}

static void on_completed(void *cls, struct MHD_Connection *conn, void **con_cls,
                         enum MHD_RequestTerminationCode toe)
{
    ag_http *http = cls;
    (void)toe;
    request_free(*con_cls);
    *con_cls = NULL;
    ag_connguard_request_done(http->cfg.guard, conn); /* the next request's headers are timed */
}

static enum MHD_Result count_header(void *cls, enum MHD_ValueKind kind, const char *key,
                                    const char *value)
{
    (void)kind;
    size_t *n = cls;
    *n += strlen(key) + (value ? strlen(value) : 0) + 4;
    return MHD_YES;
}

/* Takes a token of limit for r: 0 after answering 429 with Retry-After. */
static int within_rate(ag_request *r, ag_ratelimit *limit, const char *what,
                       enum MHD_Result *rc)
{
    char key[96];
    double wait = 0;
    if (!limit)
        return 1;
    ag_request_rate_key(r, key, sizeof key);
    if (ag_ratelimit_take(limit, key, &wait))
        return 1;
    long seconds = (long)wait + ((double)(long)wait < wait);
    if (seconds < 1)
        seconds = 1;
    char retry[24];
    snprintf(retry, sizeof retry, "%ld", seconds);
    ag_reply_header(r, MHD_HTTP_HEADER_RETRY_AFTER, retry);
    ag_error err;
    ag_error_set(&err, AG_ERR_RATE_LIMITED, 0, "too many %s from this client; try again in %ld s",
                 what, seconds);
    *rc = ag_reply_problem(r, AG_ERR_RATE_LIMITED, &err);
    return 0;
}

static ag_status append_body(ag_request *r, const char *data, size_t len, ag_error *err)
{
    if (r->body_len + len > r->cfg->max_json)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "the request body is larger than %zu bytes",
                            r->cfg->max_json);
    if (r->body_len + len + 1 > r->body_cap) {
        size_t cap = r->body_cap ? r->body_cap : 1024;
        while (cap < r->body_len + len + 1)
            cap *= 2;
        char *grown = realloc(r->body, cap);
        if (!grown)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory reading the body");
        r->body = grown;
        r->body_cap = cap;
    }
    memcpy(r->body + r->body_len, data, len);
    r->body_len += len;
    r->body[r->body_len] = '\0';
    return AG_OK;
}

/* First call for a request: route it and check what can be checked before the body. */
static enum MHD_Result begin(ag_http *http, struct MHD_Connection *conn, const char *url,
                             const char *method, void **con_cls)
{
    ag_request *r = request_new(http, conn, url, method);
    if (!r)
        return MHD_NO;
    *con_cls = r;
    ag_connguard_headers_in(http->cfg.guard, conn);
    ag_error err;
    ag_error_clear(&err);
    enum MHD_Result rc;
    if (strncmp(url, "/api/", 5) == 0)
        cors_origin(http, r); /* a 429 to an allowed page is readable by it */
    if (!within_rate(r, http->cfg.rest_limit, "requests", &rc))
        return rc;
    size_t url_len = strlen(url), headers = 0;
    /* the query's arguments count too (libmicrohttpd hands the path alone) */
    MHD_get_connection_values(conn, MHD_GET_ARGUMENT_KIND, count_header, &url_len);
    if (url_len > AG_MAX_URL) {
        ag_error_set(&err, AG_ERR_URI_TOO_LONG, 0, "the URL has %zu bytes; at most %d are taken",
                     url_len, AG_MAX_URL);
        return ag_reply_problem(r, AG_ERR_URI_TOO_LONG, &err);
    }
    MHD_get_connection_values(conn, MHD_HEADER_KIND, count_header, &headers);
    if (headers > AG_MAX_HEADERS) {
        ag_error_set(&err, AG_ERR_HEADERS_TOO_LARGE, 0,
                     "the request headers have %zu bytes; at most %d are taken", headers,
                     AG_MAX_HEADERS);
        return ag_reply_problem(r, AG_ERR_HEADERS_TOO_LARGE, &err);
    }
    /* libmicrohttpd has decoded %-escapes: a path that is not UTF-8 names nothing here */
    if (ag_app_check_utf8("the URL path (after decoding %-escapes)", url, strlen(url), &err) !=
        AG_OK)
        return ag_reply_problem(r, AG_ERR_INVALID, &err);
    if (strncmp(url, "/api/", 5) != 0)
        return MHD_YES; /* static files: answered once the (empty) body is in */

    if (strcmp(method, "OPTIONS") == 0)
        return preflight(r);
    char allow[64];
    ag_match m = ag_routes_find(method, url, &r->route, r->ids, r->name, allow, sizeof allow);
    if (m == AG_MATCH_NONE) {
        ag_error_set(&err, AG_ERR_NOT_FOUND, 0, "no resource at %s", url);
        return ag_reply_problem(r, AG_ERR_NOT_FOUND, &err);
    }
    if (m == AG_MATCH_PATH_ONLY) {
        ag_reply_header(r, MHD_HTTP_HEADER_ALLOW, allow);
        ag_error_set(&err, AG_ERR_METHOD_NOT_ALLOWED, 0, "%s does not accept %s; it accepts %s",
                     url, method, allow);
        return ag_reply_problem(r, AG_ERR_METHOD_NOT_ALLOWED, &err);
    }
    ag_status checked = authorize(http, r, &err);
    if (checked != AG_OK) {
        r->route = NULL; /* a body that still comes is dropped */
        return ag_reply_problem(r, checked, &err);
    }
    if ((r->route->flags & AG_ROUTE_SUBMITS_JOB) &&
        !within_rate(r, http->cfg.job_limit, "job submissions", &rc))
        return rc;
    const char *length = ag_request_header(r, MHD_HTTP_HEADER_CONTENT_LENGTH);
    size_t limit = r->route->body == AG_BODY_UPLOAD ? http->cfg.max_body : http->cfg.max_json;
    if (length && strtoull(length, NULL, 10) > limit) {
        ag_error_set(&err, AG_ERR_TOO_LARGE, 0,
                     "the body has %s bytes; this server accepts at most %zu here", length, limit);
        return ag_reply_problem(r, AG_ERR_TOO_LARGE, &err);
    }
    if (r->route->body == AG_BODY_UPLOAD) {
        ag_status s = ag_upload_begin(r, &r->upload, &err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &err);
    }
    return MHD_YES;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *conn, const char *url,
                                  const char *method, const char *version,
                                  const char *upload_data, size_t *upload_data_size,
                                  void **con_cls)
{
    (void)version;
    ag_http *http = cls;
    if (!*con_cls)
        return begin(http, conn, url, method, con_cls);
    ag_request *r = *con_cls;

    if (*upload_data_size) {
        size_t n = *upload_data_size;
        *upload_data_size = 0;
        if (!r->route)
            return MHD_YES; /* a static file request with a body: ignore it */
        if (r->body_status != AG_OK) {
            /* libmicrohttpd cannot answer while body data is being delivered, so the rest of
             * a rejected body is read and dropped (never stored) and the problem is sent when
             * it ends; a client that keeps sending far past the limit is disconnected. */
            r->discarded += n;
            return r->discarded > AG_DISCARD_LIMIT ? MHD_NO : MHD_YES;
        }
        ag_status s;
        if (r->route->body == AG_BODY_UPLOAD)
            s = ag_upload_feed(r->upload, upload_data, n, &r->body_err);
        else if (r->route->body == AG_BODY_JSON)
            s = append_body(r, upload_data, n, &r->body_err);
        else
            s = AG_OK; /* a body where none is used is ignored */
        if (s != AG_OK) {
            r->body_status = s;
            ag_upload_free(r->upload); /* the spooled part goes at once */
            r->upload = NULL;
        }
        return MHD_YES;
    }

    /* The whole body is in, or a deferred request's work is done. */
    enum MHD_Result rc;
    if (ag_defer_reply(r, &rc))
        return rc;
    if (r->deferred)
        return MHD_YES; /* still working: the task resumes the connection */
    if (strncmp(url, "/api/", 5) != 0)
        return ag_static_serve(r, http->cfg.web_dir);
    if (r->body_status != AG_OK)
        return ag_reply_problem(r, r->body_status, &r->body_err);
    if (r->upload) {
        ag_status s = ag_upload_end(r->upload, &r->body_err);
        if (s != AG_OK)
            return ag_reply_problem(r, s, &r->body_err);
    }
    return r->route->handler(r);
}

static void log_mhd(void *cls, const char *fmt, va_list ap)
{
    (void)cls;
    fputs("archgramd: http: ", stderr);
    vfprintf(stderr, fmt, ap);
}

ag_status ag_http_start(ag_app *app, const ag_http_options *opt, ag_http **out, ag_error *err)
{
    *out = NULL;
    ag_http *http = calloc(1, sizeof *http);
    if (!http)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    http->cfg.app = app;
    http->listen_fd = -1;
    http->cfg.max_body = opt->max_body ? opt->max_body : (size_t)512 << 20;
    http->cfg.max_json = AG_MAX_JSON_BODY;
    http->cfg.ws_port = opt->ws_port;
    if (opt->no_auth && !ag_http_is_loopback(opt->bind)) {
        http_free(http);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "--no-auth only serves a loopback address; %s would let anyone on "
                            "the network in without an account",
                            opt->bind);
    }
    http->cfg.no_auth = opt->no_auth;
    if (opt->ncors > 0 && !(http->cors = calloc((size_t)opt->ncors, sizeof *http->cors))) {
        http_free(http);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (int i = 0; i < opt->ncors; i++, http->cfg.ncors++)
        if (!(http->cors[i] = strdup(opt->cors[i]))) {
            http_free(http);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
    http->cfg.cors = (const char *const *)http->cors;
    if (opt->web_dir) {
        http->web_dir = strdup(opt->web_dir);
        http->cfg.web_dir = http->web_dir;
    }
    struct sockaddr_in addr = {.sin_family = AF_INET, .sin_port = htons((uint16_t)opt->port)};
    if (inet_pton(AF_INET, opt->bind ? opt->bind : "127.0.0.1", &addr.sin_addr) != 1) {
        http_free(http);
        return ag_error_set(err, AG_ERR_INVALID, 0, "--bind %s is not an IPv4 address",
                            opt->bind);
    }
    int threads = opt->threads;
    if (threads <= 0) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        threads = cores > 0 ? (int)cores * 2 : 4;
        if (threads < 4)
            threads = 4;
    }
    http->rest_limit = ag_ratelimit_create(opt->rest_rate, AG_RATE_KEYS);
    http->job_limit = ag_ratelimit_create(opt->job_rate, AG_RATE_KEYS);
    http->cfg.guard = ag_connguard_start(opt->header_timeout > 0 ? opt->header_timeout : 10);
    if (!http->rest_limit || !http->job_limit || !http->cfg.guard) {
        http_free(http);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory starting the HTTP server");
    }
    http->cfg.rest_limit = http->rest_limit;
    http->cfg.job_limit = http->job_limit;
    http->cfg.rate_key = opt->rate_key;
    http->cfg.abandoned = &http->abandoned;
    unsigned max_conns = opt->max_connections ? opt->max_connections : 4096;
    unsigned per_address = opt->max_per_address ? opt->max_per_address : 64;
    unsigned idle = opt->idle_timeout ? opt->idle_timeout : 60;
    http->daemon = MHD_start_daemon(
        MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_EPOLL | MHD_USE_ERROR_LOG |
            MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ITC,
        (uint16_t)opt->port,
        NULL, NULL, on_request, http, MHD_OPTION_EXTERNAL_LOGGER, log_mhd, NULL,
        MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&addr,
        MHD_OPTION_THREAD_POOL_SIZE, (unsigned)threads, MHD_OPTION_NOTIFY_COMPLETED, on_completed,
        http, MHD_OPTION_NOTIFY_CONNECTION, ag_connguard_notify, http->cfg.guard,
        MHD_OPTION_CONNECTION_TIMEOUT, idle, MHD_OPTION_CONNECTION_LIMIT, max_conns,
        MHD_OPTION_PER_IP_CONNECTION_LIMIT, per_address, MHD_OPTION_CONNECTION_MEMORY_LIMIT,
        AG_MHD_MEMORY, MHD_OPTION_LISTENING_ADDRESS_REUSE, (unsigned)1, MHD_OPTION_END);
    if (!http->daemon) {
        int e = errno;
        http_free(http);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot listen on %s:%d: %s",
                            opt->bind ? opt->bind : "127.0.0.1", opt->port,
                            e ? strerror(e) : "the port may be in use");
    }
    *out = http;
    return AG_OK;
}

void ag_http_quiesce(ag_http *http)
{
    if (!http || http->listen_fd >= 0)
        return;
    MHD_socket fd = MHD_quiesce_daemon(http->daemon);
    http->listen_fd = fd == MHD_INVALID_SOCKET ? -2 : (int)fd;
}

void ag_http_stop(ag_http *http)
{
    if (!http)
        return;
    MHD_stop_daemon(http->daemon);
    if (http->listen_fd >= 0)
        close(http->listen_fd);
    http_free(http);
}
