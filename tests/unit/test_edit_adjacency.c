/* The adjacency an edited model carries (brought up to date by ag_rebuild from its input's,
 * core/proc/adjacency.h) after random sequences of edit ops on generated buildings: resizes
 * (local and global, every axis), splits, joins of two adjacent nodes, removals, pastes and
 * compositions (a saved part composed onto a node and grafted, as the service composes).
 * After every op the result's pairs are checked against a brute force over its visible boxes
 * (every pair, independently of the adjacency code) and against the pairs found from scratch
 * (the oracle, same order); and the update must have searched, not started over, on most ops
 * that changed few nodes (replayed from the input's pairs, as ag_rebuild runs it). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "core/parts/compose.h"
#include "core/parts/graft.h"
#include "core/parts/part.h"
#include "core/proc/adjacency.h"
#include "core/proc/grammar.h"
#include "adjacency_check.h"
#include "random_fixture.h"

/* the pairs found from scratch are t's, in the same order */
static void check_oracle(const ag_splittree *t, const char *what)
{
    ag_splittree *f = ag_splittree_copy(t);
    assert_non_null(f);
    assert_int_equal(ag_splittree_adjacency(f), AG_OK);
    if (f->nadj != t->nadj || (t->nadj && memcmp(f->adj, t->adj, 2 * t->nadj * sizeof *t->adj)))
        fail_msg("%s: %zu pairs carried, %zu found from scratch (or another order)", what,
                 t->nadj, f->nadj);
    ag_splittree_free(f);
}

/* Replays the update from `before`'s pairs onto after's boxes: 1 when it found every pair
 * from scratch, 0 when it searched the changed nodes. */
static int replay_from_scratch(const ag_splittree *before, const ag_splittree *after)
{
    ag_splittree *c = ag_splittree_copy(after), *b = ag_splittree_copy(before);
    assert_true(c && b);
    ag_splittree_adjacency_take(c, b);
    int scratch = -1;
    assert_int_equal(ag_splittree_adjacency_update(c, &scratch), AG_OK);
    assert_int_equal(c->nadj, after->nadj);
    assert_memory_equal(c->adj, after->adj, 2 * after->nadj * sizeof *after->adj);
    ag_splittree_free(c);
    ag_splittree_free(b);
    return scratch;
}

/* Visible nodes whose box or visibility differs between the two trees (node ids kept). */
static size_t changed_nodes(const ag_splittree *a, const ag_splittree *b)
{
    size_t n = a->nnodes > b->nnodes ? a->nnodes : b->nnodes, k = 0;
    for (size_t i = 0; i < n; i++) {
        int va = i < a->nnodes && a->nodes[i].kind == AG_NODE_COMPONENT;
        int vb = i < b->nnodes && b->nodes[i].kind == AG_NODE_COMPONENT;
        k += va != vb || (va && memcmp(&a->nodes[i].box, &b->nodes[i].box, sizeof(ag_box)));
    }
    return k;
}

static size_t visible(const ag_splittree *t)
{
    size_t v = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        v += t->nodes[n].kind == AG_NODE_COMPONENT;
    return v;
}

static int32_t random_visible(uint64_t *s, const ag_splittree *t)
{
    size_t nv = visible(t), k = nv ? next_random(s) % nv : 0;
    for (size_t n = 1; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && !k--)
            return (int32_t)n;
    return -1;
}

static int32_t random_leaf(uint64_t *s, const ag_splittree *t)
{
    for (int tries = 0; tries < 64; tries++) {
        int32_t n = random_visible(s, t);
        if (n > 0 && t->nodes[n].first_child < 0)
            return n;
    }
    return random_visible(s, t);
}

/* A visible node with visible nodes below it (a facade, a window of several pieces). */
static int32_t random_parent(uint64_t *s, const ag_splittree *t)
{
    for (int tries = 0; tries < 64; tries++) {
        int32_t n = random_visible(s, t);
        if (n > 0 && t->nodes[n].first_child >= 0)
            return n;
    }
    return -1;
}

/* A part saved from r's node `from`, composed onto `onto` and grafted: the new model, or NULL
 * when the composition or the graft does not apply there. */
static ag_edit_model *compose_graft(const ag_edit_model *em, int32_t from, int32_t onto)
{
    ag_part_meta meta = {.name = "piece"};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(em->proc, from, &meta, &p, &err))
        return NULL;
    ag_compose_op op = {.target = onto, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_NODE};
    ag_compose_report rep;
    ag_grammar *g = NULL;
    ag_mesh *derived = NULL;
    ag_proceduralize_result *out = NULL;
    ag_graft_report gr;
    ag_grammar_derive_options o = {0};
    ag_status s = ag_compose(em->proc, p, &op, &g, &rep, &err);
    if (!s)
        s = ag_grammar_derive(g, &o, &derived, &err);
    if (!s)
        s = ag_graft_compose(em->proc, &op, derived, NULL, &out, &gr, &err);
    ag_grammar_free(g);
    ag_mesh_free(derived);
    ag_part_free(p);
    ag_edit_model *m = NULL;
    if (s || ag_edit_model_wrap(out, &em->opt, &m, &err)) {
        if (!s)
            ag_proceduralize_result_free(out);
        return NULL;
    }
    return m;
}

/* One random op on em: the new model, or NULL when the op was refused there. */
static ag_edit_model *random_op(uint64_t *s, ag_edit_model *em, int kind, char *what,
                                size_t cap)
{
    const ag_splittree *t = em->proc->tree;
    ag_edit_op op = {0};
    int32_t sel[2] = {-1, -1};
    switch (kind) {
    case 0: { /* resize, local or global, on one axis */
        op.kind = AG_EDIT_RESIZE;
        op.node = random_visible(s, t);
        op.mode = next_random(s) % 2 ? AG_EDIT_LOCAL : AG_EDIT_GLOBAL;
        op.has_scale = 1;
        op.scale[0] = op.scale[1] = op.scale[2] = 1;
        op.scale[next_random(s) % 3] = uniform(s, 0.7, 1.4);
        snprintf(what, cap, "resize %d (%s)", op.node, op.mode ? "local" : "global");
        break;
    }
    case 1: { /* split at a random place along its longest axis */
        op.kind = AG_EDIT_SPLIT;
        op.node = random_leaf(s, t);
        const ag_box *b = &t->nodes[op.node].box;
        int a = 0;
        for (int k = 1; k < 3; k++)
            if (b->max[k] - b->min[k] > b->max[a] - b->min[a])
                a = k;
        op.axis = a;
        op.at = b->min[a] + uniform(s, 0.3, 0.7) * (b->max[a] - b->min[a]);
        snprintf(what, cap, "split %d", op.node);
        break;
    }
    case 2: /* join two nodes that meet (a pair of the adjacency) */
        if (!t->nadj)
            return NULL;
        {
            size_t p = next_random(s) % t->nadj;
            sel[0] = (int32_t)t->adj[2 * p];
            sel[1] = (int32_t)t->adj[2 * p + 1];
        }
        op.kind = AG_EDIT_JOIN;
        op.nnodes = 2;
        op.nodes = sel;
        snprintf(what, cap, "join %d %d", sel[0], sel[1]);
        break;
    case 3:
        sel[0] = random_visible(s, t);
        op.kind = AG_EDIT_REMOVE;
        op.nnodes = 1;
        op.nodes = sel;
        snprintf(what, cap, "remove %d", sel[0]);
        break;
    case 4:
        sel[0] = random_leaf(s, t);
        op.kind = AG_EDIT_PASTE;
        op.node = random_leaf(s, t);
        op.nnodes = 1;
        op.nodes = sel;
        op.placement = next_random(s) % 2 ? AG_EDIT_REPLACE : AG_EDIT_INSERT;
        op.fit = AG_EDIT_DERIVE;
        snprintf(what, cap, "paste %d onto %d", sel[0], op.node);
        break;
    default: {
        int32_t from = random_parent(s, t), onto = random_leaf(s, t);
        snprintf(what, cap, "compose %d onto %d", from, onto);
        return from > 0 && onto > 0 ? compose_graft(em, from, onto) : NULL;
    }
    }
    if (op.kind != AG_EDIT_JOIN && op.kind != AG_EDIT_REMOVE && op.node <= 0)
        return NULL;
    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    ag_status st = ag_edit_apply_ex(em, &op, 0, &out, &rep, &err);
    ag_edit_report_clear(&rep);
    return st ? NULL : out;
}

static void run_sequence(uint64_t seed, const ag_gen_facade_options *go, int nops,
                         size_t *applied, size_t *kinds, size_t *small, size_t *searched)
{
    uint64_t s = seed;
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(go, &m, NULL), AG_OK);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_create(m, NULL, &em, &err))
        fail_msg("proceduralize: %s", err.text);
    ag_mesh_free(m);
    adjacency_check_brute_force(em->proc->tree, "proceduralized");
    for (int k = 0; k < nops; k++) {
        int kind = (int)(next_random(&s) % 6);
        char what[96];
        ag_edit_model *out = random_op(&s, em, kind, what, sizeof what);
        if (!out)
            continue;
        char label[160];
        snprintf(label, sizeof label, "seed %llu op %d: %s", (unsigned long long)seed, k, what);
        const ag_splittree *before = em->proc->tree, *after = out->proc->tree;
        adjacency_check_brute_force(after, label);
        check_oracle(after, label);
        int scratch = replay_from_scratch(before, after);
        size_t ch = changed_nodes(before, after);
        if (ch * 8 < visible(after)) {
            (*small)++;
            *searched += !scratch;
        }
        (*applied)++;
        kinds[kind]++;
        ag_edit_model_free(em);
        em = out;
    }
    ag_edit_model_free(em);
}

static void test_random_edit_sequences(void **state)
{
    (void)state;
    const ag_gen_facade_options buildings[] = {
        {.cols = 6, .rows = 3, .side_cols = 4, .left = 1},
        {.cols = 5, .rows = 4, .side_cols = 3, .left = 1, .back = 1, .annex = 1},
        {.cols = 4, .rows = 3, .side_cols = 3, .left = 1, .bars = 1, .no_groups = 1, .annex = 1},
    };
    size_t applied = 0, kinds[6] = {0}, small = 0, searched = 0;
    for (uint64_t seed = 1; seed <= 12; seed++)
        run_sequence(seed * 7919, &buildings[seed % 3], 24, &applied, kinds, &small, &searched);
    /* every kind of op was applied somewhere, and the checks above ran on each */
    for (int k = 0; k < 6; k++)
        if (!kinds[k])
            fail_msg("no op of kind %d was applied (%zu ops in all)", k, applied);
    /* ops that changed few nodes were brought up to date by a search */
    assert_true(small >= 10);
    assert_true(searched * 10 >= small * 9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_edit_sequences),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
