#include "extrude_batch.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "extrusion.h"

/* Footprints per unit of work: small enough to balance, large enough that the shared
 * counter is touched rarely. */
#define CHUNK 8

typedef struct {
    const ag_footprints *f;
    const ag_style *style;
    const ag_extrude_options *opt;
    size_t nchunks;
    ag_mesh **mesh;             /* one per chunk */
    ag_building_result *result; /* one per footprint */
    atomic_size_t next;
    atomic_int stop;
    pthread_mutex_t lock; /* guards the first error */
    ag_status st;
    ag_error err;
} batch;

static ag_status run_chunk(batch *b, size_t c)
{
    ag_mesh *m = ag_mesh_create();
    if (!m)
        return AG_ERR_NOMEM;
    b->mesh[c] = m;
    size_t lo = c * CHUNK, hi = lo + CHUNK < b->f->n ? lo + CHUNK : b->f->n;
    for (size_t i = lo; i < hi; i++) {
        const ag_footprint *fp = &b->f->items[i];
        size_t group = 0;
        ag_error e = {0};
        ag_status st = ag_mesh_add_group(m, fp->id, &group);
        if (st == AG_OK)
            st = ag_building_extrude(b->style, (const double *const *)fp->loops, fp->sizes,
                                     fp->nloops, fp->height, i, b->opt, m, (int32_t)group,
                                     &b->result[i], &e);
        if (st != AG_OK) {
            pthread_mutex_lock(&b->lock);
            if (b->st == AG_OK) {
                b->st = st;
                b->err = e;
            }
            pthread_mutex_unlock(&b->lock);
            return st;
        }
    }
    return AG_OK;
}

static void *worker(void *arg)
{
    batch *b = arg;
    while (!atomic_load(&b->stop)) {
        size_t c = atomic_fetch_add(&b->next, 1);
        if (c >= b->nchunks)
            break;
        if (run_chunk(b, c) != AG_OK)
            atomic_store(&b->stop, 1);
    }
    return NULL;
}

ag_status ag_extrude_batch(const ag_footprints *f, const ag_style *style,
                           const ag_extrude_batch_options *opt, ag_mesh *m,
                           ag_footprints_report *report, ag_error *err)
{
    memset(report, 0, sizeof *report);
    report->footprints = f->n;
    batch b;
    memset(&b, 0, sizeof b);
    b.f = f;
    b.style = style;
    b.opt = opt ? &opt->extrude : NULL;
    b.nchunks = (f->n + CHUNK - 1) / CHUNK;
    b.mesh = calloc(b.nchunks ? b.nchunks : 1, sizeof *b.mesh);
    b.result = calloc(f->n ? f->n : 1, sizeof *b.result);
    atomic_init(&b.next, 0);
    atomic_init(&b.stop, 0);
    pthread_mutex_init(&b.lock, NULL);
    ag_status st = b.mesh && b.result ? AG_OK : AG_ERR_NOMEM;
    size_t threads = opt && opt->threads ? opt->threads : 0;
    if (!threads) {
        long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        threads = cpus > 0 ? (size_t)cpus : 1;
    }
    if (threads > b.nchunks)
        threads = b.nchunks ? b.nchunks : 1;
    pthread_t *tid = st == AG_OK && threads > 1 ? calloc(threads - 1, sizeof *tid) : NULL;
    size_t started = 0;
    for (size_t t = 0; tid && t + 1 < threads; t++)
        if (pthread_create(&tid[t], NULL, worker, &b) == 0)
            started++;
        else
            break; /* the others share the work */
    if (st == AG_OK)
        worker(&b);
    for (size_t t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    if (st == AG_OK && b.st != AG_OK) {
        st = b.st;
        if (err)
            *err = b.err;
    }
    /* in input order: the chunks' meshes, then each building's line in the report */
    for (size_t c = 0; st == AG_OK && c < b.nchunks; c++)
        st = ag_extrusion_append(m, b.mesh[c]);
    for (size_t i = 0; st == AG_OK && i < f->n; i++)
        st = ag_footprints_report_add(report, &f->items[i], &b.result[i]);
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory");
    for (size_t c = 0; b.mesh && c < b.nchunks; c++)
        ag_mesh_free(b.mesh[c]);
    free(b.mesh);
    free(b.result);
    pthread_mutex_destroy(&b.lock);
    return st;
}
