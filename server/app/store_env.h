/* What the use cases that read and change the store are handed, instead of the whole app:
 * this thread's connection, the sequencer that orders op commits and announces them, and the
 * edit models kept in memory. A test or a tool builds one from a connection of its own;
 * threads of the service build theirs from the shared services (one connection per thread). */
#ifndef AG_STORE_ENV_H
#define AG_STORE_ENV_H

#include "../store/db.h"
#include "dbpool.h"
#include "edit_session.h"
#include "sequencer.h"
#include "work_limits.h"

typedef struct ag_store_env {
    ag_db *db;
    ag_sequencer *seq;
    ag_edit_sessions *sessions; /* NULL: an edit loads its model afresh and keeps nothing */
    const ag_work_limits *limits; /* NULL: the defaults */
} ag_store_env;

typedef struct ag_store_services {
    ag_dbpool *pool;
    ag_sequencer *seq;
    ag_edit_sessions *sessions;
    const ag_work_limits *limits;
} ag_store_services;

/* The calling thread's environment. */
static inline ag_status ag_store_services_env(const ag_store_services *s, ag_store_env *env,
                                              ag_error *err)
{
    env->seq = s->seq;
    env->sessions = s->sessions;
    env->limits = s->limits;
    env->db = ag_dbpool_get(s->pool, err);
    return env->db ? AG_OK : err ? err->code : AG_ERR_DB;
}

#endif
