#include "edit_session.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../io/meshblob.h"
#include "../store/grammars.h"
#include "../store/models.h"
#include "cloud_pipeline.h"
#include "model_kept.h"
#include "model_state.h"
#include "model_tree.h"

typedef struct entry {
    ag_edit_state state;  /* first member: a state is its entry */
    pthread_mutex_t lock; /* held while borrowed */
    int borrowed;         /* guarded by the registry's lock */
    uint64_t used;        /* LRU tick */
} entry;

struct ag_edit_sessions {
    pthread_mutex_t lock;
    entry *items[AG_EDIT_SESSIONS_MAX];
    size_t n;
    uint64_t tick;
};

ag_edit_sessions *ag_edit_sessions_create(void)
{
    ag_edit_sessions *s = calloc(1, sizeof *s);
    if (s)
        pthread_mutex_init(&s->lock, NULL);
    return s;
}

void ag_edit_session_reset(ag_edit_state *st)
{
    ag_edit_model_free(st->em);
    st->em = NULL;
    st->version = 0;
    if (st->points_free)
        st->points_free(st->points);
    st->points = NULL;
    st->points_free = NULL;
    ag_trace_free(st->trace);
    st->trace = NULL;
    free(st->served);
    st->served = NULL;
}

ag_status ag_edit_session_served(ag_edit_state *st, const char **text, ag_error *err)
{
    *text = NULL;
    if (!st->em)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no model is loaded to describe");
    if (!st->served && !(st->served = ag_model_tree_served_text(st->em)))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory describing the model");
    *text = st->served;
    return AG_OK;
}

ag_status ag_edit_session_trace(ag_edit_state *st, const ag_trace **trace, ag_error *err)
{
    *trace = NULL;
    if (!st->em)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "no model is loaded to trace");
    if (!st->trace) {
        ag_status s = ag_trace_build(st->em->proc->grammar, 0, &st->trace, err);
        if (s != AG_OK)
            return s;
    }
    *trace = st->trace;
    return AG_OK;
}

static void entry_free(entry *e)
{
    if (!e)
        return;
    ag_edit_session_reset(&e->state);
    pthread_mutex_destroy(&e->lock);
    free(e);
}

void ag_edit_sessions_free(ag_edit_sessions *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < s->n; i++)
        entry_free(s->items[i]);
    pthread_mutex_destroy(&s->lock);
    free(s);
}

void ag_edit_session_replace(ag_edit_state *st, int64_t version, ag_edit_model *em)
{
    ag_edit_session_reset(st);
    st->em = em;
    st->version = version;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* A tree stored in the numbering before this one (read off the derivation) is replaced by
 * the loaded model's; a failure only means it is rebuilt again next time. */
static void renumber_stored_tree(ag_db *db, int64_t model, int64_t mesh_blob,
                                 const ag_edit_model *em)
{
    char *tree = ag_model_kept_tree_text(em);
    if (tree && ag_db_begin(db, NULL) == AG_OK) {
        if (ag_grammars_set_tree(db, model, mesh_blob, tree, AG_MODEL_TREE_NUMBERING, NULL) ==
            AG_OK)
            ag_db_commit(db, NULL);
        else
            ag_db_rollback(db);
    }
    free(tree);
}

static ag_status load(ag_db *db, ag_edit_state *st, int64_t version, ag_error *err)
{
    double t0 = now_ms();
    ag_grammar_row g;
    ag_error e;
    ag_error_clear(&e);
    /* a point cloud's model is a point model (app/store_ws_points.c), not an edit model */
    int cloud = 0;
    ag_status s = ag_cloud_pipeline_is_cloud(db, st->model, &cloud, err);
    if (s != AG_OK)
        return s;
    if (cloud)
        return ag_error_set(err, AG_ERR_CONFLICT, 0,
                            "model %lld is a point cloud: its point model takes the structural "
                            "ops (resize, split, join, paste, remove); parts and compositions "
                            "are for meshes",
                            (long long)st->model);
    s = ag_grammars_current(db, st->model, 1, &g, &e);
    if (s == AG_ERR_NOT_FOUND && strstr(e.text, "proceduralized"))
        return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                            "model %lld is not proceduralized: structural edits need a grammar "
                            "(POST /api/v1/models/%lld/proceduralize)",
                            (long long)st->model, (long long)st->model);
    if (s != AG_OK) {
        if (err)
            *err = e;
        return s;
    }
    void *blob = NULL;
    size_t len = 0;
    ag_mesh *mesh = NULL;
    ag_edit_model *em = NULL;
    if ((s = ag_blobs_get(db, g.mesh_blob, &blob, &len, err)) == AG_OK &&
        (s = ag_meshblob_decode(blob, len, &mesh, err)) == AG_OK &&
        (s = ag_model_state_reload_kept(mesh, g.tree_numbering == AG_MODEL_TREE_NUMBERING
                                                  ? g.tree_json
                                                  : NULL,
                                        &em, err)) == AG_OK) {
        if (g.tree_numbering != AG_MODEL_TREE_NUMBERING)
            renumber_stored_tree(db, st->model, g.mesh_blob, em);
        ag_edit_session_replace(st, version, em);
    }
    free(blob);
    ag_mesh_free(mesh);
    ag_grammars_row_clear(&g);
    st->load_ms = now_ms() - t0;
    return s;
}

static entry *take_entry(ag_edit_sessions *r, int64_t model, ag_error *err)
{
    if (!r) { /* no registry: a state of its own */
        entry *e = calloc(1, sizeof *e);
        if (!e) {
            ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            return NULL;
        }
        pthread_mutex_init(&e->lock, NULL);
        e->state.model = model;
        return e;
    }
    pthread_mutex_lock(&r->lock);
    entry *e = NULL;
    for (size_t i = 0; i < r->n && !e; i++)
        if (r->items[i]->state.model == model)
            e = r->items[i];
    if (!e) {
        if (r->n == AG_EDIT_SESSIONS_MAX) {
            size_t victim = r->n;
            for (size_t i = 0; i < r->n; i++)
                if (!r->items[i]->borrowed &&
                    (victim == r->n || r->items[i]->used < r->items[victim]->used))
                    victim = i;
            if (victim == r->n) {
                pthread_mutex_unlock(&r->lock);
                ag_error_set(err, AG_ERR_BUSY, 0, "too many models are being edited at once");
                return NULL;
            }
            entry_free(r->items[victim]);
            r->items[victim] = r->items[--r->n];
        }
        if (!(e = calloc(1, sizeof *e))) {
            pthread_mutex_unlock(&r->lock);
            ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            return NULL;
        }
        pthread_mutex_init(&e->lock, NULL);
        e->state.model = model;
        r->items[r->n++] = e;
    }
    e->borrowed++;
    e->used = ++r->tick;
    pthread_mutex_unlock(&r->lock);
    pthread_mutex_lock(&e->lock);
    return e;
}

ag_status ag_edit_session_acquire(ag_edit_sessions *reg, ag_db *db, int64_t model,
                                  ag_edit_state **state, ag_error *err)
{
    *state = NULL;
    entry *e = take_entry(reg, model, err);
    if (!e)
        return err ? err->code : AG_ERR_BUSY;
    ag_model_row row;
    ag_status s = ag_models_get(db, model, &row, err);
    if (s == AG_OK) {
        int64_t version = row.version;
        ag_models_row_clear(&row);
        if (e->state.version != version)
            s = load(db, &e->state, version, err);
    }
    if (s != AG_OK) {
        ag_edit_session_reset(&e->state);
        ag_edit_session_release(reg, &e->state);
        return s;
    }
    *state = &e->state;
    return AG_OK;
}

ag_status ag_edit_session_hold(ag_edit_sessions *reg, int64_t model, ag_edit_state **state,
                               ag_error *err)
{
    entry *e = take_entry(reg, model, err);
    *state = e ? &e->state : NULL;
    return e ? AG_OK : (err ? err->code : AG_ERR_BUSY);
}

void ag_edit_session_release(ag_edit_sessions *reg, ag_edit_state *state)
{
    if (!state)
        return;
    entry *e = (entry *)state;
    if (!reg) {
        entry_free(e);
        return;
    }
    pthread_mutex_unlock(&e->lock);
    pthread_mutex_lock(&reg->lock);
    e->borrowed--;
    pthread_mutex_unlock(&reg->lock);
}
