#include "ratelimit.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define KEY_MAX 64

typedef struct {
    char key[KEY_MAX]; /* "" = free slot */
    double tokens;
    double seen;       /* monotonic seconds of the last take */
} bucket;

struct ag_ratelimit {
    pthread_mutex_t lock;
    ag_rate rate;
    bucket *slots;
    size_t cap, used;
};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int ag_ratelimit_parse(const char *text, ag_rate *out)
{
    char *end;
    double rate = strtod(text, &end), burst = 0;
    if (end == text || !(rate >= 0) || !isfinite(rate))
        return -1;
    if (*end == '/') {
        const char *b = end + 1;
        burst = strtod(b, &end);
        if (end == b || !(burst >= 1) || !isfinite(burst))
            return -1;
    }
    if (*end)
        return -1;
    out->rate = rate;
    out->burst = burst;
    return 0;
}

ag_ratelimit *ag_ratelimit_create(ag_rate rate, size_t max_keys)
{
    ag_ratelimit *rl = calloc(1, sizeof *rl);
    if (!rl)
        return NULL;
    rl->rate = rate;
    if (rl->rate.burst <= 0)
        rl->rate.burst = rl->rate.rate > 1 ? rl->rate.rate : 1;
    rl->cap = max_keys < 16 ? 16 : max_keys;
    if (rate.rate > 0 && !(rl->slots = calloc(rl->cap, sizeof *rl->slots))) {
        free(rl);
        return NULL;
    }
    pthread_mutex_init(&rl->lock, NULL);
    return rl;
}

void ag_ratelimit_free(ag_ratelimit *rl)
{
    if (!rl)
        return;
    pthread_mutex_destroy(&rl->lock);
    free(rl->slots);
    free(rl);
}

static uint64_t hash(const char *s)
{
    uint64_t h = 1469598103934665603ull; /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ull;
    return h;
}

static double refilled(const ag_ratelimit *rl, const bucket *b, double t)
{
    return fmin(rl->rate.burst, b->tokens + (t - b->seen) * rl->rate.rate);
}

/* Makes room when the table is three quarters full: idle buckets go, and if that frees too
 * little, the least recently seen half. Rehashes what stays. */
static int newest_first(const void *a, const void *b)
{
    double x = ((const bucket *)a)->seen, y = ((const bucket *)b)->seen;
    return (x < y) - (x > y);
}

static void compact(ag_ratelimit *rl, double t)
{
    bucket *old = rl->slots;
    bucket *keep = malloc(rl->cap * sizeof *keep);
    if (!keep)
        return;
    size_t n = 0;
    for (size_t i = 0; i < rl->cap; i++)
        if (old[i].key[0] && refilled(rl, &old[i], t) < rl->rate.burst)
            keep[n++] = old[i];
    if (n > rl->cap / 2) { /* still busy: keep the most recently seen half, exactly (a cut by
                              * time could drop a busy key and give it a fresh burst) */
        qsort(keep, n, sizeof *keep, newest_first);
        n = rl->cap / 2;
    }
    memset(old, 0, rl->cap * sizeof *old);
    rl->used = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = hash(keep[i].key) % rl->cap;
        while (old[j].key[0])
            j = (j + 1) % rl->cap;
        old[j] = keep[i];
        rl->used++;
    }
    free(keep);
}

int ag_ratelimit_take(ag_ratelimit *rl, const char *key, double *retry_after)
{
    *retry_after = 0;
    if (!rl || rl->rate.rate <= 0)
        return 1;
    char k[KEY_MAX];
    size_t len = strnlen(key, KEY_MAX - 1);
    memcpy(k, key, len);
    k[len] = '\0';
    if (!k[0])
        k[0] = '?', k[1] = '\0';
    double t = now();
    pthread_mutex_lock(&rl->lock);
    size_t j = hash(k) % rl->cap;
    while (rl->slots[j].key[0] && strcmp(rl->slots[j].key, k) != 0)
        j = (j + 1) % rl->cap;
    bucket *b = &rl->slots[j];
    if (!b->key[0]) {
        if (4 * (rl->used + 1) > 3 * rl->cap) {
            compact(rl, t);
            if (4 * (rl->used + 1) > 3 * rl->cap) { /* all seen at once: start afresh */
                memset(rl->slots, 0, rl->cap * sizeof *rl->slots);
                rl->used = 0;
            }
            j = hash(k) % rl->cap;
            while (rl->slots[j].key[0])
                j = (j + 1) % rl->cap;
            b = &rl->slots[j];
        }
        memcpy(b->key, k, strlen(k) + 1);
        b->tokens = rl->rate.burst;
        b->seen = t;
        rl->used++;
    }
    b->tokens = refilled(rl, b, t);
    b->seen = t;
    int ok = b->tokens >= 1;
    if (ok)
        b->tokens -= 1;
    else
        *retry_after = (1 - b->tokens) / rl->rate.rate;
    pthread_mutex_unlock(&rl->lock);
    return ok;
}
