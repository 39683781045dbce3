#include "events.h"

#include <pthread.h>
#include <stdlib.h>

#define AG_EVENTS_MAX_SUBSCRIBERS 8

struct ag_events {
    pthread_mutex_t lock; /* held while publishing, so every subscriber sees one order */
    struct {
        ag_event_fn fn;
        void *user;
    } subs[AG_EVENTS_MAX_SUBSCRIBERS];
    int nsubs;
};

ag_events *ag_events_create(void)
{
    ag_events *bus = calloc(1, sizeof *bus);
    if (bus)
        pthread_mutex_init(&bus->lock, NULL);
    return bus;
}

void ag_events_free(ag_events *bus)
{
    if (!bus)
        return;
    pthread_mutex_destroy(&bus->lock);
    free(bus);
}

int ag_events_subscribe(ag_events *bus, ag_event_fn fn, void *user)
{
    pthread_mutex_lock(&bus->lock);
    int rc = -1;
    if (bus->nsubs < AG_EVENTS_MAX_SUBSCRIBERS) {
        bus->subs[bus->nsubs].fn = fn;
        bus->subs[bus->nsubs].user = user;
        bus->nsubs++;
        rc = 0;
    }
    pthread_mutex_unlock(&bus->lock);
    return rc;
}

void ag_events_unsubscribe(ag_events *bus, ag_event_fn fn, void *user)
{
    pthread_mutex_lock(&bus->lock);
    for (int i = 0; i < bus->nsubs; i++) {
        if (bus->subs[i].fn == fn && bus->subs[i].user == user) {
            bus->subs[i] = bus->subs[bus->nsubs - 1];
            bus->nsubs--;
            break;
        }
    }
    pthread_mutex_unlock(&bus->lock);
}

void ag_events_publish(ag_events *bus, const ag_event *ev)
{
    pthread_mutex_lock(&bus->lock);
    for (int i = 0; i < bus->nsubs; i++)
        bus->subs[i].fn(bus->subs[i].user, ev);
    pthread_mutex_unlock(&bus->lock);
}
