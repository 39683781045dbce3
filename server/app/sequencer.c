#include "sequencer.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "../store/models.h"
#include "../store/ops.h"

struct ag_sequencer {
    pthread_mutex_t lock;
    ag_events *events;
};

ag_sequencer *ag_sequencer_create(ag_events *events)
{
    ag_sequencer *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    pthread_mutex_init(&s->lock, NULL);
    s->events = events;
    return s;
}

void ag_sequencer_free(ag_sequencer *s)
{
    if (!s)
        return;
    pthread_mutex_destroy(&s->lock);
    free(s);
}

ag_events *ag_sequencer_events(ag_sequencer *s) { return s ? s->events : NULL; }

void ag_sequencer_publish(ag_sequencer *s, const ag_event *ev)
{
    if (s && s->events)
        ag_events_publish(s->events, ev);
}

ag_status ag_sequencer_begin(ag_sequencer *s, ag_db *db, int64_t model, int64_t base,
                             const char *author, const char *cid, ag_seq_txn *t,
                             int64_t *duplicate, ag_error *err)
{
    memset(t, 0, sizeof *t);
    if (duplicate)
        *duplicate = 0;
    pthread_mutex_lock(&s->lock);
    ag_status st = ag_db_begin(db, err);
    if (st == AG_OK && cid) {
        int64_t seen = 0;
        st = ag_ops_find_cid(db, model, author, cid, &seen, err);
        if (st == AG_OK && seen) {
            ag_db_rollback(db);
            pthread_mutex_unlock(&s->lock);
            if (duplicate)
                *duplicate = seen;
            return AG_OK;
        }
        if (st != AG_OK)
            ag_db_rollback(db);
    }
    if (st == AG_OK && (st = ag_models_bump_version(db, model, base, &t->version, err)) != AG_OK)
        ag_db_rollback(db);
    if (st != AG_OK) {
        pthread_mutex_unlock(&s->lock);
        return st;
    }
    t->seq = s;
    t->db = db;
    t->model = model;
    return AG_OK;
}

void ag_sequencer_abort(ag_seq_txn *t)
{
    if (!t->seq)
        return;
    ag_db_rollback(t->db);
    pthread_mutex_unlock(&t->seq->lock);
    t->seq = NULL;
}

ag_status ag_sequencer_commit(ag_seq_txn *t, const char *author, const char *cid,
                              const json_t *op, ag_error *err)
{
    if (!t->seq)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no change is under way");
    char *body = json_dumps(op, JSON_COMPACT | JSON_SORT_KEYS);
    ag_status s = body ? AG_OK : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    const char *kind = json_string_value(json_object_get(op, "kind"));
    if (s == AG_OK) {
        ag_op_row row = {.model = t->model,
                         .version = t->version,
                         .author = author,
                         .cid = cid,
                         .kind = kind ? kind : "",
                         .body_json = body};
        s = ag_ops_insert(t->db, &row, err);
    }
    s = s == AG_OK ? ag_db_commit(t->db, err) : (ag_db_rollback(t->db), s);
    if (s == AG_OK) {
        ag_event ev = {.kind = AG_EVENT_OP,
                       .model = t->model,
                       .version = t->version,
                       .author = author,
                       .cid = cid,
                       .json = body,
                       .origin = t->origin};
        ag_sequencer_publish(t->seq, &ev);
    }
    pthread_mutex_unlock(&t->seq->lock);
    t->seq = NULL;
    free(body);
    return s;
}

ag_status ag_sequencer_delete(ag_sequencer *s, ag_db *db, int64_t model, int64_t version,
                              ag_error *err)
{
    pthread_mutex_lock(&s->lock);
    ag_status st = ag_db_begin(db, err);
    if (st == AG_OK) {
        st = ag_models_delete(db, model, version, err);
        st = st == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), st);
    }
    if (st == AG_OK) {
        ag_event ev = {.kind = AG_EVENT_MODEL_GONE, .model = model};
        ag_sequencer_publish(s, &ev);
    }
    pthread_mutex_unlock(&s->lock);
    return st;
}
