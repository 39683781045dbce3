/* Shared by the edit tests (test_edit_*.c): proceduralize a generated mesh as the edit pipeline
 * does, and find split-tree nodes by position. Header-only because every test file is its own
 * binary; include it after <cmocka.h>. */
#ifndef AG_TEST_EDIT_FIXTURE_H
#define AG_TEST_EDIT_FIXTURE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "io/grammar_text.h"

/* Proceduralizes as the edit pipeline does: the edited mesh's components are kept as they are.
 * Checks that the grammar derives the mesh it came from and that its text parses back. */
static inline ag_proceduralize_result *proc(const ag_mesh *m)
{
    ag_proceduralize_options o = {.verify = 1, .segment.keep_groups = 1};
    ag_proceduralize_result *r = NULL;
    ag_error err = {0};
    if (ag_proceduralize_run(m, &o, &r, &err))
        fail_msg("proceduralize: %s", err.text);
    assert_int_equal(r->fidelity.unmatched, 0);
    assert_true(r->fidelity.relative < 1e-9);
    char *text = NULL;
    size_t len = 0;
    assert_int_equal(ag_grammar_text_print(r->grammar, &text, &len, &err), AG_OK);
    ag_grammar *g = NULL;
    long col = 0;
    if (ag_grammar_text_parse(text, len, &g, &err, &col))
        fail_msg("grammar does not parse: %s (line %ld)", err.text, err.element);
    assert_int_equal(g->nrules, r->grammar->nrules);
    ag_grammar_free(g);
    free(text);
    return r;
}

/* Generates a facade building and proceduralizes it; *tris (optional) gets its triangle count. */
static inline ag_proceduralize_result *proc_facade(const ag_gen_facade_options *o, size_t *tris)
{
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(o, &m, NULL), AG_OK);
    ag_proceduralize_result *r = proc(m);
    if (tris)
        *tris = m->ntris;
    ag_mesh_free(m);
    return r;
}

/* The smallest visible node whose box holds point (x, y, z); fails the test when there is none. */
static inline int32_t node_at(const ag_proceduralize_result *r, double x, double y, double z)
{
    const ag_splittree *t = r->tree;
    int32_t best = -1;
    double bv = INFINITY;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_COMPONENT)
            continue;
        const ag_box *b = &n->box;
        if (x < b->min[0] || x > b->max[0] || y < b->min[1] || y > b->max[1] || z < b->min[2] ||
            z > b->max[2])
            continue;
        double v = (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]) * (b->max[2] - b->min[2]);
        if (v < bv) {
            bv = v;
            best = (int32_t)i;
        }
    }
    assert_true(best >= 0);
    return best;
}

/* Is node a inside the subtree of node anc? */
static inline int below(const ag_splittree *t, int32_t a, int32_t anc)
{
    for (; a >= 0; a = t->nodes[a].parent)
        if (a == anc)
            return 1;
    return 0;
}

/* How many visible nodes carry label. */
static inline size_t label_instances(const ag_splittree *t, int32_t label)
{
    size_t n = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        n += t->nodes[i].kind == AG_NODE_COMPONENT && t->nodes[i].label == label;
    return n;
}

#endif
