#include "connguard.h"

#include <pthread.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <time.h>

typedef struct entry {
    struct entry *prev, *next;
    int fd;
    double since;   /* monotonic seconds: when the clock started */
    int waiting;    /* the clock runs: headers are awaited */
    int cut;
} entry;

struct ag_connguard {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    pthread_t thread;
    int stop;
    double timeout;
    entry *head;
    size_t open, cut;
};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Every tenth of the timeout (at most 100 ms): a connection is cut within 10 % of it. */
static void *reaper(void *arg)
{
    ag_connguard *g = arg;
    double period = g->timeout / 10 < 0.1 ? g->timeout / 10 : 0.1;
    if (period < 0.01)
        period = 0.01;
    pthread_mutex_lock(&g->lock);
    while (!g->stop) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        long ns = until.tv_nsec + (long)(period * 1e9);
        until.tv_sec += ns / 1000000000L;
        until.tv_nsec = ns % 1000000000L;
        pthread_cond_timedwait(&g->wake, &g->lock, &until);
        double t = now();
        /* the entry list and the sockets are libmicrohttpd's: an entry leaves the list (under
         * this lock) before its socket is closed, so an fd seen here is still its own */
        for (entry *e = g->head; e && !g->stop; e = e->next)
            if (e->waiting && !e->cut && t - e->since > g->timeout) {
                shutdown(e->fd, SHUT_RDWR);
                e->cut = 1;
                g->cut++;
            }
    }
    pthread_mutex_unlock(&g->lock);
    return NULL;
}

ag_connguard *ag_connguard_start(double header_timeout)
{
    ag_connguard *g = calloc(1, sizeof *g);
    if (!g)
        return NULL;
    g->timeout = header_timeout > 0 ? header_timeout : 0;
    pthread_mutex_init(&g->lock, NULL);
    pthread_cond_init(&g->wake, NULL);
    if (g->timeout && pthread_create(&g->thread, NULL, reaper, g) != 0) {
        pthread_cond_destroy(&g->wake);
        pthread_mutex_destroy(&g->lock);
        free(g);
        return NULL;
    }
    return g;
}

void ag_connguard_stop(ag_connguard *g)
{
    if (!g)
        return;
    pthread_mutex_lock(&g->lock);
    g->stop = 1;
    pthread_cond_signal(&g->wake);
    pthread_mutex_unlock(&g->lock);
    if (g->timeout)
        pthread_join(g->thread, NULL);
    for (entry *e = g->head, *next; e; e = next) {
        next = e->next;
        free(e);
    }
    pthread_cond_destroy(&g->wake);
    pthread_mutex_destroy(&g->lock);
    free(g);
}

void ag_connguard_notify(void *cls, struct MHD_Connection *conn, void **socket_context,
                         enum MHD_ConnectionNotificationCode code)
{
    ag_connguard *g = cls;
    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
        entry *e = calloc(1, sizeof *e);
        const union MHD_ConnectionInfo *ci =
            MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
        if (!e || !ci) {
            free(e);
            *socket_context = NULL;
            return;
        }
        e->fd = ci->connect_fd;
        e->since = now();
        e->waiting = 1;
        pthread_mutex_lock(&g->lock);
        e->next = g->head;
        if (g->head)
            g->head->prev = e;
        g->head = e;
        g->open++;
        pthread_mutex_unlock(&g->lock);
        *socket_context = e;
    } else if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        entry *e = *socket_context;
        if (!e)
            return;
        pthread_mutex_lock(&g->lock);
        if (e->prev)
            e->prev->next = e->next;
        else
            g->head = e->next;
        if (e->next)
            e->next->prev = e->prev;
        g->open--;
        pthread_mutex_unlock(&g->lock);
        free(e);
        *socket_context = NULL;
    }
}

static entry *entry_of(struct MHD_Connection *conn)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return ci ? ci->socket_context : NULL;
}

void ag_connguard_headers_in(ag_connguard *g, struct MHD_Connection *conn)
{
    entry *e = g ? entry_of(conn) : NULL;
    if (!e)
        return;
    pthread_mutex_lock(&g->lock);
    e->waiting = 0;
    pthread_mutex_unlock(&g->lock);
}

void ag_connguard_request_done(ag_connguard *g, struct MHD_Connection *conn)
{
    entry *e = g ? entry_of(conn) : NULL;
    if (!e)
        return;
    pthread_mutex_lock(&g->lock);
    e->waiting = 1;
    e->since = now();
    pthread_mutex_unlock(&g->lock);
}

size_t ag_connguard_open(ag_connguard *g)
{
    pthread_mutex_lock(&g->lock);
    size_t n = g->open;
    pthread_mutex_unlock(&g->lock);
    return n;
}

size_t ag_connguard_cut(ag_connguard *g)
{
    pthread_mutex_lock(&g->lock);
    size_t n = g->cut;
    pthread_mutex_unlock(&g->lock);
    return n;
}
