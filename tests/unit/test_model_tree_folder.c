/* A folder's tree.json printed directly (ag_model_tree_folder_text) is what jansson prints
 * for the same tree (ag_model_tree_folder, JSON_INDENT(1) | JSON_REAL_PRECISION(15)),
 * character for character: on generated buildings with and without groups, turned, at UTM
 * coordinates, jittered, with windows recessed, flush and proud, after patterns removed
 * nodes, and with group names that need escaping or are not UTF-8. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/model_tree.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "edit_building_fixture.h"

static void same_as_jansson(const ag_edit_model *em, const char *name)
{
    char *text = ag_model_tree_folder_text(em);
    json_t *j = ag_model_tree_folder(em);
    char *want = json_dumps(j, JSON_INDENT(1) | JSON_REAL_PRECISION(15));
    assert_non_null(text);
    assert_non_null(want);
    if (strcmp(text, want)) {
        size_t i = 0;
        while (text[i] && text[i] == want[i])
            i++;
        fail_msg("%s: differs at byte %zu: ...%.60s... instead of ...%.60s...", name, i,
                 text + (i > 20 ? i - 20 : 0), want + (i > 20 ? i - 20 : 0));
    }
    /* and it parses back, one entry per live node */
    json_error_t e;
    json_t *back = json_loads(text, 0, &e);
    assert_non_null(back);
    size_t live = 0;
    for (size_t n = 0; n < em->proc->tree->nnodes; n++)
        live += em->proc->tree->nodes[n].kind != AG_NODE_DEAD;
    assert_int_equal(json_array_size(json_object_get(back, "nodes")), live);
    json_decref(back);
    free(want);
    json_decref(j);
    free(text);
}

static void test_generated_facades(void **state)
{
    (void)state;
    const ag_gen_facade_options opts[] = {
        {.cols = 6, .rows = 3},
        {.cols = 5, .rows = 4, .side_cols = 3, .back = 1, .left = 1, .annex = 1},
        {.cols = 4, .rows = 2, .side_cols = 2, .annex = 1, .no_groups = 1},
    };
    for (size_t i = 0; i < sizeof opts / sizeof *opts; i++) {
        ag_mesh *m;
        ag_error err = {0};
        assert_int_equal(ag_gen_facade(&opts[i], &m, &err), AG_OK);
        if (i == 1) { /* names that need escaping, a non-ASCII one, one that is not UTF-8 */
            const char *names[] = {"Fenster \"Süd\"", "back\\slash", "\xff\xfe bad", "tab\there"};
            for (size_t g = 0; g < m->ngroups && g < 4; g++) {
                free(m->group_names[g]);
                m->group_names[g] = strdup(names[g]);
            }
        }
        if (i == 2) /* UTM-sized coordinates */
            for (size_t v = 0; v < m->nverts; v++) {
                m->pos[3 * v] += 512345.25;
                m->pos[3 * v + 1] += 5812345.5;
            }
        ag_edit_model *em = NULL;
        if (ag_edit_model_create(m, NULL, &em, &err))
            fail_msg("facade %zu: %s", i, err.text);
        size_t dead = 0;
        for (size_t n = 0; n < em->proc->tree->nnodes; n++)
            dead += em->proc->tree->nodes[n].kind == AG_NODE_DEAD;
        if (i == 0)
            assert_true(dead > 0); /* patterns removed nodes: they are left out */
        char name[32];
        snprintf(name, sizeof name, "facade %zu", i);
        same_as_jansson(em, name);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

static void test_box_buildings(void **state)
{
    (void)state;
    const bb_options variants[] = {
        {"recessed", 6, 3, 3, 0, BB_RECESSED, 0, 0, 0, 0, 0, 0, 0},
        {"flush", 6, 3, 3, 2, BB_FLUSH, 0, 0, 0, 0, 0, 0, 0},
        {"proud, overhang, turned", 6, 3, 3, 0, BB_PROUD, 0.3, 1, 0, 0, 0, 0, 0},
        {"recessed, UTM", 6, 3, 3, 0, BB_RECESSED, 0, 0, 512345.0, 5812345.0, 31.0, 0, 0},
        {"flush, jittered", 5, 2, 3, 0, BB_FLUSH, 0, 0, 0, 0, 0, 2e-7, 0},
    };
    for (size_t i = 0; i < sizeof variants / sizeof *variants; i++) {
        ag_mesh *m = NULL;
        ag_error err = {0};
        ag_edit_model *em = bb_service_model(&variants[i], &m, &err);
        if (!em)
            fail_msg("%s: %s", variants[i].name, err.text);
        same_as_jansson(em, variants[i].name);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_generated_facades),
        cmocka_unit_test(test_box_buildings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
