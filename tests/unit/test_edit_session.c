/* The map between the split tree the service serves (read off the grammar's derivation) and
 * the edit model's tree (its proceduralization): on a generated facade every served node has a
 * counterpart with the same box and a compatible kind, the two directions agree, and a tree
 * that is not JSON is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "app/edit_session.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "core/proc/proceduralize.h"
#include "io/splittree_json.h"

static void served_tree_maps_onto_the_edit_tree(void **state)
{
    (void)state;
    ag_error err;
    ag_mesh *m = NULL;
    ag_gen_facade_options o = {.cols = 5, .rows = 3, .annex = 1};
    assert_int_equal(ag_gen_facade(&o, &m, &err), AG_OK);
    ag_proceduralize_result *r = NULL;
    assert_int_equal(ag_proceduralize_run(m, NULL, &r, &err), AG_OK);
    /* what the service stores: the derived mesh and the tree read off the derivation */
    ag_mesh *derived = NULL;
    assert_int_equal(ag_grammar_derive(r->grammar, NULL, &derived, &err), AG_OK);
    char *json = NULL;
    size_t ncomp = 0;
    assert_int_equal(ag_splittree_json_build(r->grammar, NULL, &json, &ncomp, &err), AG_OK);
    ag_edit_model *em = NULL;
    assert_int_equal(ag_edit_model_create(derived, NULL, &em, &err), AG_OK);

    int32_t *t2n = NULL, *n2t = NULL;
    size_t n = 0;
    assert_int_equal(ag_edit_session_map(json, em->proc->tree, &t2n, &n, &n2t, &err), AG_OK);
    json_t *doc = json_loads(json, 0, NULL);
    json_t *nodes = json_object_get(doc, "nodes");
    assert_int_equal(n, json_array_size(nodes));
    const ag_splittree *t = em->proc->tree;
    double diag = ag_box_diagonal(&t->nodes[0].box);
    size_t visible = 0;
    for (size_t i = 0; i < n; i++) {
        json_t *jn = json_array_get(nodes, i);
        assert_true(t2n[i] >= 0);
        const ag_tnode *tn = &t->nodes[t2n[i]];
        assert_int_not_equal(tn->kind, AG_NODE_DEAD);
        assert_int_equal(n2t[t2n[i]], (int32_t)i);
        json_t *box = json_object_get(jn, "box");
        for (int k = 0; k < 3; k++) {
            assert_true(fabs(json_number_value(json_array_get(box, k)) - tn->box.min[k]) <= 1e-6 * diag);
            assert_true(fabs(json_number_value(json_array_get(box, 3 + k)) - tn->box.max[k]) <= 1e-6 * diag);
        }
        if (json_is_true(json_object_get(jn, "visible"))) {
            assert_int_equal(tn->kind, AG_NODE_COMPONENT);
            visible++;
        }
    }
    assert_int_equal(visible, ncomp);

    int32_t *a, *b;
    size_t na;
    assert_int_equal(ag_edit_session_map("not json", t, &a, &na, &b, &err), AG_ERR_INTERNAL);
    assert_null(a);

    json_decref(doc);
    free(t2n);
    free(n2t);
    free(json);
    ag_edit_model_free(em);
    ag_mesh_free(derived);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(served_tree_maps_onto_the_edit_tree)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
