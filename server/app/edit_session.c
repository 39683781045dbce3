#include "edit_session.h"

#include <jansson.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../io/meshblob.h"
#include "../store/grammars.h"
#include "../store/models.h"

typedef struct entry {
    ag_edit_state state;
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
    free(st->tree_to_node);
    free(st->node_to_tree);
    st->em = NULL;
    st->tree_to_node = st->node_to_tree = NULL;
    st->ntree = 0;
    st->version = 0;
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

/* --- matching the served tree with the in-memory one ----------------------------------- */

typedef struct {
    int32_t parent;
    int kind; /* ag_node_kind, as the served tree names it */
    double box[6];
} jnode;

static int jkind(const char *k)
{
    if (!k)
        return -1;
    if (strcmp(k, "root") == 0)
        return AG_NODE_ROOT;
    if (strcmp(k, "component") == 0)
        return AG_NODE_COMPONENT;
    if (strcmp(k, "pattern") == 0)
        return AG_NODE_PATTERN;
    return AG_NODE_SPLIT;
}

static double box_distance(const double a[6], const ag_box *b)
{
    double d = 0;
    for (int k = 0; k < 3; k++) {
        d = fmax(d, fabs(a[k] - b->min[k]));
        d = fmax(d, fabs(a[3 + k] - b->max[k]));
    }
    return d;
}

/* Live nodes below p, at most two levels down (a served node may skip one intermediate
 * split the in-memory tree has, or the other way round). */
static size_t candidates(const ag_splittree *t, int32_t p, int32_t *out, size_t cap)
{
    size_t n = 0;
    for (int32_t c = t->nodes[p].first_child; c >= 0; c = t->nodes[c].next_sibling) {
        if (t->nodes[c].kind == AG_NODE_DEAD)
            continue;
        if (n < cap)
            out[n++] = c;
        for (int32_t g = t->nodes[c].first_child; g >= 0; g = t->nodes[g].next_sibling)
            if (t->nodes[g].kind != AG_NODE_DEAD && n < cap)
                out[n++] = g;
    }
    return n;
}

ag_status ag_edit_session_map(const char *tree_json, const ag_splittree *t, int32_t **tree_to_node,
                              size_t *ntree, int32_t **node_to_tree, ag_error *err)
{
    *tree_to_node = *node_to_tree = NULL;
    *ntree = 0;
    json_t *doc = json_loads(tree_json, 0, NULL);
    json_t *nodes = json_object_get(doc, "nodes");
    size_t n = json_array_size(nodes);
    if (!n || t->nnodes == 0) {
        json_decref(doc);
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "the stored split tree is not readable");
    }
    jnode *j = calloc(n, sizeof *j);
    int32_t *t2n = malloc(n * sizeof *t2n), *n2t = malloc(t->nnodes * sizeof *n2t);
    size_t *first = calloc(n, sizeof *first), *next = calloc(n, sizeof *next);
    size_t *queue = malloc(n * sizeof *queue);
    /* a node's candidates are at most every live node */
    size_t cap = t->nnodes;
    int32_t *cand = malloc(cap * sizeof *cand);
    if (!j || !t2n || !n2t || !first || !next || !queue || !cand) {
        free(j), free(t2n), free(n2t), free(first), free(next), free(queue), free(cand);
        json_decref(doc);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    /* children lists of the served tree: first[i]/next[i] hold index + 1 */
    ag_box all = t->nodes[0].box;
    double tol = 1e-6 * fmax(1.0, ag_box_diagonal(&all));
    for (size_t i = 0; i < n; i++) {
        json_t *o = json_array_get(nodes, i), *b = json_object_get(o, "box");
        j[i].parent = json_is_integer(json_object_get(o, "parent"))
                          ? (int32_t)json_integer_value(json_object_get(o, "parent"))
                          : -1;
        j[i].kind = jkind(json_string_value(json_object_get(o, "kind")));
        for (int k = 0; k < 6; k++)
            j[i].box[k] = json_number_value(json_array_get(b, (size_t)k));
        t2n[i] = -1;
    }
    for (size_t i = 0; i < t->nnodes; i++)
        n2t[i] = -1;
    for (size_t i = n; i-- > 1;) {
        int32_t p = j[i].parent;
        if (p >= 0 && (size_t)p < n && (size_t)p != i) {
            next[i] = first[p];
            first[p] = i + 1;
        }
    }
    /* breadth first from the roots; a served node without a counterpart passes its parent's
     * counterpart on to its children */
    int32_t *anchor = malloc(n * sizeof *anchor);
    if (!anchor) {
        free(j), free(t2n), free(n2t), free(first), free(next), free(queue), free(cand);
        json_decref(doc);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t qh = 0, qt = 0;
    t2n[0] = 0;
    n2t[0] = 0;
    anchor[0] = 0;
    queue[qt++] = 0;
    while (qh < qt) {
        size_t i = queue[qh++];
        int32_t p = anchor[i];
        size_t nc = candidates(t, p, cand, cap), start = 0;
        for (size_t c = first[i]; c; c = next[c - 1]) {
            size_t ci = c - 1;
            int32_t best = -1;
            size_t bestk = 0;
            double bestd = INFINITY;
            /* both trees list siblings mostly in the same order: start after the last match
             * and stop at an exact one, so a pattern of many cells costs little */
            for (size_t step = 0; step < nc; step++) {
                size_t k = (start + step) % nc;
                int32_t q = cand[k];
                if (n2t[q] >= 0)
                    continue;
                double dd = box_distance(j[ci].box, &t->nodes[q].box);
                /* equal boxes: prefer the same kind, then the shallower node */
                if (t->nodes[q].kind != j[ci].kind)
                    dd += tol * 0.5;
                if (t->nodes[q].parent != p)
                    dd += tol * 0.25;
                if (dd < bestd) {
                    bestd = dd;
                    best = q;
                    bestk = k;
                }
                if (dd <= tol * 0.1)
                    break;
            }
            if (best >= 0 && bestd <= tol) {
                start = bestk + 1;
                t2n[ci] = best;
                n2t[best] = (int32_t)ci;
                anchor[ci] = best;
            } else {
                anchor[ci] = p;
            }
            if (qt < n)
                queue[qt++] = ci;
        }
    }
    free(anchor);
    free(j);
    free(first);
    free(next);
    free(queue);
    free(cand);
    json_decref(doc);
    *tree_to_node = t2n;
    *node_to_tree = n2t;
    *ntree = n;
    return AG_OK;
}

ag_status ag_edit_session_node(const ag_edit_state *st, int32_t id, const char *field,
                               int32_t *node, ag_error *err)
{
    if (id < 0 || (size_t)id >= st->ntree)
        return ag_error_set(err, AG_ERR_NOT_FOUND, id,
                            "%s: node %d is not in the model's split tree (nodes 0..%zu)", field,
                            (int)id, st->ntree ? st->ntree - 1 : 0);
    if (st->tree_to_node[id] < 0)
        return ag_error_set(err, AG_ERR_NOT_FOUND, id,
                            "%s: node %d of the split tree cannot be edited (it has no "
                            "counterpart in the model's structure)",
                            field, (int)id);
    *node = st->tree_to_node[id];
    return AG_OK;
}

/* --- loading ----------------------------------------------------------------------------- */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

ag_status ag_edit_session_replace(ag_edit_state *st, int64_t version, ag_edit_model *em,
                                  const char *tree_json, ag_error *err)
{
    ag_edit_session_reset(st);
    ag_status s = ag_edit_session_map(tree_json, em->proc->tree, &st->tree_to_node, &st->ntree,
                                      &st->node_to_tree, err);
    if (s != AG_OK) {
        ag_edit_model_free(em);
        return s;
    }
    st->em = em;
    st->version = version;
    return AG_OK;
}

static ag_status load(ag_db *db, ag_edit_state *st, int64_t version, ag_error *err)
{
    double t0 = now_ms();
    ag_grammar_row g;
    ag_error e;
    ag_error_clear(&e);
    ag_status s = ag_grammars_current(db, st->model, 1, &g, &e);
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
        (s = ag_edit_model_create(mesh, NULL, &em, err)) == AG_OK)
        s = ag_edit_session_replace(st, version, em, g.tree_json, err);
    free(blob);
    ag_mesh_free(mesh);
    ag_grammars_row_clear(&g);
    st->load_ms = now_ms() - t0;
    return s;
}

static entry *take_entry(ag_edit_sessions *r, int64_t model, ag_error *err)
{
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

ag_status ag_edit_session_acquire(ag_app *app, int64_t model, ag_edit_state **state,
                                  ag_error *err)
{
    *state = NULL;
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    entry *e = take_entry(ag__app_edit_sessions(app), model, err);
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
        ag_edit_session_release(app, &e->state);
        return s;
    }
    *state = &e->state;
    return AG_OK;
}

ag_status ag_edit_session_hold(ag_app *app, int64_t model, ag_edit_state **state, ag_error *err)
{
    entry *e = take_entry(ag__app_edit_sessions(app), model, err);
    *state = e ? &e->state : NULL;
    return e ? AG_OK : (err ? err->code : AG_ERR_BUSY);
}

void ag_edit_session_release(ag_app *app, ag_edit_state *state)
{
    if (!state)
        return;
    entry *e = (entry *)state; /* state is the entry's first member */
    ag_edit_sessions *r = ag__app_edit_sessions(app);
    pthread_mutex_unlock(&e->lock);
    pthread_mutex_lock(&r->lock);
    e->borrowed--;
    pthread_mutex_unlock(&r->lock);
}
