/* Websocket message dispatch (net/live_protocol.c) against a real app on a temporary store
 * with the demo models: every message of a session (the input, split at newlines) is
 * answered or refused without a crash, a hang or a leak. The live layer's plumbing
 * (libwebsockets, the service thread) is replaced by what this file defines: writes are
 * dropped, answers posted from other threads are dropped. */
#include <libwebsockets.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

#include "app/app.h"
#include "fuzz_check.h"
#include "net/live_protocol.h"
#include "net/live_rooms.h"

static ag_app *app;
static ag_live_rooms rooms;
static atomic_size_t posted;

/* --- what live.c and libwebsockets provide to the protocol ----------------------------------- */
ag_app *ag__live_app(ag_live *live) { (void)live; return app; }
ag_live_rooms *ag__live_rooms(ag_live *live) { (void)live; return &rooms; }
struct ag_ratelimit *ag__live_message_limit(ag_live *live) { (void)live; return NULL; }
void ag__live_post_to_session(ag_live *live, uint64_t session, const char *text)
{
    (void)live, (void)session, (void)text;
    atomic_fetch_add(&posted, 1);
}
void ag__live_post_to_room(ag_live *live, int64_t model, const char *text)
{
    (void)live, (void)model, (void)text;
    atomic_fetch_add(&posted, 1);
}
int lws_callback_on_writable(struct lws *wsi) { (void)wsi; return 0; }
void lws_set_timer_usecs(struct lws *wsi, lws_usec_t usecs) { (void)wsi, (void)usecs; }

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    static char dir[] = "/tmp/archgram-fuzz-ws-XXXXXX";
    if (!mkdtemp(dir))
        abort();
    static char db[64];
    snprintf(db, sizeof db, "%s/f.db", dir);
    ag_error err;
    ag_app_options o = {.db_path = db, .workers = 1, .demo = 1, .task_workers = 2};
    if (ag_app_create(&o, &app, &err) != AG_OK) {
        fprintf(stderr, "fuzz_ws_dispatch: %s\n", err.text);
        abort();
    }
    sleep(1); /* the demo models are proceduralized by jobs */
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    ag_live_session *s = calloc(1, sizeof *s);
    if (!s)
        return 0;
    ag_live_rooms_add(&rooms, s, (struct lws *)s);
    snprintf(s->rate_key, sizeof s->rate_key, "addr:fuzz");
    const char *p = (const char *)data, *end = p + size;
    /* the first message decides whether later ones may come as binary or oversized frames */
    for (int n = 0; p <= end && n < 16; n++) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t len = nl ? (size_t)(nl - p) : (size_t)(end - p);
        int binary = len > 0 && (unsigned char)p[0] == 0xff;
        ag_live_protocol_message(NULL, s, p, len, binary, len > 0 && p[0] == 0x01);
        if (!nl)
            break;
        p = nl + 1;
    }
    ag_live_rooms_remove(&rooms, s);
    free(s);
    return 0;
}
