/* Binary min-heap of sweep events ordered by height (ties: intersection events before
 * profile direction events at the same height). */
#ifndef AG_EXTRUDE_EVENTQ_H
#define AG_EXTRUDE_EVENTQ_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"

typedef enum {
    AG_EVENT_EDGE = 0,      /* an edge shrinks to zero length: a = edge */
    AG_EVENT_SPLIT = 1,     /* a corner reaches an edge: a = corner, b = edge */
    AG_EVENT_DIRECTION = 2, /* profile a switches to its segment b */
    AG_EVENT_ANCHOR = 3,    /* anchor b is located on the active plan */
} ag_event_type;

typedef struct {
    double z, x, y;
    uint32_t a, b;
    uint32_t ver; /* version of the edge the event was computed against */
    uint8_t type;
} ag_event;

typedef struct {
    ag_event *h;
    size_t n, cap;
} ag_eventq;

ag_status ag_eventq_push(ag_eventq *q, const ag_event *e);
/* Returns 0 when empty. */
int ag_eventq_pop(ag_eventq *q, ag_event *out);
const ag_event *ag_eventq_peek(const ag_eventq *q);
void ag_eventq_free(ag_eventq *q);

#endif
