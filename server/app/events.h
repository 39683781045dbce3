/* The event bus: use cases publish what happened (an op committed, a job advanced), the live
 * layer subscribes and fans it out to websocket rooms. Subscribers are called on the
 * publishing thread, in publishing order, and must only queue work. */
#ifndef AG_EVENTS_H
#define AG_EVENTS_H

#include <stdint.h>

typedef enum {
    AG_EVENT_OP,          /* model, version, author, cid, json = the op */
    AG_EVENT_JOB,         /* job, json = the job resource (any status) */
    AG_EVENT_MODEL_GONE,  /* model */
    AG_EVENT_ACCESS,      /* model: who may use it changed (members, public-read) */
} ag_event_kind;

typedef struct {
    ag_event_kind kind;
    int64_t model;
    int64_t version;
    int64_t job;
    const char *author;
    const char *cid;
    const char *json;     /* serialized JSON, see kind */
    uint64_t origin;      /* the live session that caused it, 0 for none (REST, workers) */
} ag_event;

typedef struct ag_events ag_events;
typedef void (*ag_event_fn)(void *user, const ag_event *ev);

ag_events *ag_events_create(void);
void ag_events_free(ag_events *bus);
/* At most 8 subscribers; returns 0 on success. */
int ag_events_subscribe(ag_events *bus, ag_event_fn fn, void *user);
void ag_events_unsubscribe(ag_events *bus, ag_event_fn fn, void *user);
void ag_events_publish(ag_events *bus, const ag_event *ev);

#endif
