#include "auth.h"

#include <pthread.h>
#include <sodium.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../store/jobs.h"
#include "../store/tokens.h"

/* Direct-mapped tables (by the token hash's first bytes; by account and model): small, and a
 * miss costs one query. */
#define CACHE_SLOTS 256
#define ROLE_SLOTS 1024

typedef struct {
    unsigned char hash[32];
    ag_identity who;
    double until; /* monotonic seconds; 0 = empty */
} cache_slot;

typedef struct {
    int64_t user, model;
    ag_model_role member;
    int public_read;
    double until;
} role_slot;

struct ag_auth_cache {
    pthread_mutex_t lock;
    cache_slot slots[CACHE_SLOTS];
    role_slot roles[ROLE_SLOTS];
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

ag_auth_cache *ag_auth_cache_create(void)
{
    ag_auth_cache *c = calloc(1, sizeof *c);
    if (c)
        pthread_mutex_init(&c->lock, NULL);
    return c;
}

void ag_auth_cache_free(ag_auth_cache *c)
{
    if (!c)
        return;
    pthread_mutex_destroy(&c->lock);
    sodium_memzero(c->slots, sizeof c->slots);
    free(c);
}

static cache_slot *slot_of(ag_auth_cache *c, const unsigned char hash[32])
{
    return &c->slots[(hash[0] | hash[1] << 8) % CACHE_SLOTS];
}

static int recall(ag_auth_cache *c, const unsigned char hash[32], ag_identity *who)
{
    if (!c)
        return 0;
    double t = now_s();
    pthread_mutex_lock(&c->lock);
    cache_slot *s = slot_of(c, hash);
    int hit = s->until > t && sodium_memcmp(s->hash, hash, 32) == 0;
    if (hit)
        *who = s->who;
    pthread_mutex_unlock(&c->lock);
    return hit;
}

static void remember(ag_auth_cache *c, const unsigned char hash[32], const ag_identity *who)
{
    if (!c)
        return;
    double t = now_s();
    pthread_mutex_lock(&c->lock);
    cache_slot *s = slot_of(c, hash);
    memcpy(s->hash, hash, 32);
    s->who = *who;
    s->until = t + AG_AUTH_REMEMBER_S;
    pthread_mutex_unlock(&c->lock);
}

static role_slot *role_slot_of(ag_auth_cache *c, int64_t user, int64_t model)
{
    uint64_t h = (uint64_t)user * 0x9E3779B97F4A7C15u ^ (uint64_t)model * 0xC2B2AE3D27D4EB4Fu;
    return &c->roles[(h >> 32) % ROLE_SLOTS];
}

static int recall_role(ag_auth_cache *c, int64_t user, int64_t model, ag_model_role *member,
                       int *public_read)
{
    if (!c)
        return 0;
    double t = now_s();
    pthread_mutex_lock(&c->lock);
    role_slot *s = role_slot_of(c, user, model);
    int hit = s->until > t && s->user == user && s->model == model;
    if (hit) {
        *member = s->member;
        *public_read = s->public_read;
    }
    pthread_mutex_unlock(&c->lock);
    return hit;
}

static void remember_role(ag_auth_cache *c, int64_t user, int64_t model, ag_model_role member,
                          int public_read)
{
    if (!c)
        return;
    double t = now_s();
    pthread_mutex_lock(&c->lock);
    *role_slot_of(c, user, model) = (role_slot){.user = user,
                                               .model = model,
                                               .member = member,
                                               .public_read = public_read,
                                               .until = t + AG_AUTH_REMEMBER_S};
    pthread_mutex_unlock(&c->lock);
}

void ag_auth_forget(ag_app *app)
{
    ag_auth_cache *c = ag__app_auth_cache(app);
    if (!c)
        return;
    pthread_mutex_lock(&c->lock);
    sodium_memzero(c->slots, sizeof c->slots);
    memset(c->roles, 0, sizeof c->roles);
    pthread_mutex_unlock(&c->lock);
}

void ag_auth_local(ag_identity *who)
{
    memset(who, 0, sizeof *who);
    snprintf(who->name, sizeof who->name, "local");
    who->role = AG_ACCOUNT_ADMIN;
}

ag_status ag_auth_token(ag_app *app, const char *token, ag_identity *who, ag_error *err)
{
    memset(who, 0, sizeof *who);
    unsigned char hash[32];
    if (!ag_tokens_hash(token, hash))
        return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                            "the token is not one this server gave out");
    ag_auth_cache *cache = ag__app_auth_cache(app);
    if (recall(cache, hash, who))
        return AG_OK;
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    int64_t user, id;
    ag_user_row row;
    ag_status s = ag_tokens_verify(db, token, &user, &id, &row, err);
    if (s != AG_OK)
        return s;
    who->user = row.id;
    who->token = id;
    who->role = row.role;
    snprintf(who->name, sizeof who->name, "%s", row.name);
    remember(cache, hash, who);
    sodium_memzero(hash, sizeof hash);
    return AG_OK;
}

ag_model_role ag_auth_role(const ag_identity *who, ag_model_role member, int public_read)
{
    if (who->role == AG_ACCOUNT_ADMIN)
        return AG_ROLE_OWNER;
    if (member != AG_ROLE_NONE)
        return member;
    return public_read ? AG_ROLE_VIEWER : AG_ROLE_NONE;
}

static const char *doing(ag_model_role need)
{
    return need == AG_ROLE_OWNER ? "only its owners may do this"
                                 : "only its editors and owners may change it";
}

static ag_status check_model(ag_app *app, const ag_identity *who, int64_t model,
                             ag_model_role need, ag_model_role *role, ag_error *err)
{
    ag_model_role member = AG_ROLE_NONE, have;
    int public_read = 0;
    ag_auth_cache *cache = ag__app_auth_cache(app);
    if (who->role == AG_ACCOUNT_ADMIN) {
        have = AG_ROLE_OWNER; /* a missing model is the handler's to report */
    } else {
        if (!recall_role(cache, who->user, model, &member, &public_read)) {
            ag_db *db = ag_app_db(app, err);
            if (!db)
                return err ? err->code : AG_ERR_DB;
            ag_status s = ag_members_access(db, model, who->user, &member, &public_read, err);
            if (s != AG_OK)
                return s; /* a model that does not exist is not remembered */
            remember_role(cache, who->user, model, member, public_read);
        }
        have = ag_auth_role(who, member, public_read);
    }
    if (role)
        *role = have;
    if (have == AG_ROLE_NONE)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no model %lld", (long long)model);
    if (have < need)
        return ag_error_set(err, AG_ERR_FORBIDDEN, 0, "%s is a %s of model %lld: %s", who->name,
                            ag_members_role_name(have), (long long)model, doing(need));
    return AG_OK;
}

static ag_status check_job(ag_db *db, const ag_identity *who, int64_t job, ag_error *err)
{
    if (who->role == AG_ACCOUNT_ADMIN)
        return AG_OK;
    ag_job_row row;
    ag_status s = ag_jobs_get(db, job, &row, err);
    int mine = s == AG_OK && row.user != 0 && row.user == who->user;
    ag_jobs_row_clear(&row);
    if (s != AG_OK && s != AG_ERR_NOT_FOUND)
        return s;
    return mine ? AG_OK
                : ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no job %lld", (long long)job);
}

ag_status ag_auth_check(ag_app *app, const ag_identity *who, ag_need need, int64_t id,
                        ag_model_role *role, ag_error *err)
{
    if (role)
        *role = AG_ROLE_NONE;
    if (need == AG_NEED_NOTHING)
        return AG_OK;
    if (!who || (!who->user && who->role != AG_ACCOUNT_ADMIN))
        return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                            "sign in: send Authorization: Bearer <token>");
    switch (need) {
    case AG_NEED_ACCOUNT:
        return AG_OK;
    case AG_NEED_EDITOR:
        return who->role >= AG_ACCOUNT_EDITOR
                   ? AG_OK
                   : ag_error_set(err, AG_ERR_FORBIDDEN, 0,
                                  "%s is a viewer account: only editors and admins may do this",
                                  who->name);
    case AG_NEED_ADMIN:
    case AG_NEED_UNDECLARED:
        return who->role == AG_ACCOUNT_ADMIN
                   ? AG_OK
                   : ag_error_set(err, AG_ERR_FORBIDDEN, 0, "only admins may do this");
    default:
        break;
    }
    switch (need) {
    case AG_NEED_MODEL_VIEWER:
        return check_model(app, who, id, AG_ROLE_VIEWER, role, err);
    case AG_NEED_MODEL_EDITOR:
        return check_model(app, who, id, AG_ROLE_EDITOR, role, err);
    case AG_NEED_MODEL_OWNER:
        return check_model(app, who, id, AG_ROLE_OWNER, role, err);
    case AG_NEED_JOB: {
        ag_db *db = ag_app_db(app, err);
        return db ? check_job(db, who, id, err) : err ? err->code : AG_ERR_DB;
    }
    default:
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "unknown access need %d", (int)need);
    }
}

const char *ag_auth_model_role_name(ag_model_role role)
{
    return ag_members_role_name(role);
}

ag_status ag_auth_account_role_parse(const char *text, ag_account_role *role, ag_error *err)
{
    return ag_users_role_parse(text, role, err);
}
