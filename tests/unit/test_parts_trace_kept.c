/* A model's derivation traced once serves every part save and composition of that version
 * (core/parts: ag_part_extract_traced, ag_compose_traced; app/edit_session.h: the service keeps
 * the trace with the edit model): each gives what tracing anew gives, byte for byte, and a new
 * version of the model is traced anew. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "app/edit_session.h"
#include "core/edit/edit.h"
#include "core/parts/compose.h"
#include "core/parts/part.h"
#include "io/grammar_text.h"
#include "parts_fixture.h"

#define TOL 1e-6

/* The part's grammar text and its nodes' boxes, the whole of what a save makes. */
static char *part_text(const ag_part *p)
{
    char *g = pf_print(p->grammar);
    size_t n = strlen(g) + 64 * p->nnodes + 64;
    char *out = malloc(n);
    assert_non_null(out);
    size_t k = (size_t)snprintf(out, n, "%s", g);
    for (size_t i = 0; i < p->nnodes; i++)
        k += (size_t)snprintf(out + k, n - k, "%d %d %.17g %.17g\n", p->nodes[i].kind,
                              p->nodes[i].parent, p->nodes[i].box[0], p->nodes[i].box[5]);
    free(g);
    return out;
}

static int32_t slot_of(const ag_proceduralize_result *r, const ag_box *slots, size_t ns)
{
    int32_t n = pf_node_with_box(r, &slots[ns / 2], TOL);
    assert_true(n > 0);
    return n;
}

static ag_part *extract(const ag_proceduralize_result *r, const ag_trace *t, int32_t node)
{
    ag_part_meta meta = {.name = "piece", .source = "A"};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract_traced(r, t, node, &meta, &p, &err))
        fail_msg("extract node %d: %s", (int)node, err.text);
    return p;
}

static char *composed(const ag_proceduralize_result *r, const ag_trace *t, const ag_part *p,
                      int32_t target, int mode, int scope)
{
    ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
    ag_grammar *g = NULL;
    ag_error err = {0};
    if (ag_compose_traced(r, t, p, &op, &g, NULL, &err))
        fail_msg("compose into %d (mode %d, scope %d): %s", (int)target, mode, scope, err.text);
    char *text = pf_print(g);
    ag_grammar_free(g);
    return text;
}

/* Saves and compositions on several designs (recessed and proud windows, turned, at UTM
 * offsets): one trace used for all of them gives what each tracing for itself gives. */
static void one_trace_serves_every_save_and_composition(void **state)
{
    (void)state;
    const pf_options designs[] = {pf_design_a(PF_RECESSED, 0, 0, 0),
                                  pf_design_b(PF_PROUD, 1, 0, 0),
                                  pf_design_a(PF_FLUSH, 2, 512345.0, 5812345.0)};
    ag_box *slots_a;
    size_t na;
    ag_mesh *ma = pf_building(&designs[0], &slots_a, &na);
    ag_proceduralize_result *ra = pf_proc(ma);
    ag_part *window = extract(ra, NULL, pf_node_with_box(ra, &slots_a[0], TOL));
    for (size_t d = 0; d < sizeof designs / sizeof designs[0]; d++) {
        ag_box *slots;
        size_t ns;
        ag_mesh *m = pf_building(&designs[d], &slots, &ns);
        ag_proceduralize_result *r = pf_proc(m);
        ag_trace *t = NULL;
        ag_error err = {0};
        assert_int_equal(ag_trace_build(r->grammar, 0, &t, &err), AG_OK);
        /* saves: every visible node, the root's first */
        size_t saves = 0;
        for (int32_t n = 0; n < (int32_t)r->tree->nnodes; n++) {
            if (r->tree->nodes[n].kind != AG_NODE_COMPONENT)
                continue;
            ag_part *own = extract(r, NULL, n), *kept = extract(r, t, n);
            saves++;
            char *a = part_text(own), *b = part_text(kept);
            if (strcmp(a, b))
                fail_msg("design %zu, node %d: the part saved with the kept trace differs", d,
                         (int)n);
            free(a);
            free(b);
            ag_part_free(own);
            ag_part_free(kept);
        }
        print_message("design %zu: %zu nodes, %zu saves compared, trace of %zu instances\n", d,
                      r->tree->nnodes, saves, t->ninstances);
        assert_true(saves >= 3);
        /* a trace is of its own grammar: design A's trace does not find B's nodes alike */
        if (d > 0) {
            ag_trace *ta = NULL;
            assert_int_equal(ag_trace_build(ra->grammar, 0, &ta, &err), AG_OK);
            ag_part_meta meta = {.name = "piece"};
            ag_part *wrong = NULL, *own = extract(r, NULL, slot_of(r, slots, ns));
            ag_status s = ag_part_extract_traced(r, ta, slot_of(r, slots, ns), &meta, &wrong,
                                                 &err);
            if (s == AG_OK) {
                char *a = part_text(own), *b = part_text(wrong);
                assert_true(strcmp(a, b) != 0);
                free(a);
                free(b);
            }
            ag_part_free(wrong);
            ag_part_free(own);
            ag_trace_free(ta);
        }
        /* compositions in every mode and scope, several in a row with the one trace */
        int32_t slot = pf_node_with_box(r, &slots[ns / 2], TOL);
        assert_true(slot > 0);
        const int modes[][2] = {{AG_COMPOSE_REPLACE, AG_COMPOSE_RULE},
                                {AG_COMPOSE_REPLACE, AG_COMPOSE_NODE},
                                {AG_COMPOSE_INSERT, AG_COMPOSE_NODE},
                                {AG_COMPOSE_FILL, AG_COMPOSE_NODE}};
        for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++) {
            char *a = composed(r, NULL, window, slot, modes[k][0], modes[k][1]);
            char *b = composed(r, t, window, slot, modes[k][0], modes[k][1]);
            if (strcmp(a, b))
                fail_msg("design %zu, mode %d scope %d: composed with the kept trace differs",
                         d, modes[k][0], modes[k][1]);
            free(a);
            free(b);
        }
        ag_trace_free(t);
        free(slots);
        ag_proceduralize_result_free(r);
        ag_mesh_free(m);
    }
    ag_part_free(window);
    free(slots_a);
    ag_proceduralize_result_free(ra);
    ag_mesh_free(ma);
}

/* The session keeps one trace per version: asked twice it is the same, a replaced or reset
 * model has none until asked again, and the new one traces the new model. */
static void the_session_traces_each_version_once(void **state)
{
    (void)state;
    pf_options o = pf_design_a(PF_RECESSED, 0, 0, 0);
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(&o, &slots, &ns);
    ag_error err = {0};
    ag_edit_model *em = NULL, *other = NULL;
    assert_int_equal(ag_edit_model_create(m, NULL, &em, &err), AG_OK);
    ag_edit_state st = {.model = 1, .version = 1, .em = em};
    const ag_trace *t1 = NULL, *t2 = NULL;
    assert_int_equal(ag_edit_session_trace(&st, &t1, &err), AG_OK);
    assert_int_equal(ag_edit_session_trace(&st, &t2, &err), AG_OK);
    assert_non_null(t1);
    assert_ptr_equal(t1, t2);
    size_t instances = t1->ninstances;
    /* a new version: a model of a wider building */
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = AG_EDIT_ROOT, .has_scale = 1,
                     .scale = {2.0, 1, 1}};
    ag_edit_report rep = {0};
    assert_int_equal(ag_edit_apply_ex(em, &op, 0, &other, &rep, &err), AG_OK);
    ag_edit_report_clear(&rep);
    ag_edit_session_replace(&st, 2, other);
    assert_null(st.trace);
    assert_int_equal(ag_edit_session_trace(&st, &t2, &err), AG_OK);
    assert_non_null(t2);
    assert_true(t2->ninstances > instances); /* the wider model's own, more windows */
    ag_edit_session_reset(&st);
    assert_null(st.trace);
    assert_int_equal(ag_edit_session_trace(&st, &t2, &err), AG_ERR_INTERNAL);
    free(slots);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_trace_serves_every_save_and_composition),
        cmocka_unit_test(the_session_traces_each_version_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
