/* The bare stored tree (app/model_kept.h): what an edit stores is the kept member alone, and
 * everything the service serves from it must be what the full text gave. On generated box
 * buildings (edit_building_fixture.h: recessed, flush and proud windows, turned, at UTM
 * offsets) with dead nodes between and after the live ones:
 * - the bare text is the full text's kept member, and only the full text says it serves;
 * - the model reloaded from the bare text has every node under its id, and prints the same
 *   served tree byte for byte (a restart serves what the running service served);
 * - the tree a rebase reads from the bare text (ag_model_kept_tree, ag_model_tree_boxes) maps
 *   every node as the served tree itself does, read with the rebase's own matcher;
 * - a bare text cut short, one whose data is not base64, or one that keeps nothing, is
 *   refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/model_kept.h"
#include "app/model_tree.h"
#include "app/rebase.h"
#include "core/edit/edit.h"
#include "edit_building_fixture.h"

#define EXTRA_DEAD 5000

/* A variant's edit model with dead nodes added after the live ones (as edits leave them). */
static ag_edit_model *model_of(const bb_options *o, ag_mesh **mesh)
{
    *mesh = bb_generate(o);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_create(*mesh, NULL, &em, &err))
        fail_msg("the fixture does not proceduralize: %s", err.text);
    for (size_t i = 0; i < EXTRA_DEAD; i++)
        assert_true(ag_splittree_add_node(em->proc->tree, AG_NODE_DEAD) >= 0);
    return em;
}

static void bare_text_reloads_and_serves_the_same(void **state)
{
    (void)state;
    size_t nv;
    const bb_options *v = bb_id_variants(&nv);
    for (size_t i = 0; i < nv; i++) {
        ag_mesh *m = NULL;
        ag_edit_model *em = model_of(&v[i], &m);
        char *full = ag_model_kept_tree_text(em), *bare = ag_model_kept_bare_text(em);
        assert_non_null(full);
        assert_non_null(bare);
        assert_true(ag_model_kept_serves(full));
        assert_false(ag_model_kept_serves(bare));
        /* the same kept member: {"kept":K} and {...served...,"kept":K} */
        const char *k = strstr(full, ",\"kept\":");
        assert_non_null(k);
        assert_string_equal(bare + 1, k + 1);
        if (strlen(bare) * 2 > strlen(full))
            fail_msg("variant %zu: the bare text (%zu bytes) is not much shorter than the full "
                     "one (%zu)",
                     i, strlen(bare), strlen(full));

        ag_edit_model *back = NULL;
        ag_error err = {0};
        if (ag_model_kept_reload(em->proc->mesh, bare, &back, &err))
            fail_msg("variant %zu: the bare text does not reload: %s", i, err.text);
        const ag_splittree *a = em->proc->tree, *b = back->proc->tree;
        assert_int_equal(b->nnodes, a->nnodes);
        for (size_t n = 0; n < a->nnodes; n++) {
            assert_int_equal(b->nodes[n].kind, a->nodes[n].kind);
            if (a->nodes[n].kind == AG_NODE_DEAD)
                continue;
            assert_int_equal(b->nodes[n].parent, a->nodes[n].parent);
            assert_memory_equal(&b->nodes[n].box, &a->nodes[n].box, sizeof a->nodes[n].box);
        }
        char *served = ag_model_tree_served_text(em), *served_back = ag_model_tree_served_text(back);
        assert_non_null(served);
        assert_non_null(served_back);
        assert_string_equal(served_back, served);
        char *stripped = ag_model_kept_served_text(full);
        assert_string_equal(stripped, served); /* what a full text served before */
        free(stripped);
        free(served);
        free(served_back);
        ag_edit_model_free(back);
        free(full);
        free(bare);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

static void kept_boxes_map_as_the_served_tree(void **state)
{
    (void)state;
    size_t nv;
    const bb_options *v = bb_id_variants(&nv);
    for (size_t i = 0; i < nv; i++) {
        ag_mesh *m = NULL;
        ag_edit_model *em = model_of(&v[i], &m);
        char *bare = ag_model_kept_bare_text(em), *served = ag_model_tree_served_text(em);
        ag_splittree *t = NULL;
        ag_error err = {0};
        if (ag_model_kept_tree(bare, &t, &err))
            fail_msg("variant %zu: the bare text's tree does not read: %s", i, err.text);
        json_t *boxes = ag_model_tree_boxes(t), *tree = json_loads(served, 0, NULL);
        assert_non_null(boxes);
        assert_non_null(tree);
        json_t *bn = json_object_get(boxes, "nodes"), *sn = json_object_get(tree, "nodes");
        assert_int_equal(json_array_size(bn), json_array_size(sn));
        size_t live = 0;
        for (size_t n = 0; n < json_array_size(sn); n++) {
            const json_t *x = json_array_get(sn, n), *y = json_array_get(bn, n);
            assert_string_equal(json_string_value(json_object_get(y, "kind")),
                                json_string_value(json_object_get(x, "kind")));
            /* the rebase's matcher: served to boxes as served to served, and back */
            int64_t id = (int64_t)n;
            assert_int_equal(ag_rebase_map_node(tree, boxes, id), ag_rebase_map_node(tree, tree, id));
            assert_int_equal(ag_rebase_map_node(boxes, tree, id), ag_rebase_map_node(tree, tree, id));
            live += ag_rebase_map_node(tree, boxes, id) == id;
        }
        if (live < 10)
            fail_msg("variant %zu: only %zu nodes map to themselves", i, live);
        json_decref(boxes);
        json_decref(tree);
        ag_splittree_free(t);
        free(bare);
        free(served);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

static void bad_bare_texts_are_refused(void **state)
{
    (void)state;
    size_t nv;
    ag_mesh *m = NULL;
    ag_edit_model *em = model_of(&bb_id_variants(&nv)[0], &m);
    char *bare = ag_model_kept_bare_text(em);
    ag_splittree *t = NULL;
    ag_error err = {0};
    assert_int_equal(ag_model_kept_tree("{}", &t, &err), AG_ERR_NOT_FOUND);
    assert_null(t);
    /* the data cut by a node's record (kept a multiple of 4 characters: still base64) */
    char *data = strstr(bare, "\"data\":\"") + 8;
    size_t len = strlen(data) - 3; /* the closing quote and braces */
    size_t cut = len / 2 - (len / 2) % 4;
    char *cut_text = NULL;
    assert_true(asprintf(&cut_text, "%.*s\"}}", (int)(data - bare + cut), bare) > 0);
    assert_int_equal(ag_model_kept_tree(cut_text, &t, &err), AG_ERR_PARSE);
    assert_null(t);
    ag_edit_model *back = NULL;
    assert_int_equal(ag_model_kept_reload(em->proc->mesh, cut_text, &back, &err), AG_ERR_PARSE);
    assert_null(back);
    assert_false(ag_model_kept_serves(cut_text)); /* bare still: refused, not served as {} */
    free(cut_text);
    /* not base64: a character outside the alphabet, padding inside, a length that is no
     * multiple of four */
    size_t at = (size_t)(strstr(bare, "\"data\":\"") + 8 + 16 - bare);
    for (int b = 0; b < 3; b++) {
        char *broken = NULL;
        if (b < 2) {
            broken = strdup(bare);
            broken[at] = b == 0 ? '*' : '=';
        } else {
            assert_true(asprintf(&broken, "%.*sA%s", (int)at, bare, bare + at) > 0);
        }
        assert_int_equal(ag_model_kept_tree(broken, &t, &err), AG_ERR_PARSE);
        if (!strstr(err.text, "base64"))
            fail_msg("case %d: %s", b, err.text);
        assert_null(t);
        free(broken);
    }
    free(bare);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(bare_text_reloads_and_serves_the_same),
        cmocka_unit_test(kept_boxes_map_as_the_served_tree),
        cmocka_unit_test(bad_bare_texts_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
