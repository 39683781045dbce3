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
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/accounts.h"
#include "app/app.h"
#include "app/extrusion.h"
#include "net/http.h"
#include "net/live.h"
#include "store/db.h"

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
            "\n"
            "bounded work (an op past a limit is refused with 422 too-large before it runs):\n"
            "  --max-triangles N   largest mesh an edit may make or a proceduralization start\n"
            "                      from (default 2000000)\n"
            "  --max-nodes N       most terminals (components) an edit may place (default 200000)\n"
            "  --op-seconds S      time budget of one structural op, grammar edit or drag\n"
            "                      preview (default 60)\n"
            "  --job-seconds S     time budget of one job (default 3600)\n"
            "  --preview-seconds S time budget of one extrusion preview (default 10)\n"
            "  --import-seconds S  time to read one uploaded glTF, PLY, STL, FBX or DAE file\n"
            "                      (default 120)\n"
            "  --task-workers N    threads for ops and previews, one model at a time each\n"
            "                      (default: 2 x cores, at least 4)\n"
            "  --db-max-bytes N    let the database grow to N bytes; changes past it are\n"
            "                      refused with 507 storage-full (default: no limit)\n"
            "  --stop-grace S      on SIGTERM, how long running work may take to stop before\n"
            "                      archgramd exits anyway, recording it as cancelled\n"
            "                      (default 0.5)\n"
            "\n"
            "clients (a rate is PER_SECOND or PER_SECOND/BURST per client address; 0: none;\n"
            "past it: 429 with Retry-After):\n"
            "  --rate-rest R       REST requests (default 200/2000)\n"
            "  --rate-jobs R       job submissions: uploads, proceduralize, extrusions\n"
            "                      (default 1/60)\n"
            "  --rate-ws R         websocket messages (default 200/2000)\n"
            "  --max-connections N          open HTTP connections (default 4096)\n"
            "  --max-connections-per-address N  of one client address (default 64)\n"
            "  --header-timeout S  seconds a client has to send a request's headers\n"
            "                      (default 10)\n"
            "  --idle-timeout S    seconds a connection may stay silent (default 60)\n"
            "accounts (every request but the health check needs an account's API token):\n"
            "  --cors ORIGIN    let web pages of ORIGIN (e.g. https://app.example.org; \"*\" for\n"
            "                   any) call the API and open websockets; repeatable; off by default\n"
            "  --admin-token-file PATH\n"
            "                   the account \"admin\" signs in with the token in PATH (a docker\n"
            "                   secret: 32..256 characters of A-Z a-z 0-9 . _ ~ + -)\n"
            "  --no-auth        no accounts: everyone is a local admin; only with a loopback\n"
            "                   --bind (a change still needs an Authorization header)\n"
            "  --create-user NAME [--role admin|editor|viewer]\n"
            "                   make an account (role editor by default) in --db, print its\n"
            "                   first token, and exit (the service may be running)\n"
            "  --create-token NAME\n"
            "                   print a new token of the account NAME and exit\n"
            "On a first start with no account, archgramd makes the admin account \"admin\" and\n"
            "prints a sign-in link with its token, once.\n"
            "\n"
            "  --extrude-timeout SECONDS\n"
            "                   time budget of one building (and of a preview; default 10;\n"
            "                   0: none): one that takes longer falls back to a flat roof\n"
            "  --extrude-max-events N\n"
            "                   event budget of one building (default 100000 + 4000 per corner)\n"
            "  --extrude-max-memory MB\n"
            "                   memory budget of one building (default 64 + 0.125 per corner)\n"
            "  --extrude-threads N\n"
            "                   threads of one extrusion batch (default: the number of cores)\n"
            "  --help           this text\n"
            "  --version        print the version\n");
}

static int parse_seconds(const char *flag, const char *text, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || !*text || *end || !(v >= lo && v <= hi)) {
        fprintf(stderr, "archgramd: %s takes seconds from %g to %g, not \"%s\"\n", flag, lo, hi,
                text);
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_rate(const char *flag, const char *text, ag_rate *out)
{
    if (ag_ratelimit_parse(text, out) == 0)
        return 0;
    fprintf(stderr, "archgramd: %s takes PER_SECOND or PER_SECOND/BURST (e.g. 200/2000, 0 for "
                    "no limit), not \"%s\"\n",
            flag, text);
    return -1;
}

/* Every connection is a descriptor: the soft limit goes up to the hard one, so the
 * connection limit, not the descriptor limit, is what clients meet. */
static void raise_open_files(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur < rl.rlim_max) {
        rl.rlim_cur = rl.rlim_max > 1048576 ? 1048576 : rl.rlim_max;
        setrlimit(RLIMIT_NOFILE, &rl);
    }
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

#define MAX_CORS 16

/* --admin-token-file: the token, without the line end; NULL with a message when unreadable. */
static char *read_token_file(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "archgramd: cannot read --admin-token-file %s: %s\n", path,
                strerror(errno));
        return NULL;
    }
    char buf[1024];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    int more = fgetc(f) != EOF;
    fclose(f);
    buf[n] = '\0';
    while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r' || buf[n - 1] == ' '))
        buf[--n] = '\0';
    if (more || n == 0 || ag_tokens_check_text(buf, NULL) != AG_OK) {
        fprintf(stderr, "archgramd: --admin-token-file %s must hold one token: 32 to 256 "
                        "characters of A-Z a-z 0-9 . _ ~ + -\n",
                path);
        return NULL;
    }
    return strdup(buf);
}

/* An allowed origin: "*" or scheme://host[:port], nothing after. */
static int check_origin(const char *o)
{
    if (strcmp(o, "*") == 0)
        return 0;
    const char *rest = strncmp(o, "http://", 7) == 0    ? o + 7
                       : strncmp(o, "https://", 8) == 0 ? o + 8
                                                        : NULL;
    if (!rest || !*rest || strpbrk(rest, "/?#@ ")) {
        fprintf(stderr, "archgramd: --cors takes an origin such as https://app.example.org or "
                        "http://localhost:5173 (no path), or *, not \"%s\"\n",
                o);
        return -1;
    }
    return 0;
}

/* --create-user and --create-token: on the database alone (a running service keeps serving
 * it), the token on stdout, what it is on stderr. */
static int account_command(const char *db_path, const char *create_user, const char *role_name,
                           const char *create_token)
{
    ag_error err;
    ag_error_clear(&err);
    ag_account_role role = AG_ACCOUNT_EDITOR;
    if (role_name && ag_users_role_parse(role_name, &role, &err) != AG_OK) {
        fprintf(stderr, "archgramd: --role: %s\n", err.text);
        return 2;
    }
    ag_db *db = NULL;
    if (ag_db_open(db_path, NULL, &db, &err) != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        return 1;
    }
    json_t *view = NULL;
    ag_status s = create_user ? ag_accounts_create_in(db, create_user, role, "command line", &view,
                                                      &err)
                              : ag_accounts_new_token_in(db, create_token, "command line", &view,
                                                         &err);
    ag_db_close(db);
    if (s != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        return 1;
    }
    json_t *user = json_object_get(view, "user");
    fprintf(stderr, "archgramd: %s token of %s (%s); it is shown only now:\n",
            create_user ? "the first" : "a new", json_string_value(json_object_get(user, "name")),
            json_string_value(json_object_get(user, "role")));
    printf("%s\n", json_string_value(json_object_get(view, "token")));
    json_decref(view);
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
           O_HELP, O_VERSION, O_CORS, O_ADMIN_TOKEN_FILE, O_NO_AUTH, O_CREATE_USER, O_ROLE,
           O_CREATE_TOKEN, O_MAX_TRIANGLES, O_MAX_NODES, O_OP_SECONDS, O_JOB_SECONDS,
           O_PREVIEW_SECONDS, O_IMPORT_SECONDS, O_TASK_WORKERS, O_DB_MAX_BYTES, O_STOP_GRACE,
           O_RATE_REST, O_RATE_JOBS, O_RATE_WS, O_MAX_CONNECTIONS, O_MAX_PER_ADDRESS,
           O_HEADER_TIMEOUT, O_IDLE_TIMEOUT, O_EXTRUDE_TIMEOUT, O_EXTRUDE_EVENTS,
           O_EXTRUDE_MEMORY, O_EXTRUDE_THREADS };
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
        {"cors", required_argument, NULL, O_CORS},
        {"admin-token-file", required_argument, NULL, O_ADMIN_TOKEN_FILE},
        {"no-auth", no_argument, NULL, O_NO_AUTH},
        {"create-user", required_argument, NULL, O_CREATE_USER},
        {"role", required_argument, NULL, O_ROLE},
        {"create-token", required_argument, NULL, O_CREATE_TOKEN},
        {"extrude-timeout", required_argument, NULL, O_EXTRUDE_TIMEOUT},
        {"extrude-max-events", required_argument, NULL, O_EXTRUDE_EVENTS},
        {"extrude-max-memory", required_argument, NULL, O_EXTRUDE_MEMORY},
        {"extrude-threads", required_argument, NULL, O_EXTRUDE_THREADS},
        {"help", no_argument, NULL, O_HELP},
        {"version", no_argument, NULL, O_VERSION},
        {"max-triangles", required_argument, NULL, O_MAX_TRIANGLES},
        {"max-nodes", required_argument, NULL, O_MAX_NODES},
        {"op-seconds", required_argument, NULL, O_OP_SECONDS},
        {"job-seconds", required_argument, NULL, O_JOB_SECONDS},
        {"preview-seconds", required_argument, NULL, O_PREVIEW_SECONDS},
        {"task-workers", required_argument, NULL, O_TASK_WORKERS},
        {"db-max-bytes", required_argument, NULL, O_DB_MAX_BYTES},
        {"stop-grace", required_argument, NULL, O_STOP_GRACE},
        {"import-seconds", required_argument, NULL, O_IMPORT_SECONDS},
        {"rate-rest", required_argument, NULL, O_RATE_REST},
        {"rate-jobs", required_argument, NULL, O_RATE_JOBS},
        {"rate-ws", required_argument, NULL, O_RATE_WS},
        {"max-connections", required_argument, NULL, O_MAX_CONNECTIONS},
        {"max-connections-per-address", required_argument, NULL, O_MAX_PER_ADDRESS},
        {"header-timeout", required_argument, NULL, O_HEADER_TIMEOUT},
        {"idle-timeout", required_argument, NULL, O_IDLE_TIMEOUT},
        {NULL, 0, NULL, 0},
    };
    long long port = 8080, ws_port = 0, workers = 0, max_body = 512LL << 20;
    long long max_triangles = 0, max_nodes = 0, task_workers = 0, db_max_bytes = 0;
    double op_seconds = 0, job_seconds = 0, preview_seconds = 0, import_seconds = 0;
    double stop_grace = 0.5;
    ag_rate rate_rest = {200, 2000}, rate_jobs = {1, 60}, rate_ws = {200, 2000};
    long long max_connections = 4096, max_per_address = 64, idle_timeout = 60;
    double header_timeout = 10;
    const char *bind = "127.0.0.1", *db = "var/archgram.db", *web = NULL;
    int no_web = 0, demo = 0, no_auth = 0, ncors = 0, opt;
    const char *cors[MAX_CORS];
    const char *token_file = NULL, *create_user = NULL, *create_token = NULL, *role = NULL;
    ag_extrusion_limits extrude = ag_extrusion_limits_get();
    long long extrude_n = 0;
    while ((opt = getopt_long(argc, argv, "", options, NULL)) != -1) {
        switch (opt) {
        case O_PORT: if (parse_int("--port", optarg, 1, 65535, &port)) return 2; break;
        case O_WS_PORT: if (parse_int("--ws-port", optarg, 1, 65535, &ws_port)) return 2; break;
        case O_WORKERS: if (parse_int("--workers", optarg, 1, 256, &workers)) return 2; break;
        case O_MAX_BODY:
            if (parse_int("--max-body", optarg, 1, 1LL << 40, &max_body)) return 2;
            break;
        case O_MAX_TRIANGLES:
            if (parse_int("--max-triangles", optarg, 1, 1LL << 32, &max_triangles)) return 2;
            break;
        case O_MAX_NODES:
            if (parse_int("--max-nodes", optarg, 1, 1LL << 31, &max_nodes)) return 2;
            break;
        case O_TASK_WORKERS:
            if (parse_int("--task-workers", optarg, 1, 256, &task_workers)) return 2;
            break;
        case O_DB_MAX_BYTES:
            if (parse_int("--db-max-bytes", optarg, 65536, 1LL << 50, &db_max_bytes)) return 2;
            break;
        case O_OP_SECONDS:
            if (parse_seconds("--op-seconds", optarg, 0.01, 86400, &op_seconds)) return 2;
            break;
        case O_JOB_SECONDS:
            if (parse_seconds("--job-seconds", optarg, 0.01, 7 * 86400.0, &job_seconds)) return 2;
            break;
        case O_PREVIEW_SECONDS:
            if (parse_seconds("--preview-seconds", optarg, 0.01, 3600, &preview_seconds)) return 2;
            break;
        case O_IMPORT_SECONDS:
            if (parse_seconds("--import-seconds", optarg, 0.01, 86400, &import_seconds)) return 2;
            break;
        case O_STOP_GRACE:
            if (parse_seconds("--stop-grace", optarg, 0, 60, &stop_grace)) return 2;
            break;
        case O_RATE_REST:
            if (parse_rate("--rate-rest", optarg, &rate_rest)) return 2;
            break;
        case O_RATE_JOBS:
            if (parse_rate("--rate-jobs", optarg, &rate_jobs)) return 2;
            break;
        case O_RATE_WS:
            if (parse_rate("--rate-ws", optarg, &rate_ws)) return 2;
            break;
        case O_MAX_CONNECTIONS:
            if (parse_int("--max-connections", optarg, 1, 1 << 20, &max_connections)) return 2;
            break;
        case O_MAX_PER_ADDRESS:
            if (parse_int("--max-connections-per-address", optarg, 1, 1 << 20, &max_per_address))
                return 2;
            break;
        case O_HEADER_TIMEOUT:
            if (parse_seconds("--header-timeout", optarg, 0.05, 3600, &header_timeout)) return 2;
            break;
        case O_IDLE_TIMEOUT:
            if (parse_int("--idle-timeout", optarg, 1, 86400, &idle_timeout)) return 2;
            break;
        case O_BIND: bind = optarg; break;
        case O_DB: db = optarg; break;
        case O_WEB: web = optarg; break;
        case O_NO_WEB: no_web = 1; break;
        case O_DEMO: demo = 1; break;
        case O_CORS:
            if (check_origin(optarg)) return 2;
            if (ncors == MAX_CORS) {
                fprintf(stderr, "archgramd: at most %d --cors origins\n", MAX_CORS);
                return 2;
            }
            cors[ncors++] = optarg;
            break;
        case O_ADMIN_TOKEN_FILE: token_file = optarg; break;
        case O_NO_AUTH: no_auth = 1; break;
        case O_CREATE_USER: create_user = optarg; break;
        case O_ROLE: role = optarg; break;
        case O_CREATE_TOKEN: create_token = optarg; break;
        case O_EXTRUDE_TIMEOUT: {
            char *end = NULL;
            double v = strtod(optarg, &end);
            if (end == optarg || *end || !(v >= 0 && v <= 1e6)) {
                fprintf(stderr, "archgramd: --extrude-timeout needs seconds (0: none), not "
                                "\"%s\"\n", optarg);
                return 2;
            }
            extrude.seconds = v > 0 ? v : -1;
            break;
        }
        case O_EXTRUDE_EVENTS:
            if (parse_int("--extrude-max-events", optarg, 1, 1LL << 40, &extrude_n)) return 2;
            extrude.max_events = (size_t)extrude_n;
            break;
        case O_EXTRUDE_MEMORY:
            if (parse_int("--extrude-max-memory", optarg, 1, 1LL << 20, &extrude_n)) return 2;
            extrude.max_bytes = (size_t)extrude_n << 20;
            break;
        case O_EXTRUDE_THREADS:
            if (parse_int("--extrude-threads", optarg, 1, 256, &extrude_n)) return 2;
            extrude.threads = (size_t)extrude_n;
            break;
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
    if (create_user && create_token) {
        fprintf(stderr, "archgramd: --create-user and --create-token go one at a time\n");
        return 2;
    }
    if (role && !create_user) {
        fprintf(stderr, "archgramd: --role goes with --create-user\n");
        return 2;
    }
    if (create_user || create_token)
        return account_command(db, create_user, role, create_token);
    if (no_auth && !ag_http_is_loopback(bind)) {
        fprintf(stderr, "archgramd: --no-auth serves only a loopback address (127.x.x.x): "
                        "--bind %s would let anyone on the network in without an account\n",
                bind);
        return 2;
    }
    if (no_auth && token_file) {
        fprintf(stderr, "archgramd: --admin-token-file and --no-auth contradict each other\n");
        return 2;
    }
    char *admin_token = token_file ? read_token_file(token_file) : NULL;
    if (token_file && !admin_token)
        return 2;
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

    raise_open_files();
    /* Signals are taken by sigwait on the main thread; every other thread inherits the mask. */
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);

    ag_extrusion_configure(&extrude);
    ag_error err;
    ag_error_clear(&err);
    ag_app *app = NULL;
    ag_app_options aopt = {.db_path = db,
                           .workers = (int)workers,
                           .demo = demo,
                           .task_workers = (int)task_workers,
                           .db_max_bytes = (size_t)db_max_bytes,
                           .limits = {.max_triangles = (size_t)max_triangles,
                                      .max_nodes = (size_t)max_nodes,
                                      .op_seconds = op_seconds,
                                      .job_seconds = job_seconds,
                                      .preview_seconds = preview_seconds,
                                      .import_seconds = import_seconds}};
    if (ag_app_create(&aopt, &app, &err) != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        free(web_dir);
        free(admin_token);
        return 1;
    }
    /* the first start makes the admin account; its token is shown once, below */
    char first_token[AG_TOKEN_TEXT_MAX + 1] = "";
    int made = 0;
    if (!no_auth) {
        ag_db *adb = ag_app_db(app, &err);
        ag_status s = adb ? ag_accounts_bootstrap(adb, admin_token, first_token, &made, &err)
                          : err.code;
        if (admin_token) {
            memset(admin_token, 0, strlen(admin_token));
            free(admin_token);
            admin_token = NULL;
        }
        if (s != AG_OK) {
            fprintf(stderr, "archgramd: %s\n", err.text);
            ag_app_shutdown(app, -1);
            ag_app_free(app);
            free(web_dir);
            return 1;
        }
    }
    ag_http *http = NULL;
    ag_http_options hopt = {.bind = bind,
                            .port = (int)port,
                            .ws_port = (int)ws_port,
                            .web_dir = web_dir,
                            .max_body = (size_t)max_body,
                            .rest_rate = rate_rest,
                            .job_rate = rate_jobs,
                            .max_connections = (unsigned)max_connections,
                            .max_per_address = (unsigned)max_per_address,
                            .header_timeout = header_timeout,
                            .idle_timeout = (unsigned)idle_timeout,
                            .no_auth = no_auth,
                            .cors = cors,
                            .ncors = ncors};
    ag_live *live = NULL;
    ag_live_options lopt = {.bind = bind,
                            .port = (int)ws_port,
                            .http_port = (int)port,
                            .no_auth = no_auth,
                            .origins = cors,
                            .norigins = ncors,
                            .message_rate = rate_ws};
    if (ag_http_start(app, &hopt, &http, &err) != AG_OK ||
        ag_live_start(app, &lopt, &live, &err) != AG_OK) {
        fprintf(stderr, "archgramd: %s\n", err.text);
        ag_http_stop(http);
        ag_app_shutdown(app, -1);
        ag_app_free(app);
        free(web_dir);
        return 1;
    }
    printf("archgramd: listening on http://%s:%lld/ (websocket ws://%s:%lld/)\n", bind, port, bind,
           ws_port);
    const char *host = strcmp(bind, "0.0.0.0") == 0 ? "localhost" : bind;
    if (no_auth) {
        printf("archgramd: no accounts (--no-auth): everyone on this machine is an admin\n");
    } else if (made) {
        printf("archgramd: first start: made the admin account \"%s\". Sign in with this link; "
               "it is shown only now (archgramd keeps a hash of the token):\n"
               "archgramd:   http://%s:%lld/#token=%s\n",
               AG_ACCOUNTS_ADMIN, host, port, first_token);
        memset(first_token, 0, sizeof first_token);
    } else {
        printf("archgramd: sign in with an API token (a new one: archgramd --db %s "
               "--create-token NAME)\n",
               db);
    }
    fflush(stdout);

    int sig = 0;
    sigwait(&sigs, &sig);
    fprintf(stderr, "archgramd: %s received, shutting down\n",
            sig == SIGINT ? "SIGINT" : "SIGTERM");
    /* Order: stop taking connections, then stop the work (jobs recorded as cancelled, which
     * the live layer may still announce; requests and ops waiting on the task lanes answered
     * 503), then the REST and live layers, then the store. Work inside a stage that cannot be
     * interrupted is not waited for past the grace period: it is recorded as cancelled and the
     * process ends (every write is one transaction, so the store stays consistent). */
    ag_http_quiesce(http);
    ag_extrusion_stop_all(); /* extrusions in requests, ops and jobs stop within milliseconds */
    if (!ag_app_shutdown(app, stop_grace)) {
        ag_app_abandon(app);
        fprintf(stderr, "archgramd: work still running after %g s was recorded as cancelled; "
                        "stopped\n",
                stop_grace);
        fflush(stdout);
        fflush(stderr);
        _exit(0);
    }
    ag_http_stop(http);
    ag_live_stop(live);
    ag_app_free(app);
    free(web_dir);
    fprintf(stderr, "archgramd: stopped\n");
    return 0;
}
