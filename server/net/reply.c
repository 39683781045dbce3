#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "../app/app_query.h"
#include "../app/problem.h"
#include "request.h"

void ag_reply_header(ag_request *r, const char *name, const char *value)
{
    int n = r->nheaders;
    if (n >= (int)(sizeof r->headers / sizeof r->headers[0]))
        return;
    snprintf(r->headers[n].name, sizeof r->headers[n].name, "%s", name);
    snprintf(r->headers[n].value, sizeof r->headers[n].value, "%s", value);
    r->nheaders++;
}

static enum MHD_Result queue(ag_request *r, unsigned status, struct MHD_Response *resp,
                            const char *content_type, const char *etag)
{
    if (!resp)
        return MHD_NO;
    if (content_type)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
    if (etag) {
        MHD_add_response_header(resp, MHD_HTTP_HEADER_ETAG, etag);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    } else if (strncmp(r->url, "/api/", 5) == 0) {
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    }
    if (r->origin[0]) {
        MHD_add_response_header(resp, MHD_HTTP_HEADER_ACCESS_CONTROL_ALLOW_ORIGIN, r->origin);
        MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                                "ETag, Location, Retry-After, WWW-Authenticate, X-Archgram-Failing-Faces");
    }
    if (r->cfg && r->cfg->ncors && strncmp(r->url, "/api/", 5) == 0)
        MHD_add_response_header(resp, MHD_HTTP_HEADER_VARY, "Origin");
    for (int i = 0; i < r->nheaders; i++)
        MHD_add_response_header(resp, r->headers[i].name, r->headers[i].value);
    r->nheaders = 0;
    enum MHD_Result rc = MHD_queue_response(r->conn, status, resp);
    MHD_destroy_response(resp);
    return rc;
}

enum MHD_Result ag_reply_bytes(ag_request *r, unsigned status, const char *content_type,
                               void *data, size_t len, const char *etag)
{
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(len, data ? data : (void *)"", data ? MHD_RESPMEM_MUST_FREE
                                                                            : MHD_RESPMEM_PERSISTENT);
    return queue(r, status, resp, content_type, etag);
}

enum MHD_Result ag_reply_json(ag_request *r, unsigned status, json_t *body, const char *etag)
{
    char *text = body ? json_dumps(body, JSON_COMPACT) : NULL;
    json_decref(body);
    if (!text) {
        ag_error e;
        ag_error_set(&e, AG_ERR_NOMEM, 0, "out of memory writing the answer");
        return ag_reply_problem(r, AG_ERR_NOMEM, &e);
    }
    return ag_reply_bytes(r, status, "application/json", text, strlen(text), etag);
}

enum MHD_Result ag_reply_problem(ag_request *r, ag_status s, const ag_error *err)
{
    char *text = ag_problem_text(s, err);
    if (s == AG_ERR_UNAUTHORIZED)
        ag_reply_header(r, MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"archgram\"");
    if (text)
        return ag_reply_bytes(r, (unsigned)ag_status_http(s), "application/problem+json", text,
                              strlen(text), NULL);
    /* out of memory: still an answer, built without allocating */
    char fallback[AG_PROBLEM_FALLBACK_MAX];
    size_t n = ag_problem_fallback(s, fallback, sizeof fallback);
    return queue(r, (unsigned)ag_status_http(s),
                 MHD_create_response_from_buffer(n, fallback, MHD_RESPMEM_MUST_COPY),
                 "application/problem+json", NULL);
}

enum MHD_Result ag_reply_empty(ag_request *r, unsigned status, const char *etag)
{
    struct MHD_Response *resp = MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    return queue(r, status, resp, NULL, etag);
}

enum MHD_Result ag_reply_job(ag_request *r, int64_t job, unsigned status)
{
    ag_error err;
    json_t *body = NULL;
    ag_status s = ag_app_query_job(r->cfg->app, job, &body, NULL, &err);
    if (s != AG_OK)
        return ag_reply_problem(r, s, &err);
    if (status == 202) {
        char location[64];
        snprintf(location, sizeof location, "/api/v1/jobs/%lld", (long long)job);
        ag_reply_header(r, MHD_HTTP_HEADER_LOCATION, location);
    }
    return ag_reply_json(r, status, body, NULL);
}

enum MHD_Result ag_reply_new_job(ag_request *r, ag_status s, int64_t job, const ag_error *err)
{
    return s == AG_OK ? ag_reply_job(r, job, 202) : ag_reply_problem(r, s, err);
}

const char *ag_request_author(ag_request *r)
{
    return r->who.name;
}

const char *ag_request_bearer(const char *authorization)
{
    if (!authorization || strncasecmp(authorization, "Bearer ", 7) != 0)
        return NULL;
    const char *token = authorization + 7;
    while (*token == ' ')
        token++;
    return *token ? token : NULL;
}

void ag_request_fresh_cid(const char *prefix, char *buf, size_t len)
{
    static atomic_ullong counter;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    snprintf(buf, len, "%s-%lld%09ld-%llu", prefix, (long long)ts.tv_sec, ts.tv_nsec,
             (unsigned long long)atomic_fetch_add(&counter, 1));
}

int ag_request_none_match(ag_request *r, const char *etag)
{
    const char *header = ag_request_header(r, MHD_HTTP_HEADER_IF_NONE_MATCH);
    if (!header)
        return 0;
    if (strcmp(header, "*") == 0)
        return 1;
    /* A list of tags, possibly weak ("W/"): compare each one's opaque part. */
    size_t n = strlen(etag);
    for (const char *p = header; (p = strstr(p, etag)); p += n)
        if ((p == header || p[-1] == ' ' || p[-1] == ',' || p[-1] == '/') &&
            (p[n] == '\0' || p[n] == ',' || p[n] == ' '))
            return 1;
    return 0;
}

void ag_request_address_key(ag_request *r, char *buf, size_t len)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    char addr[INET6_ADDRSTRLEN] = "?";
    const struct sockaddr *sa = ci ? ci->client_addr : NULL;
    if (sa && sa->sa_family == AF_INET)
        inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, addr, sizeof addr);
    else if (sa && sa->sa_family == AF_INET6)
        inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, addr, sizeof addr);
    snprintf(buf, len, "addr:%s", addr);
}

void ag_request_rate_key(ag_request *r, char *buf, size_t len)
{
    if (r->cfg->rate_key)
        r->cfg->rate_key(r, buf, len);
    else if (r->who.user) /* signed in: the account's budget, wherever it calls from */
        snprintf(buf, len, "user:%lld", (long long)r->who.user);
    else
        ag_request_address_key(r, buf, len);
}

const char *ag_request_query(ag_request *r, const char *name)
{
    return MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, name);
}

ag_status ag_request_query_int(ag_request *r, const char *name, long long lo, long long hi,
                               long long def, long long *out, ag_error *err)
{
    const char *v = ag_request_query(r, name);
    if (!v) {
        *out = def;
        return AG_OK;
    }
    char *end;
    long long n = strtoll(v, &end, 10);
    if (!*v || *end || n < lo || n > hi)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s must be a whole number from %lld to %lld",
                            name, lo, hi);
    *out = n;
    return AG_OK;
}

const char *ag_request_header(ag_request *r, const char *name)
{
    return MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, name);
}

ag_status ag_request_json(ag_request *r, json_t **out, ag_error *err)
{
    *out = NULL;
    if (!r->body || r->body_len == 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a JSON body is required");
    json_error_t je;
    json_t *v = json_loadb(r->body, r->body_len, 0, &je);
    if (!v)
        return ag_error_set(err, AG_ERR_INVALID, je.line, "the body is not valid JSON: %s (line %d, column %d)",
                            je.text, je.line, je.column);
    if (!json_is_object(v)) {
        json_decref(v);
        return ag_error_set(err, AG_ERR_INVALID, 0, "the body must be a JSON object");
    }
    *out = v;
    return AG_OK;
}

/* One entity-tag of an If-Match list at *p (RFC 9110: [W/]"etagc*"), or bare digits (an
 * older client's form): 0 when malformed. Sets *strong and the opaque part. */
static int read_etag(const char **p, int *strong, const char **opaque, size_t *len)
{
    const char *c = *p;
    *strong = 1;
    if (c[0] == 'W' && c[1] == '/') {
        *strong = 0;
        c += 2;
    }
    if (*c == '"') {
        const char *start = ++c;
        while ((unsigned char)*c == 0x21 || ((unsigned char)*c >= 0x23 && (unsigned char)*c != 0x7f))
            c++;
        if (*c != '"')
            return 0;
        *opaque = start;
        *len = (size_t)(c - start);
        *p = c + 1;
        return 1;
    }
    if (!*strong || *c < '0' || *c > '9')
        return 0;
    *opaque = c;
    while (*c >= '0' && *c <= '9')
        c++;
    *len = (size_t)(c - *opaque);
    *p = c;
    return 1;
}

ag_status ag_request_if_match(ag_request *r, ag_if_match *m, ag_error *err)
{
    memset(m, 0, sizeof *m);
    const char *h = ag_request_header(r, MHD_HTTP_HEADER_IF_MATCH);
    if (!h)
        return ag_error_set(err, AG_ERR_PRECONDITION_REQUIRED, 0,
                            "send If-Match with the model's ETag (its version) to change it");
    const char *p = h;
    while (*p == ' ' || *p == '\t')
        p++;
    if (p[0] == '*') {
        const char *q = p + 1;
        while (*q == ' ' || *q == '\t')
            q++;
        if (*q == '\0') {
            m->any = 1;
            return AG_OK;
        }
    }
    for (;;) {
        int strong;
        const char *opaque;
        size_t len;
        if (!read_etag(&p, &strong, &opaque, &len))
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "If-Match must be \"*\" or entity tags such as \"3\" (the model's "
                                "ETag)");
        m->tags++;
        /* only a strong tag of digits can be a version (a weak tag never matches If-Match) */
        int digits = strong && len > 0 && len <= 18 && opaque[0] != '0';
        for (size_t i = 0; digits && i < len; i++)
            digits = opaque[i] >= '0' && opaque[i] <= '9';
        if (digits && m->n < sizeof m->versions / sizeof m->versions[0])
            m->versions[m->n++] = strtoll(opaque, NULL, 10);
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0')
            return AG_OK;
        if (*p++ != ',')
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "If-Match holds entity tags separated by commas");
        while (*p == ' ' || *p == '\t' || *p == ',')
            p++;
    }
}

ag_status ag_request_if_match_check(const ag_if_match *m, const char *what, int64_t id,
                                    int64_t current, int64_t *version, ag_error *err)
{
    *version = current;
    if (m->any)
        return AG_OK;
    for (size_t i = 0; i < m->n; i++)
        if (m->versions[i] == current)
            return AG_OK;
    *version = 0;
    if (m->n == 1 && m->tags == 1)
        return ag_error_set(err, AG_ERR_STALE, (long)current,
                            "%s %lld is at version %lld, not %lld", what, (long long)id,
                            (long long)current, (long long)m->versions[0]);
    return ag_error_set(err, AG_ERR_STALE, (long)current,
                        "%s %lld is at version %lld, which If-Match does not name", what,
                        (long long)id, (long long)current);
}
