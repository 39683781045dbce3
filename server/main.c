/* archgramd: the archgram service. Parses its flags, opens the store, starts the workers,
 * the REST server and the live (websocket) server, and shuts all down cleanly on
 * SIGINT/SIGTERM: running jobs are cancelled and recorded, the database is closed. */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/app.h"
#include "net/http.h"
#include "net/live.h"

static void usage(FILE *to)
{
    fprintf(to,
            "usage: archgramd [options]\n"
            "\n"
            "The archgram service: REST API under /api/v1, the web client at /, and live\n"
            "collaboration over websockets.\n"
            "\n"
            "options:\n"
            "  --port N         HTTP port (default 8080)\n"
            "  --ws-port N      websocket port (default: the HTTP port + 1)\n"
            "  --bind ADDR      IPv4 address to listen on (default 127.0.0.1)\n"
            "  --db PATH        SQLite database, created on first start (default var/archgram.db)\n"
            "  --workers N      job worker threads (default: the number of cores)\n"
            "  --web DIR        web client folder (default: web/ beside this binary)\n"
            "  --no-web         serve no web client\n"
            "  --max-body BYTES largest accepted upload (default 536870912 = 512 MiB)\n"
            "  --demo           when the database has no model: store two demo buildings (then\n"
            "                   proceduralized by jobs) and extrude a demo street\n"
            "  --help           this text\n"
            "  --version        print the version\n");
}

static int parse_int(const char *flag, const char *text, long long lo, long long hi,
                     long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (errno || !*text || *end || v < lo || v > hi) {
        fprintf(stderr, "archgramd: %s takes a whole number from %lld to %lld, not \"%s\"\n",
                flag, lo, hi, text);
        return -1;
    }
    *out = v;
    return 0;
}

/* The built client lives in build/web next to build/archgramd. */
static char *default_web_dir(const char *argv0)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) {
        if (!argv0)
            return NULL;
        snprintf(self, sizeof self, "%s", argv0);
    } else {
        self[n] = '\0';
    }
    char *slash = strrchr(self, '/');
    if (!slash)
        return NULL;
    *slash = '\0';
    char *dir = NULL;
    if (asprintf(&dir, "%s/web", self) < 0)
        return NULL;
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        free(dir);
        return NULL;
    }
    return dir;
}

int main(int argc, char **argv)
{
    enum { O_PORT = 1, O_WS_PORT, O_BIND, O_DB, O_WORKERS, O_WEB, O_NO_WEB, O_MAX_BODY, O_DEMO,
           O_HELP, O_VERSION };
    static const struct option options[] = {
        {"port", required_argument, NULL, O_PORT},
        {"ws-port", required_argument, NULL, O_WS_PORT},
        {"bind", required_argument, NULL, O_BIND},
        {"db", required_argument, NULL, O_DB},
        {"workers", required_argument, NULL, O_WORKERS},
        {"web", required_argument, NULL, O_WEB},
        {"no-web", no_argument, NULL, O_NO_WEB},
        {"max-body", required_argument, NULL, O_MAX_BODY},
        {"demo", no_argument, NULL, O_DEMO},
        {"help", no_argument, NULL, O_HELP},
        {"version", no_argument, NULL, O_VERSION},
        {NULL, 0, NULL, 0},
    };
    long long port = 8080, ws_port = 0, workers = 0, max_body = 512LL << 20;
    const char *bind = "127.0.0.1", *db = "var/archgram.db", *web = NULL;
    int no_web = 0, demo = 0, opt;
    while ((opt = getopt_long(argc, argv, "", options, NULL)) != -1) {
        switch (opt) {
        case O_PORT: if (parse_int("--port", optarg, 1, 65535, &port)) return 2; break;
        case O_WS_PORT: if (parse_int("--ws-port", optarg, 1, 65535, &ws_port)) return 2; break;
        case O_WORKERS: if (parse_int("--workers", optarg, 1, 256, &workers)) return 2; break;
        case O_MAX_BODY:
            if (parse_int("--max-body", optarg, 1, 1LL << 40, &max_body)) return 2;
            break;
        case O_BIND: bind = optarg; break;
        case O_DB: db = optarg; break;
        case O_WEB: web = optarg; break;
        case O_NO_WEB: no_web = 1; break;
        case O_DEMO: demo = 1; break;
        case O_HELP: usage(stdout); return 0;
        case O_VERSION: printf("archgramd %s\n", AG_VERSION); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "archgramd: unexpected argument \"%s\"\n", argv[optind]);
        usage(stderr);
        return 2;
    }
    if (!ws_port)
        ws_port = port < 65535 ? port + 1 : port - 1;
    if (ws_port == port) {
        fprintf(stderr, "archgramd: --ws-port must differ from --port\n");
        return 2;
    }
    char *web_dir = no_web ? NULL : web ? strdup(web) : default_web_dir(argv[0]);
    if (!no_web && !web_dir)
        fprintf(stderr, "archgramd: no web client found (build it with `make web`); serving "
                        "the API only\n");

    /* Signals are taken by sigwait on the main thread; every other thread inherits the mask. */
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);

    ag_error err;
    ag_error_clear(&err);
    ag_app *app = NULL;
    ag_app_options aopt = {.db_path = db, .workers = (int)workers, .demo = demo};
    if (ag_app_create(&aopt, &app, &err) != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        free(web_dir);
        return 1;
    }
    ag_http *http = NULL;
    ag_http_options hopt = {.bind = bind,
                            .port = (int)port,
                            .ws_port = (int)ws_port,
                            .web_dir = web_dir,
                            .max_body = (size_t)max_body};
    ag_live *live = NULL;
    ag_live_options lopt = {.bind = bind, .port = (int)ws_port};
    if (ag_http_start(app, &hopt, &http, &err) != AG_OK ||
        ag_live_start(app, &lopt, &live, &err) != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        ag_http_stop(http);
        ag_app_shutdown(app);
        ag_app_free(app);
        free(web_dir);
        return 1;
    }
    printf("archgramd: listening on http://%s:%lld/ (websocket ws://%s:%lld/)\n", bind, port, bind,
           ws_port);
    fflush(stdout);

    int sig = 0;
    sigwait(&sigs, &sig);
    fprintf(stderr, "archgramd: %s received, shutting down\n", sig == SIGINT ? "SIGINT" : "SIGTERM");
    /* Order: stop taking requests, then stop the jobs (recorded as cancelled, which the live
     * layer may still announce), then the live layer, then the store. */
    ag_http_stop(http);
    ag_app_shutdown(app);
    ag_live_stop(live);
    ag_app_free(app);
    free(web_dir);
    fprintf(stderr, "archgramd: stopped\n");
    return 0;
}
