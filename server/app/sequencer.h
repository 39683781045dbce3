/* The sequencer: every change of a model is one op that raises its version by one, written to
 * the op log in the transaction that makes the change, and announced on the event bus after
 * the commit. One lock orders the commits of all threads, so events leave in version order.
 *
 * A change is ag_sequencer_begin (lock, BEGIN IMMEDIATE, the client id looked up, the version
 * raised), the caller's writes on t->db, then ag_sequencer_commit (log, commit, publish) or
 * ag_sequencer_abort (roll back). Both release the lock. */
#ifndef AG_SEQUENCER_H
#define AG_SEQUENCER_H

#include <jansson.h>
#include <stdint.h>

#include "../core/status.h"
#include "../store/db.h"
#include "events.h"

typedef struct ag_sequencer ag_sequencer;

/* events may be NULL: commits are then announced to nobody. */
ag_sequencer *ag_sequencer_create(ag_events *events);
void ag_sequencer_free(ag_sequencer *s);
ag_events *ag_sequencer_events(ag_sequencer *s);
/* Publishes an event (job progress) on the bus, if there is one. */
void ag_sequencer_publish(ag_sequencer *s, const ag_event *ev);

typedef struct {
    ag_sequencer *seq; /* NULL when no change is under way */
    ag_db *db;
    int64_t model;
    int64_t version;   /* the version the change gets */
    uint64_t origin;   /* the live session that sent the op (0 = none), passed to the event */
} ag_seq_txn;

/* Opens a change of model made on version base. With cid (and author) given, a pair this
 * author used on the model before is not applied again: *duplicate gets the version it got
 * then and nothing is left open (t->seq is NULL). AG_ERR_STALE carries the current version in
 * err->element; AG_ERR_NOT_FOUND when there is no such model. duplicate may be NULL without
 * cid. */
ag_status ag_sequencer_begin(ag_sequencer *s, ag_db *db, int64_t model, int64_t base,
                             const char *author, const char *cid, ag_seq_txn *t,
                             int64_t *duplicate, ag_error *err);
/* Logs op (canonical JSON, keys sorted) under author and cid, commits, publishes. */
ag_status ag_sequencer_commit(ag_seq_txn *t, const char *author, const char *cid,
                              const json_t *op, ag_error *err);
void ag_sequencer_abort(ag_seq_txn *t);

/* Deletes a model at the given version (AG_ERR_STALE otherwise) and announces its end. */
ag_status ag_sequencer_delete(ag_sequencer *s, ag_db *db, int64_t model, int64_t version,
                              ag_error *err);

#endif
