/* The cost of signing in (figures, not pass/fail), in process on a temp database: what every
 * REST request and websocket handshake pays — ag_auth_token (the bearer token to its account:
 * remembered, and the first time a query) and ag_auth_check (the account's role on a model: a
 * query unless it is an admin) — next to what GET /api/v1/models/{id} itself reads
 * (ag_app_query_model). bench/http.sh measures the whole request over HTTP. Median of 7 runs
 * of 20,000 calls each. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/accounts.h"
#include "app/app.h"
#include "app/app_query.h"
#include "app/auth.h"
#include "store/members.h"
#include "store/models.h"

#define CALLS 20000
#define RUNS 7

static double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e6 + ts.tv_nsec * 1e-3;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void die(const char *what, const ag_error *err)
{
    fprintf(stderr, "bench/auth: %s: %s\n", what, err->text);
    exit(1);
}

typedef struct {
    ag_app *app;
    const char *token;
    int64_t model;
    ag_identity who;
} ctx;

static void sign_in(ctx *c)
{
    ag_error err;
    if (ag_auth_token(c->app, c->token, &c->who, &err) != AG_OK)
        die("sign in", &err);
}

static void sign_in_fresh(ctx *c)
{
    ag_auth_forget(c->app); /* as if the token had not been seen for AG_AUTH_REMEMBER_S */
    sign_in(c);
}

static void check(ctx *c)
{
    ag_error err;
    ag_model_role role;
    if (ag_auth_check(c->app, &c->who, AG_NEED_MODEL_VIEWER, c->model, &role, &err) != AG_OK ||
        role != AG_ROLE_OWNER)
        die("check", &err);
}

static void read_model(ctx *c)
{
    ag_error err;
    json_t *view;
    int64_t version;
    if (ag_app_query_model(c->app, c->model, &view, &version, &err) != AG_OK)
        die("read", &err);
    char *text = json_dumps(view, JSON_COMPACT); /* the reply's body, as the handler makes it */
    free(text);
    json_decref(view);
}

static double time_us(ctx *c, void (*fn)(ctx *))
{
    double us[RUNS];
    for (int r = 0; r < RUNS; r++) {
        double t0 = now_us();
        for (int i = 0; i < CALLS; i++)
            fn(c);
        us[r] = (now_us() - t0) / CALLS;
    }
    qsort(us, RUNS, sizeof *us, cmp);
    return us[RUNS / 2];
}

int main(void)
{
    char dir[] = "/tmp/archgram-bench-auth-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    char db_path[128];
    snprintf(db_path, sizeof db_path, "%s/a.db", dir);
    ag_error err;
    ag_app *app;
    ag_app_options opt = {.db_path = db_path, .workers = 1};
    if (ag_app_create(&opt, &app, &err) != AG_OK)
        die("app", &err);
    ag_db *db = ag_app_db(app, &err);
    json_t *made;
    if (ag_accounts_create_in(db, "owner", AG_ACCOUNT_EDITOR, "bench", &made, &err) != AG_OK)
        die("account", &err);
    ctx c = {.app = app, .token = json_string_value(json_object_get(made, "token"))};
    int64_t user = 0;
    ag_model_new m = {.name = "bench", .mesh = "x", .mesh_len = 1,
                      .stats_json = "{\"vertices\":16,\"triangles\":24,\"components\":2}"};
    if (ag_db_begin(db, &err) != AG_OK || ag_models_insert(db, &m, &c.model, &err) != AG_OK)
        die("model", &err);
    sign_in(&c);
    user = c.who.user;
    if (ag_members_put(db, c.model, user, AG_ROLE_OWNER, &err) != AG_OK ||
        ag_db_commit(db, &err) != AG_OK)
        die("owner", &err);

    double read = time_us(&c, read_model);
    double token = time_us(&c, sign_in);
    double fresh = time_us(&c, sign_in_fresh);
    double role = time_us(&c, check);
    printf("auth: GET /api/v1/models/{id} reads the model in %.2f us; signing in costs %.2f us "
           "(token remembered) or %.2f us (looked up), the owner's role on the model %.2f us: "
           "%.2f us in all per request, %.1f%% of the model read alone (less of a whole HTTP "
           "request; bench/http.sh)\n",
           read, token, fresh, role, token + role, (token + role) / read * 100);
    json_decref(made);
    ag_app_shutdown(app, -1);
    ag_app_free(app);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : 1;
}
