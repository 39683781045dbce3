/* A composition's new state with its read-back beside the maker
 * (app/model_state.h ag_model_state_from_grammar_start) against the synchronous path
 * (ag_model_state_from_grammar_ex: printed, read back, that derivation given to the maker), on
 * generated buildings (parts_fixture.h) for replace, insert and fill in node and rule scope:
 * the same text, terminals, derived mesh and tree, byte for byte; a grammar that does not
 * read back is refused by the check; the mesh comparison the check makes is exact. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "app/model_state.h"
#include "core/edit/edit.h"
#include "core/parts/compose.h"
#include "core/parts/graft.h"
#include "core/parts/part.h"
#include "parts_fixture.h"

#define TOL 1e-6

/* The maker the store's composition uses: the part grafted into the model's tree, else the
 * derivation proceduralized. */
typedef struct {
    const ag_edit_model *model;
    const ag_compose_op *op;
    const ag_mesh *given; /* the derivation the maker was given */
    int grafted;
} maker;

static ag_status make_grafted(void *user, const ag_mesh *derived, ag_edit_model **em,
                              ag_error *err)
{
    maker *mk = user;
    mk->given = derived;
    ag_proceduralize_result *r = NULL;
    ag_graft_report rep;
    ag_status s = ag_graft_compose(mk->model->proc, mk->op, derived, &mk->model->opt.patterns,
                                   &r, &rep, err);
    if (s == AG_ERR_NOT_AVAILABLE)
        return ag_model_state_reload(derived, em, err);
    if (s == AG_OK && (s = ag_edit_model_wrap(r, &mk->model->opt, em, err)) != AG_OK)
        ag_proceduralize_result_free(r);
    mk->grafted += s == AG_OK;
    return s;
}

static void same_tree(const ag_splittree *a, const ag_splittree *b)
{
    assert_int_equal(a->nnodes, b->nnodes);
    assert_int_equal(a->ncomponents, b->ncomponents);
    assert_int_equal(a->npatterns, b->npatterns);
    for (size_t n = 0; n < a->nnodes; n++) {
        const ag_tnode *x = &a->nodes[n], *y = &b->nodes[n];
        assert_memory_equal(&x->box, &y->box, sizeof x->box);
        assert_memory_equal(x->pivot, y->pivot, sizeof x->pivot);
        assert_true(x->parent == y->parent && x->first_child == y->first_child &&
                    x->last_child == y->last_child && x->next_sibling == y->next_sibling);
        assert_true(x->component == y->component && x->label == y->label &&
                    x->variant == y->variant && x->rule == y->rule && x->pattern == y->pattern);
        assert_true(x->rot == y->rot && x->kind == y->kind && x->octant == y->octant &&
                    x->rule_rot == y->rule_rot);
    }
    if (a->ncomponents)
        assert_memory_equal(a->comp_node, b->comp_node, a->ncomponents * sizeof *a->comp_node);
}

static void same_state(const ag_model_state *a, const ag_model_state *b)
{
    assert_int_equal(a->text_len, b->text_len);
    assert_memory_equal(a->text, b->text, a->text_len);
    assert_int_equal(a->terms.n, b->terms.n);
    for (size_t i = 0; i < a->terms.n; i++) {
        assert_string_equal(a->terms.path[i], b->terms.path[i]);
        assert_int_equal(a->terms.len[i], b->terms.len[i]);
        assert_memory_equal(a->terms.obj[i], b->terms.obj[i], a->terms.len[i]);
    }
    assert_string_equal(ag_mesh_difference(a->derived, b->derived), "");
    assert_string_equal(ag_mesh_difference(a->em->proc->mesh, b->em->proc->mesh), "");
    same_tree(a->em->proc->tree, b->em->proc->tree);
}

/* Composes the window part into building b at target (the node with box `at`) both ways and
 * compares the states; returns how many of the two were grafted. */
static int compare_paths(const pf_options *b, const ag_part *part, const ag_box *at, int mode,
                         int scope)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(b, &slots, &ns);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_model_create(m, NULL, &em, &err), AG_OK);
    int32_t target = pf_node_with_box(em->proc, at ? at : &slots[0], TOL);
    assert_true(target > 0);
    ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
    ag_grammar *g1 = NULL, *g2 = NULL;
    ag_compose_report rep;
    if (ag_compose(em->proc, part, &op, &g1, &rep, &err) ||
        ag_compose(em->proc, part, &op, &g2, &rep, &err))
        fail_msg("compose: %s", err.text);
    maker m1 = {.model = em, .op = &op}, m2 = m1;
    ag_model_state sync, beside;
    if (ag_model_state_from_grammar_ex(g1, 0, make_grafted, &m1, &sync, &err))
        fail_msg("synchronous: %s", err.text);
    if (ag_model_state_from_grammar_start(&g2, 0, make_grafted, &m2, &beside, &err))
        fail_msg("beside: %s", err.text);
    assert_null(g2); /* the check took it */
    assert_ptr_equal(m2.given, beside.derived); /* the maker had the state's derivation */
    assert_int_equal(ag_model_state_checked(&beside, &err), AG_OK);
    assert_true(beside.text && beside.text_len > 0);
    same_state(&sync, &beside);
    assert_int_equal(m1.grafted, m2.grafted);
    ag_model_state_clear(&sync);
    ag_model_state_clear(&beside);
    ag_grammar_free(g1);
    ag_edit_model_free(em);
    free(slots);
    ag_mesh_free(m);
    return m1.grafted + m2.grafted;
}

/* B's blank back wall (the fill test's wall of test_parts_compose.c). */
static ag_box back_wall(const pf_options *b)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(b, &slots, &ns);
    ag_box bounds = ag_mesh_bounds(m);
    double Dp = bounds.max[1] - 0.2; /* the roof overhangs by 0.2 */
    free(slots);
    ag_mesh_free(m);
    return (ag_box){{0, Dp - 0.3, 0}, {11.2, Dp, 10.6}};
}

static void test_replace_node_and_rule(void **state)
{
    (void)state;
    pf_options a = pf_design_a(PF_RECESSED, 0, 0, 0);
    ag_part *part = pf_window_part(&a, 0, NULL);
    for (int turn = 0; turn < 4; turn += 3) {
        /* turned and far from the origin: the numbers need all their printed digits */
        pf_options b = pf_design_b(PF_RECESSED, turn, turn ? 512345.678 : 0,
                                   turn ? 5412345.678 : 0);
        int grafted = compare_paths(&b, part, NULL, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE);
        grafted += compare_paths(&b, part, NULL, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE);
        print_message("turn %d: %d of 4 states grafted\n", turn, grafted);
    }
    ag_part_free(part);
}

static void test_insert_and_fill(void **state)
{
    (void)state;
    pf_options a = pf_design_a(PF_FLUSH, 0, 0, 0), b = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_part *part = pf_window_part(&a, 2, NULL);
    ag_box wall = back_wall(&b);
    compare_paths(&b, part, &wall, AG_COMPOSE_FILL, AG_COMPOSE_NODE);
    compare_paths(&b, part, &wall, AG_COMPOSE_INSERT, AG_COMPOSE_NODE);
    ag_part_free(part);
}

/* A composed grammar of building b's first window replaced by the part. */
static ag_grammar *composed(const pf_options *b, const ag_part *part, ag_mesh **m)
{
    ag_box *slots;
    size_t ns;
    *m = pf_building(b, &slots, &ns);
    ag_proceduralize_result *r = pf_proc(*m);
    int32_t target = pf_node_with_box(r, &slots[0], TOL);
    ag_compose_op op = {.target = target, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_NODE};
    ag_grammar *g = NULL;
    ag_compose_report rep;
    ag_error err = {0};
    if (ag_compose(r, part, &op, &g, &rep, &err))
        fail_msg("compose: %s", err.text);
    free(slots);
    ag_proceduralize_result_free(r);
    return g;
}

/* A grammar that derives but whose text does not parse (a terminal named with a blank) is
 * refused by the check, after the maker ran, as the synchronous path refuses it at once. */
static void test_text_that_does_not_read_back_is_refused(void **state)
{
    (void)state;
    pf_options a = pf_design_a(PF_RECESSED, 0, 0, 0), b = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_part *part = pf_window_part(&a, 0, NULL);
    for (int beside = 0; beside < 2; beside++) {
        ag_mesh *m;
        ag_grammar *g = composed(&b, part, &m);
        free(g->terminals[0].name);
        g->terminals[0].name = strdup("a blank");
        ag_model_state st;
        ag_error err = {0};
        ag_status s;
        if (beside) {
            assert_int_equal(ag_model_state_from_grammar_start(&g, 0, NULL, NULL, &st, &err),
                             AG_OK);
            assert_non_null(st.em); /* made meanwhile */
            s = ag_model_state_checked(&st, &err);
        } else {
            s = ag_model_state_from_grammar_ex(g, 0, NULL, NULL, &st, &err);
        }
        assert_int_equal(s, AG_ERR_INTERNAL);
        print_message("%s\n", err.text);
        assert_non_null(strstr(err.text, "does not read back"));
        ag_model_state_clear(&st);
        ag_grammar_free(g);
        ag_mesh_free(m);
    }
    ag_part_free(part);
}

/* A state cleared while its check runs waits for it (no leak, no use after free: the
 * sanitizer build runs this too); past the budget, nothing starts and g stays the caller's. */
static void test_clear_while_checking_and_budget(void **state)
{
    (void)state;
    pf_options a = pf_design_a(PF_RECESSED, 0, 0, 0), b = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_part *part = pf_window_part(&a, 0, NULL);
    ag_mesh *m;
    ag_grammar *g = composed(&b, part, &m);
    ag_model_state st;
    ag_error err = {0};
    assert_int_equal(ag_model_state_from_grammar_start(&g, 0, NULL, NULL, &st, &err), AG_OK);
    ag_model_state_clear(&st);
    assert_null(st.check);
    ag_grammar_free(g);
    ag_mesh_free(m);
    g = composed(&b, part, &m);
    assert_int_equal(ag_model_state_from_grammar_start(&g, 10, NULL, NULL, &st, &err),
                     AG_ERR_TOO_LARGE);
    assert_non_null(g);
    assert_non_null(strstr(err.text, "more than 10 triangles"));
    assert_null(st.em);
    ag_grammar_free(g);
    ag_mesh_free(m);
    ag_part_free(part);
}

/* The check's comparison is exact: one vertex one ulp off, one triangle's component, one
 * group's name are each a difference it names. */
static void test_mesh_difference_is_exact(void **state)
{
    (void)state;
    pf_options b = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(&b, &slots, &ns);
    ag_mesh *c = ag_mesh_clone(m);
    assert_string_equal(ag_mesh_difference(m, c), "");
    c->pos[7] = nextafter(c->pos[7], INFINITY);
    assert_string_equal(ag_mesh_difference(m, c), "the vertices");
    c->pos[7] = m->pos[7];
    c->tri_component[3] ^= 1;
    assert_string_equal(ag_mesh_difference(m, c), "the triangles");
    c->tri_component[3] = m->tri_component[3];
    c->group_names[1][0] ^= 1;
    assert_string_equal(ag_mesh_difference(m, c), "the group names");
    c->group_names[1][0] = m->group_names[1][0];
    c->ntris--;
    assert_string_equal(ag_mesh_difference(m, c), "the vertex or triangle counts");
    c->ntris++;
    ag_mesh_free(c);
    free(slots);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_replace_node_and_rule),
        cmocka_unit_test(test_insert_and_fill),
        cmocka_unit_test(test_text_that_does_not_read_back_is_refused),
        cmocka_unit_test(test_clear_while_checking_and_budget),
        cmocka_unit_test(test_mesh_difference_is_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
