#include "rebase.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../store/ops.h"
#include "../store/states.h"
#include "model_kept.h"
#include "model_tree.h"

/* --- the ops that came since the base ------------------------------------------------------ */

typedef struct {
    int64_t version;
    char kind[32];
    char author[128];
    unsigned flags;
} later_op;

typedef struct {
    later_op *ops;
    size_t n, cap;
    int nomem;
} later_list;

static void collect(void *user, const ag_op_row *op)
{
    later_list *l = user;
    if (l->nomem)
        return;
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 16;
        later_op *grown = realloc(l->ops, cap * sizeof *grown);
        if (!grown) {
            l->nomem = 1;
            return;
        }
        l->ops = grown;
        l->cap = cap;
    }
    later_op *o = &l->ops[l->n++];
    o->version = op->version;
    snprintf(o->kind, sizeof o->kind, "%s", op->kind);
    snprintf(o->author, sizeof o->author, "%s", op->author ? op->author : "");
    const ag_op_kind *row = ag_optable_find(op->kind);
    o->flags = row ? row->flags : AG_OP_GEOMETRY; /* a kind unknown today: assume the worst */
}

static ag_status conflict(const later_op *o, int64_t base, int64_t current, const char *what,
                          ag_error *err)
{
    return ag_error_set(err, AG_ERR_STALE, (long)current,
                        "the %s op of version %lld by %s %s since version %lld, the one this op "
                        "was made on; make it again on version %lld",
                        o->kind, (long long)o->version, o->author, what, (long long)base,
                        (long long)current);
}

/* --- trees --------------------------------------------------------------------------------- */

static const json_t *node_at(const json_t *tree, int64_t id)
{
    const json_t *n = json_array_get(json_object_get(tree, "nodes"), (size_t)id);
    return id >= 0 && json_integer_value(json_object_get(n, "id")) == id ? n : NULL;
}

static int read_box(const json_t *node, double b[6])
{
    const json_t *box = json_object_get(node, "box");
    if (json_array_size(box) != 6)
        return 0;
    for (size_t k = 0; k < 6; k++) {
        const json_t *v = json_array_get(box, k);
        if (!json_is_number(v))
            return 0;
        b[k] = json_number_value(v);
    }
    return 1;
}

int64_t ag_rebase_map_node(const json_t *tree_a, const json_t *tree_b, int64_t id)
{
    const json_t *a = node_at(tree_a, id);
    const char *kind = json_string_value(json_object_get(a, "kind"));
    double box[6], root[6];
    if (!a || !kind || strcmp(kind, "dead") == 0 || !read_box(a, box))
        return -1;
    double diag = 1;
    if (read_box(node_at(tree_a, 0), root))
        diag = fmax(1, sqrt((root[3] - root[0]) * (root[3] - root[0]) +
                            (root[4] - root[1]) * (root[4] - root[1]) +
                            (root[5] - root[2]) * (root[5] - root[2])));
    double eps = 1e-6 * diag;
    /* edits keep the ids of the nodes they leave alone: the node with its id, when unchanged */
    const json_t *same = node_at(tree_b, id);
    const char *same_kind = json_string_value(json_object_get(same, "kind"));
    double sb[6];
    if (same && same_kind && strcmp(same_kind, kind) == 0 && read_box(same, sb)) {
        int unchanged = 1;
        for (int c = 0; c < 6 && unchanged; c++)
            unchanged = fabs(sb[c] - box[c]) <= eps;
        if (unchanged)
            return id;
    }
    const json_t *nodes = json_object_get(tree_b, "nodes");
    int64_t found = -1;
    size_t count = 0;
    int same_id = 0;
    for (size_t i = 0; i < json_array_size(nodes); i++) {
        const json_t *b = json_array_get(nodes, i);
        const char *k = json_string_value(json_object_get(b, "kind"));
        double bb[6];
        if (!k || strcmp(k, kind) != 0 || !read_box(b, bb))
            continue;
        int same = 1;
        for (int c = 0; c < 6 && same; c++)
            same = fabs(bb[c] - box[c]) <= eps;
        if (!same)
            continue;
        count++;
        found = json_integer_value(json_object_get(b, "id"));
        same_id |= found == id;
    }
    if (count == 1)
        return found;
    return count > 1 && same_id ? id : -1; /* twins: only keeping its id is certain */
}

/* Is node id dead in tree b (an edit removed it)? */
static int removed(const json_t *tree_b, int64_t id)
{
    const json_t *b = node_at(tree_b, id);
    const char *kind = json_string_value(json_object_get(b, "kind"));
    return b && kind && strcmp(kind, "dead") == 0;
}

/* --- the op's node ids ---------------------------------------------------------------------- */

static int64_t ref_id(const json_t *v)
{
    if (json_is_integer(v))
        return json_integer_value(v);
    const char *s = json_string_value(v);
    if (!s)
        return -1;
    if (strcmp(s, "root") == 0)
        return 0;
    char *end;
    long long n = strtoll(s, &end, 10);
    return *s && !*end && n >= 0 ? n : -1;
}

/* Rewrites one reference from tree a to tree b: 0 when it is not there unchanged (*lost
 * gets its id). */
static int map_ref(json_t *holder, const char *key, size_t index, const json_t *ta,
                   const json_t *tb, int64_t *lost)
{
    json_t *v = key ? json_object_get(holder, key) : json_array_get(holder, index);
    int64_t id = ref_id(v), to = id >= 0 ? ag_rebase_map_node(ta, tb, id) : -1;
    if (to < 0) {
        *lost = id;
        return 0;
    }
    if (to == id)
        return 1;
    json_t *nv = json_integer(to);
    if (key)
        json_object_set_new(holder, key, nv);
    else
        json_array_set_new(holder, index, nv);
    return 1;
}

/* Every node the op names, from tree a to tree b; 0 with *lost when one is not there. */
static int map_op(json_t *op, int64_t model, const json_t *ta, const json_t *tb, int64_t *lost)
{
    static const char *const single[] = {"node", "target"};
    for (size_t i = 0; i < 2; i++)
        if (json_object_get(op, single[i]) && !map_ref(op, single[i], 0, ta, tb, lost))
            return 0;
    /* a paste's source is this model's only when it names no other */
    const json_t *sm = json_object_get(op, "source_model");
    int own_source = !sm || json_integer_value(sm) == model;
    const char *lists[] = {"nodes", own_source ? "source" : NULL};
    for (size_t i = 0; i < 2; i++) {
        json_t *list = lists[i] ? json_object_get(op, lists[i]) : NULL;
        for (size_t k = 0; k < json_array_size(list); k++)
            if (!map_ref(list, NULL, k, ta, tb, lost))
                return 0;
    }
    return 1;
}

/* The nodes' kinds and boxes of a bare stored tree (app/model_kept.h), as a served tree has
 * them; NULL when it keeps no valid tree. */
static json_t *kept_boxes(const char *tree_text)
{
    ag_splittree *t = NULL;
    if (ag_model_kept_tree(tree_text, &t, NULL) != AG_OK)
        return NULL;
    json_t *tree = ag_model_tree_boxes(t);
    ag_splittree_free(t);
    return tree;
}

/* The served tree kept with version v, parsed (a bare one's boxes); NULL when none was kept in today's numbering. */
static json_t *tree_of(ag_db *db, int64_t model, int64_t v, ag_status *s, ag_error *err)
{
    ag_state_row row = {0};
    ag_error e;
    *s = ag_states_get(db, model, v, &row, &e);
    json_t *tree = NULL;
    if (*s == AG_OK && row.tree_json && row.tree_numbering == AG_MODEL_TREE_NUMBERING)
        tree = ag_model_kept_serves(row.tree_json) ? json_loads(row.tree_json, 0, NULL)
                                                   : kept_boxes(row.tree_json);
    else if (*s != AG_OK && *s != AG_ERR_NOT_FOUND && err)
        *err = e;
    if (*s == AG_ERR_NOT_FOUND)
        *s = AG_OK; /* not kept: the caller calls it a conflict */
    ag_states_row_clear(&row);
    return tree;
}

ag_status ag_rebase_op(const ag_store_env *env, const ag_op_request *rq, const ag_op_kind *row,
                       int64_t current, int64_t *onto, json_t **op, ag_error *err)
{
    *onto = rq->base;
    *op = NULL;
    if (rq->base >= current || row->rebase == AG_REBASE_ALWAYS) {
        if (row->rebase == AG_REBASE_ALWAYS)
            *onto = current;
        return AG_OK;
    }
    later_list later = {0};
    ag_status s = ag_ops_each_since(env->db, rq->model, rq->base, 0, collect, &later, err);
    if (s == AG_OK && later.nomem)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s != AG_OK) {
        free(later.ops);
        return s;
    }
    const later_op *first_geometry = NULL, *same_kind = NULL;
    const char *kind = json_string_value(json_object_get(rq->op, "kind"));
    for (size_t i = 0; i < later.n; i++) {
        if (!first_geometry && (later.ops[i].flags & AG_OP_GEOMETRY))
            first_geometry = &later.ops[i];
        if (!same_kind && kind && strcmp(later.ops[i].kind, kind) == 0)
            same_kind = &later.ops[i];
    }
    switch (row->rebase) {
    case AG_REBASE_UNLESS_SAME:
        s = same_kind ? conflict(same_kind, rq->base, current, "came", err) : AG_OK;
        break;
    case AG_REBASE_OVER_CONTENT:
        s = first_geometry ? conflict(first_geometry, rq->base, current, "changed the geometry",
                                      err)
                           : AG_OK;
        break;
    case AG_REBASE_NODES:
        if (!first_geometry)
            break;
        {
            json_t *copy = json_deep_copy(rq->op);
            /* the tree at the base is the one before the first geometry op: only ops that
             * leave the geometry alone lie between, and that op kept its state before it */
            json_t *ta = tree_of(env->db, rq->model, first_geometry->version - 1, &s, err);
            if (!copy && s == AG_OK)
                s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            if (s == AG_OK && !ta)
                s = conflict(first_geometry, rq->base, current,
                             "changed the geometry (no tree of that version is kept)", err);
            /* through the tree after each geometry op in turn: the first that lost a node is
             * the conflict */
            for (size_t i = 0; s == AG_OK && i < later.n; i++) {
                const later_op *g = &later.ops[i];
                if (!(g->flags & AG_OP_GEOMETRY))
                    continue;
                json_t *tb = tree_of(env->db, rq->model, g->version, &s, err);
                int64_t lost = -1;
                char what[96];
                if (s == AG_OK && !tb)
                    s = conflict(g, rq->base, current, "changed the geometry", err);
                else if (s == AG_OK && !map_op(copy, rq->model, ta, tb, &lost)) {
                    snprintf(what, sizeof what, "%s node %lld",
                             removed(tb, lost) ? "removed" : "changed", (long long)lost);
                    s = conflict(g, rq->base, current, what, err);
                }
                json_decref(ta);
                ta = tb;
            }
            json_decref(ta);
            if (s == AG_OK)
                *op = copy;
            else
                json_decref(copy);
        }
        break;
    default: /* AG_REBASE_NEVER */
        s = later.n ? conflict(&later.ops[0], rq->base, current, "came", err) : AG_OK;
        break;
    }
    free(later.ops);
    if (s == AG_OK)
        *onto = current;
    return s;
}
