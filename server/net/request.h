/* One HTTP request as the REST handlers see it, and the ways to answer it. */
#ifndef AG_REQUEST_H
#define AG_REQUEST_H

#include <jansson.h>
#include <microhttpd.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "../app/app.h"
#include "../app/auth.h"
#include "../core/status.h"

struct ag_route;
struct ag_upload;

struct ag_ratelimit;
struct ag_connguard;
struct ag_request;

/* Writes the key a request's rate limits are counted under into buf (len bytes). */
typedef void (*ag_rate_key_fn)(struct ag_request *r, char *buf, size_t len);

typedef struct {
    ag_app *app;
    size_t max_body;     /* uploads */
    size_t max_json;     /* JSON request bodies */
    int ws_port;
    const char *web_dir; /* NULL: no client served */
    struct ag_ratelimit *rest_limit, *job_limit; /* NULL: none */
    ag_rate_key_fn rate_key;                     /* NULL: ag_request_address_key */
    struct ag_connguard *guard;
    atomic_size_t *abandoned; /* deferred requests whose client went away first: their work
                                 was skipped or stopped */
    int no_auth;         /* everyone is the local admin (loopback only) */
    const char *const *cors; /* origins allowed to call the API from a browser ("*": any) */
    int ncors;
} ag_http_config;

/* The answer a deferred request's work made on a task worker (net/defer.h), sent by the
 * HTTP thread when the connection resumes. */
typedef struct {
    int ready;
    ag_status problem;        /* != AG_OK: answer this problem */
    ag_error err;
    unsigned status;
    const char *content_type; /* a string constant */
    void *body;               /* malloc'd */
    size_t len;
    char etag[48];
} ag_defer_answer;

typedef struct ag_request {
    const ag_http_config *cfg;
    struct MHD_Connection *conn;
    const struct ag_route *route;
    const char *method;
    const char *url;
    int64_t ids[2];          /* the {id} segments of the matched route, in order */
    char name[AG_USER_NAME_MAX + 1]; /* its {name} segment, "" when none */
    /* who asks (from the bearer token; the local admin with --no-auth), set before the
     * handler runs for every route that needs more than nothing; and for routes on a model,
     * that account's role on it */
    ag_identity who;
    ag_model_role model_role;
    char origin[256];        /* the Origin header when --cors allows it, else "" */
    /* body */
    char *body;              /* small bodies (JSON), NUL-terminated */
    size_t body_len, body_cap;
    struct ag_upload *upload; /* spooled uploads */
    ag_status body_status;   /* set when receiving the body failed */
    ag_error body_err;
    size_t discarded;        /* bytes of a rejected body dropped so far */
    /* work deferred to a task lane (net/defer.h) */
    int deferred;            /* the connection is suspended while a task works for it */
    int fd;                  /* its socket, to see whether the client is still there */
    void (*work)(struct ag_request *r, ag_task_budget *budget);
    void *work_input;                  /* what the handler parsed for its work, */
    void (*work_input_free)(void *);   /* freed with the request */
    ag_defer_answer answer;
    /* headers for the reply, added by handlers */
    struct {
        char name[32];
        char value[256];
    } headers[8];
    int nheaders;
} ag_request;

typedef enum MHD_Result (*ag_handler)(ag_request *r);

/* Answers; each takes ownership of nothing it is given unless said. */
enum MHD_Result ag_reply_json(ag_request *r, unsigned status, json_t *body /* stolen */,
                              const char *etag);
enum MHD_Result ag_reply_problem(ag_request *r, ag_status s, const ag_error *err);
enum MHD_Result ag_reply_bytes(ag_request *r, unsigned status, const char *content_type,
                               void *data /* stolen, malloc'd */, size_t len, const char *etag);
enum MHD_Result ag_reply_empty(ag_request *r, unsigned status, const char *etag);
/* Adds a header to the next reply of this request (Location, Allow …); copied. */
void ag_reply_header(ag_request *r, const char *name, const char *value);
/* Answers a job just asked for (app/app_jobs.h): 202 Accepted with its Location and view, or
 * the problem s when it could not be queued. */
enum MHD_Result ag_reply_new_job(ag_request *r, ag_status s, int64_t job, const ag_error *err);
/* Answers with job's view; a 202 also names it in Location. */
enum MHD_Result ag_reply_job(ag_request *r, int64_t job, unsigned status);
/* Who makes a change over REST: the name of the caller's account (never a header it sends). */
const char *ag_request_author(ag_request *r);
/* The token of an Authorization header "Bearer <token>" (scheme in any case), NULL when the
 * header is something else. */
const char *ag_request_bearer(const char *authorization);
/* A client id for a REST change that brings none, "<prefix>-…": unique within this process
 * and across restarts (time-based), so the op log's (author, cid) uniqueness holds. */
void ag_request_fresh_cid(const char *prefix, char *buf, size_t len);
/* Does If-None-Match name etag (or "*")? Weak tags ("W/") match by their opaque part. */
int ag_request_none_match(ag_request *r, const char *etag);

/* "addr:<the client's IP address>" into buf: the default rate-limit key. */
void ag_request_address_key(ag_request *r, char *buf, size_t len);
/* The key r's rate limits count under: cfg->rate_key when set, else "user:<id>" once the
 * request is signed in (job submissions are counted after that), else the address (REST
 * requests are counted before it, so a flood of bad tokens is limited too). */
void ag_request_rate_key(ag_request *r, char *buf, size_t len);

/* Query parameter or NULL. */
const char *ag_request_query(ag_request *r, const char *name);
/* A decimal query parameter within [lo, hi]; absent gives def; AG_ERR_INVALID naming it. */
ag_status ag_request_query_int(ag_request *r, const char *name, long long lo, long long hi,
                               long long def, long long *out, ag_error *err);
const char *ag_request_header(ag_request *r, const char *name);
/* The body parsed as a JSON object; AG_ERR_INVALID with the parse position otherwise. */
ag_status ag_request_json(ag_request *r, json_t **out, ag_error *err);

/* Preconditions (RFC 9110 If-Match): "*", or a list of entity tags of which the strong ones
 * made of digits name versions ("3"; bare digits are taken too). */
typedef struct {
    int any;             /* "*" */
    size_t n;            /* versions named */
    int64_t versions[16];
    size_t tags;         /* entity tags in the list, versions or not */
} ag_if_match;
/* AG_ERR_PRECONDITION_REQUIRED when the header is absent, AG_ERR_INVALID when it is not
 * "*" or a list of entity tags. */
ag_status ag_request_if_match(ag_request *r, ag_if_match *m, ag_error *err);
/* *version = current when m matches the resource (`what` id: "model 7", "part 3") at
 * `current`, else AG_ERR_STALE (the current version in err->element), whatever the tags'
 * text ("stale-0" is well-formed and stale). */
ag_status ag_request_if_match_check(const ag_if_match *m, const char *what, int64_t id,
                                    int64_t current, int64_t *version, ag_error *err);

#endif
