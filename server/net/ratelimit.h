/* Rate limits: a token bucket per key (a client address, or an account once requests carry
 * one), refilled at `rate` per second up to `burst`. One limiter per kind of traffic: REST
 * requests, job submissions, websocket messages. The table of keys is bounded: idle keys (a
 * full bucket is the same as a fresh one) go first, then the longest unseen. */
#ifndef AG_RATELIMIT_H
#define AG_RATELIMIT_H

#include <stddef.h>

typedef struct ag_ratelimit ag_ratelimit;

typedef struct {
    double rate;  /* tokens per second; 0: no limit */
    double burst; /* bucket size; 0: max(1, rate) */
} ag_rate;

/* "RATE" or "RATE/BURST" (e.g. "200/1000"; "0" for none): 0 on success, -1 otherwise. */
int ag_ratelimit_parse(const char *text, ag_rate *out);

/* NULL when out of memory; a rate of 0 gives a limiter that allows everything. */
ag_ratelimit *ag_ratelimit_create(ag_rate rate, size_t max_keys);
void ag_ratelimit_free(ag_ratelimit *rl);

/* Takes a token for key (NUL-terminated, at most 63 bytes are told apart): 1 when allowed,
 * 0 when the bucket is empty, with *retry_after the seconds until a token comes back. */
int ag_ratelimit_take(ag_ratelimit *rl, const char *key, double *retry_after);

#endif
