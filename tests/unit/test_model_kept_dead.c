/* The kept tree with many dead nodes (app/model_kept.h): a generated box building's edit model
 * (edit_building_fixture.h) with 100,000 more dead nodes reloads from its stored tree text with
 * every id where it was (each node of the same kind, live nodes with the same links and box),
 * the dead nodes cost the text almost nothing, a node added after the reload takes an id past
 * every old one (ids are never reused), and the same model written in format 3 (every dead
 * node a whole record, as stores from before keep it) still reloads the same; the served tree
 * lists each dead node as its id alone. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sodium.h>

#include "app/model_kept.h"
#include "app/model_tree.h"
#include "core/edit/edit.h"
#include "core/proc/proceduralize.h"
#include "edit_building_fixture.h"

#define EXTRA_DEAD 100000
/* format 3's record of a node: 13 int32s, box and pivot (9 doubles) */
#define FULL_NODE_BYTES (4 * 13 + 8 * 9)

static size_t count_dead(const ag_splittree *t)
{
    size_t d = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        d += t->nodes[n].kind == AG_NODE_DEAD;
    return d;
}

/* back holds em's nodes under the same ids: same kinds, live ones with the same links and
 * box. */
static void assert_same_nodes(const ag_edit_model *em, const ag_edit_model *back)
{
    const ag_splittree *a = em->proc->tree, *b = back->proc->tree;
    assert_int_equal(b->nnodes, a->nnodes);
    for (size_t n = 0; n < a->nnodes; n++) {
        const ag_tnode *x = &a->nodes[n], *y = &b->nodes[n];
        if (x->kind != y->kind)
            fail_msg("node %zu: kind %d became %d", n, x->kind, y->kind);
        if (x->kind == AG_NODE_DEAD)
            continue;
        assert_int_equal(y->parent, x->parent);
        assert_int_equal(y->first_child, x->first_child);
        assert_int_equal(y->next_sibling, x->next_sibling);
        assert_int_equal(y->component, x->component);
        assert_memory_equal(&y->box, &x->box, sizeof x->box);
    }
}

/* The kept member's data, decoded (malloc'd, its length in *n), and where the text holds
 * it. */
static uint8_t *kept_data(const char *text, size_t *n, const char **b64, size_t *b64len)
{
    const char *at = strstr(text, "\"kept\":");
    assert_non_null(at);
    at = strstr(at, "\"data\":\"");
    assert_non_null(at);
    *b64 = at + 8;
    *b64len = (size_t)(strchr(*b64, '"') - *b64);
    uint8_t *out = malloc(*b64len + 1);
    assert_int_equal(sodium_base642bin(out, *b64len + 1, *b64, *b64len, NULL, n, NULL,
                                       sodium_base64_VARIANT_ORIGINAL),
                     0);
    return out;
}

static uint32_t le32(const uint8_t *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* text in format 3: each run of dead nodes (kind 4 and a count) written as that many whole
 * dead records (links and classes -1, turns, octant, box and pivot zero). */
static char *as_format_3(const char *text, size_t nnodes)
{
    size_t n = 0, b64len = 0;
    const char *b64 = NULL;
    uint8_t *d = kept_data(text, &n, &b64, &b64len);
    uint8_t *full = calloc(nnodes * FULL_NODE_BYTES + n + 1, 1);
    size_t at = 0, out = 0;
    for (size_t node = 0; node < nnodes;) {
        if (le32(d + at) == AG_NODE_DEAD) {
            uint32_t run = le32(d + at + 4);
            at += 8;
            for (uint32_t i = 0; i < run; i++, node++) {
                uint8_t *r = full + out;
                r[0] = AG_NODE_DEAD;
                memset(r + 4, 0xff, 4 * 12); /* int32 -1, but the turns and octant 0 */
                memset(r + 4 * 8, 0, 4 * 3);
                out += FULL_NODE_BYTES;
            }
        } else {
            memcpy(full + out, d + at, FULL_NODE_BYTES);
            at += FULL_NODE_BYTES;
            out += FULL_NODE_BYTES;
            node++;
        }
    }
    memcpy(full + out, d + at, n - at);
    out += n - at;
    size_t elen = sodium_base64_ENCODED_LEN(out, sodium_base64_VARIANT_ORIGINAL);
    char *enc = malloc(elen);
    sodium_bin2base64(enc, elen, full, out, sodium_base64_VARIANT_ORIGINAL);
    size_t head = (size_t)(b64 - text), tail = strlen(b64 + b64len);
    char *res = malloc(head + elen + tail + 1);
    memcpy(res, text, head);
    strcpy(res + head, enc);
    strcat(res, b64 + b64len);
    char *f = strstr(strstr(res, "\"kept\":"), "\"format\":4");
    assert_non_null(f);
    f[9] = '3';
    free(enc);
    free(full);
    free(d);
    return res;
}

static void many_dead_nodes_keep_their_ids(void **state)
{
    (void)state;
    size_t nv;
    ag_mesh *m = bb_generate(&bb_id_variants(&nv)[0]);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_model_create(m, NULL, &em, &err), AG_OK);
    ag_splittree *t = em->proc->tree;
    size_t dead_before = count_dead(t);
    /* proceduralization's own dead nodes sit between live ones: runs, not only one at the end */
    if (!dead_before)
        fail_msg("the fixture's tree has no dead node between live ones");
    for (size_t i = 0; i < EXTRA_DEAD; i++)
        assert_true(ag_splittree_add_node(t, AG_NODE_DEAD) >= 0);
    size_t nnodes = t->nnodes, live = nnodes - count_dead(t);

    char *text = ag_model_kept_tree_text(em);
    assert_non_null(text);
    /* the dead nodes cost the kept data a few bytes per run, not a record each */
    size_t dlen = 0, b64len = 0;
    const char *b64 = NULL;
    free(kept_data(text, &dlen, &b64, &b64len));
    if (dlen >= live * FULL_NODE_BYTES + 8 * (dead_before + 1) + nnodes)
        fail_msg("the kept data takes %zu bytes for %zu live and %zu dead nodes", dlen, live,
                 nnodes - live);

    ag_edit_model *back = NULL;
    if (ag_model_kept_reload(em->proc->mesh, text, &back, &err))
        fail_msg("the kept model does not reload: %s", err.text);
    assert_same_nodes(em, back);
    /* an id made after the reload is past every old one */
    assert_int_equal(ag_splittree_add_node(back->proc->tree, AG_NODE_DEAD), (int32_t)nnodes);
    ag_edit_model_free(back);

    /* written again by the reloaded model, the kept text is the same */
    back = NULL;
    assert_int_equal(ag_model_kept_reload(em->proc->mesh, text, &back, &err), AG_OK);
    char *again = ag_model_kept_tree_text(back);
    assert_non_null(again);
    assert_string_equal(strstr(again, "\"kept\":"), strstr(text, "\"kept\":"));
    free(again);
    ag_edit_model_free(back);

    /* the format stores kept before: every dead node whole */
    char *old = as_format_3(text, nnodes);
    back = NULL;
    if (ag_model_kept_reload(em->proc->mesh, old, &back, &err))
        fail_msg("a format 3 kept model does not reload: %s", err.text);
    assert_same_nodes(em, back);
    ag_edit_model_free(back);

    /* a run passing the last node is refused, naming it */
    size_t n = 0;
    uint8_t *d = kept_data(text, &n, &b64, &b64len);
    size_t at = 0;
    for (size_t node = 0; node < nnodes;) { /* the last run: the appended dead nodes */
        if (le32(d + at) == AG_NODE_DEAD) {
            node += le32(d + at + 4);
            if (node == nnodes)
                break;
            at += 8;
        } else {
            at += FULL_NODE_BYTES;
            node++;
        }
    }
    uint32_t more = EXTRA_DEAD + 1;
    memcpy(d + at + 4, &more, 4); /* little-endian hosts only, as the tests run */
    size_t elen = sodium_base64_ENCODED_LEN(n, sodium_base64_VARIANT_ORIGINAL);
    char *enc = malloc(elen);
    sodium_bin2base64(enc, elen, d, n, sodium_base64_VARIANT_ORIGINAL);
    assert_int_equal(strlen(enc), b64len);
    char *broken = strdup(text);
    memcpy(broken + (b64 - text), enc, b64len);
    back = NULL;
    assert_int_equal(ag_model_kept_reload(em->proc->mesh, broken, &back, &err), AG_ERR_PARSE);
    assert_null(back);
    assert_non_null(strstr(err.text, "dead nodes"));
    free(broken);
    free(enc);
    free(d);
    free(old);
    free(text);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

/* The served tree of the same model: nodes[i].id == i for every id, each dead node exactly
 * {"id":i,"kind":"dead"} (as the tree says, read independently of the printer), every live
 * node whole with the links of the tree, and the dead nodes a few bytes each. */
static void served_dead_nodes_are_their_ids_only(void **state)
{
    (void)state;
    size_t nv;
    ag_mesh *m = bb_generate(&bb_id_variants(&nv)[0]);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_model_create(m, NULL, &em, &err), AG_OK);
    ag_splittree *t = em->proc->tree;
    size_t live_before = t->nnodes - count_dead(t);
    char *small = ag_model_tree_served_text(em);
    assert_non_null(small);
    for (size_t i = 0; i < EXTRA_DEAD; i++)
        assert_true(ag_splittree_add_node(t, AG_NODE_DEAD) >= 0);
    char *text = ag_model_tree_served_text(em);
    assert_non_null(text);
    /* 100,000 more dead ids: at most 32 bytes each ({"id":123456,"kind":"dead"}, and a comma) */
    if (strlen(text) > strlen(small) + 32 * (size_t)EXTRA_DEAD)
        fail_msg("the served tree grew by %zu bytes for %d dead nodes",
                 strlen(text) - strlen(small), EXTRA_DEAD);
    json_t *doc = json_loads(text, 0, NULL);
    assert_non_null(doc);
    json_t *nodes = json_object_get(doc, "nodes");
    assert_int_equal(json_array_size(nodes), t->nnodes);
    size_t live = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        json_t *jn = json_array_get(nodes, i);
        assert_int_equal(json_integer_value(json_object_get(jn, "id")), (json_int_t)i);
        const char *kind = json_string_value(json_object_get(jn, "kind"));
        assert_non_null(kind);
        if (t->nodes[i].kind == AG_NODE_DEAD) {
            assert_string_equal(kind, "dead");
            assert_int_equal(json_object_size(jn), 2);
            continue;
        }
        live++;
        assert_true(strcmp(kind, "dead") != 0);
        json_t *parent = json_object_get(jn, "parent");
        assert_int_equal(json_is_null(parent) ? -1 : json_integer_value(parent),
                         t->nodes[i].parent);
        size_t nc = 0;
        for (int32_t c = t->nodes[i].first_child; c >= 0; c = t->nodes[c].next_sibling)
            assert_int_equal(json_integer_value(json_array_get(json_object_get(jn, "children"),
                                                               nc++)),
                             c);
        assert_int_equal(json_array_size(json_object_get(jn, "children")), nc);
        assert_int_equal(json_array_size(json_object_get(jn, "box")), 6);
    }
    assert_int_equal(live, live_before);
    assert_int_equal(json_integer_value(json_object_get(json_object_get(doc, "stats"), "nodes")),
                     (json_int_t)live);
    json_decref(doc);
    free(text);
    free(small);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(many_dead_nodes_keep_their_ids),
        cmocka_unit_test(served_dead_nodes_are_their_ids_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
