#include "extrude_batch.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "extrusion.h"

/* Buildings per unit of work: small enough to balance, large enough that the shared
 * counter is touched rarely. */
#define CHUNK 8

typedef struct {
    size_t n, nchunks;
    ag_extrude_batch_build build;
    void *user;
    const ag_extrude_batch_options *opt;
    const ag_extrude_options *extrude;
    int per_building;           /* meshes[i] per building, else one per chunk */
    ag_mesh **mesh;
    ag_building_result *result; /* one per building */
    atomic_size_t next, done;
    atomic_int stop;
    pthread_t caller;
    pthread_mutex_t lock; /* guards the first error */
    ag_status st;
    ag_error err;
} batch;

static ag_status run_chunk(batch *b, size_t c)
{
    size_t lo = c * CHUNK, hi = lo + CHUNK < b->n ? lo + CHUNK : b->n;
    ag_mesh *m = NULL;
    for (size_t i = lo; i < hi; i++) {
        if (!m || b->per_building) {
            m = ag_mesh_create();
            if (!m)
                return AG_ERR_NOMEM;
            b->mesh[b->per_building ? i : c] = m;
        }
        ag_error e = {0};
        ag_status st = b->build(b->user, i, b->extrude, m, &b->result[i], &e);
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
    atomic_fetch_add(&b->done, hi - lo);
    return AG_OK;
}

static void *worker(void *arg)
{
    batch *b = arg;
    int caller = pthread_equal(pthread_self(), b->caller);
    while (!atomic_load(&b->stop)) {
        size_t c = atomic_fetch_add(&b->next, 1);
        if (c >= b->nchunks)
            break;
        if (run_chunk(b, c) != AG_OK)
            atomic_store(&b->stop, 1);
        else if (caller && b->opt && b->opt->progress)
            b->opt->progress(b->opt->progress_user, atomic_load(&b->done), b->n);
    }
    return NULL;
}

/* Runs b on every core; the first error (its text in err) or AG_OK. */
static ag_status run(batch *b, ag_error *err)
{
    atomic_init(&b->next, 0);
    atomic_init(&b->done, 0);
    atomic_init(&b->stop, 0);
    b->caller = pthread_self();
    pthread_mutex_init(&b->lock, NULL);
    size_t threads = b->opt && b->opt->threads ? b->opt->threads : 0;
    if (!threads) {
        long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        threads = cpus > 0 ? (size_t)cpus : 1;
    }
    if (threads > b->nchunks)
        threads = b->nchunks ? b->nchunks : 1;
    pthread_t *tid = threads > 1 ? calloc(threads - 1, sizeof *tid) : NULL;
    size_t started = 0;
    for (size_t t = 0; tid && t + 1 < threads; t++)
        if (pthread_create(&tid[t], NULL, worker, b) == 0)
            started++;
        else
            break; /* the others share the work */
    worker(b);
    for (size_t t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    pthread_mutex_destroy(&b->lock);
    ag_status st = b->st;
    if (st != AG_OK && err)
        *err = b->err;
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory");
    return st;
}

static void free_meshes(ag_mesh **m, size_t n)
{
    for (size_t i = 0; m && i < n; i++) {
        ag_mesh_free(m[i]);
        m[i] = NULL;
    }
}

ag_status ag_extrude_batch_each(size_t n, ag_extrude_batch_build build, void *user,
                                const ag_extrude_batch_options *opt, ag_mesh **meshes,
                                ag_building_result *results, ag_error *err)
{
    memset(meshes, 0, n * sizeof *meshes);
    batch b;
    memset(&b, 0, sizeof b);
    b.n = n;
    b.nchunks = (n + CHUNK - 1) / CHUNK;
    b.build = build;
    b.user = user;
    b.opt = opt;
    b.extrude = opt ? &opt->extrude : NULL;
    b.per_building = 1;
    b.mesh = meshes;
    b.result = results;
    ag_status st = run(&b, err);
    if (st != AG_OK)
        free_meshes(meshes, n);
    return st;
}

typedef struct {
    const ag_footprints *f;
    const ag_style *style;
} styled;

static ag_status build_footprint(void *user, size_t i, const ag_extrude_options *opt,
                                 ag_mesh *m, ag_building_result *out, ag_error *err)
{
    const styled *s = user;
    const ag_footprint *fp = &s->f->items[i];
    size_t group = 0;
    ag_status st = ag_mesh_add_group(m, fp->id, &group);
    if (st != AG_OK)
        return ag_error_set(err, st, 0, "out of memory");
    return ag_building_extrude(s->style, (const double *const *)fp->loops, fp->sizes,
                               fp->nloops, fp->height, i, opt, m, (int32_t)group, out, err);
}

ag_status ag_extrude_batch(const ag_footprints *f, const ag_style *style,
                           const ag_extrude_batch_options *opt, ag_mesh *m,
                           ag_footprints_report *report, ag_error *err)
{
    memset(report, 0, sizeof *report);
    report->footprints = f->n;
    styled s = {f, style};
    batch b;
    memset(&b, 0, sizeof b);
    b.n = f->n;
    b.nchunks = (f->n + CHUNK - 1) / CHUNK;
    b.build = build_footprint;
    b.user = &s;
    b.opt = opt;
    b.extrude = opt ? &opt->extrude : NULL;
    b.mesh = calloc(b.nchunks ? b.nchunks : 1, sizeof *b.mesh);
    b.result = calloc(f->n ? f->n : 1, sizeof *b.result);
    ag_status st = b.mesh && b.result ? run(&b, err) : AG_ERR_NOMEM;
    /* in input order: the chunks' meshes, then each building's line in the report */
    for (size_t c = 0; st == AG_OK && c < b.nchunks; c++)
        st = ag_extrusion_append(m, b.mesh[c]);
    for (size_t i = 0; st == AG_OK && i < f->n; i++)
        st = ag_footprints_report_add(report, &f->items[i], &b.result[i]);
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory");
    free_meshes(b.mesh, b.nchunks);
    free(b.mesh);
    free(b.result);
    return st;
}
