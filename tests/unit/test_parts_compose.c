/* Parts library: save (core/parts/part.c) and compose (core/parts/compose.c) on generated
 * buildings whose structure is known (parts_fixture.h). Results are checked on the derived
 * mesh, measured independently of the composition's own report. */
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
#include "core/parts/compose.h"
#include "core/parts/part.h"
#include "io/grammar_text.h"
#include "parts_fixture.h"

#define TOL 1e-6

/* Window design A (the part): 1.2 x 1.8, frame 0.08, one mullion. Design B (the target's):
 * 1.6 x 2.0, frame 0.12, two mullions. */
static pf_options design_a(int depth, int turn, double ox, double oy)
{
    return (pf_options){.cols = 3, .rows = 2, .ww = 1.2, .wh = 1.8, .frame = 0.08, .mullions = 1,
                        .depth = depth, .turn = turn, .ox = ox, .oy = oy};
}
static pf_options design_b(int depth, int turn, double ox, double oy)
{
    return (pf_options){.cols = 4, .rows = 3, .side_cols = 2, .ww = 1.6, .wh = 2.0,
                        .frame = 0.12, .mullions = 2, .depth = depth, .turn = turn, .ox = ox,
                        .oy = oy};
}

static ag_part *save_window(const pf_options *o, int which)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(o, &slots, &ns);
    ag_proceduralize_result *r = pf_proc(m);
    int32_t node = pf_node_with_box(r, &slots[which], TOL);
    assert_true(node > 0);
    ag_part_meta meta = {.name = "sash window", .source = "A"};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(r, node, &meta, &p, &err))
        fail_msg("extract: %s", err.text);
    /* the part's grammar derives the window as it stood: 1 casing, 4 bars, glass, mullions */
    ag_mesh *d = NULL;
    assert_int_equal(ag_grammar_derive(p->grammar, NULL, &d, &err), AG_OK);
    ag_box *cb = pf_component_boxes(d);
    size_t inside = 0;
    for (size_t c = 0; c < d->ncomponents; c++)
        inside += pf_inside(&cb[c], &slots[which], TOL);
    assert_int_equal(d->ncomponents, 6 + o->mullions);
    assert_int_equal(inside, d->ncomponents);
    free(cb);
    ag_mesh_free(d);
    size_t visible = 0;
    for (size_t i = 0; i < p->nnodes; i++)
        visible += p->nodes[i].kind == AG_NODE_COMPONENT;
    assert_int_equal(visible, 6 + o->mullions);
    assert_true(p->nodes[0].parent == -1);
    assert_int_equal(p->nodes[0].kind, AG_NODE_COMPONENT);
    for (int a = 0; a < 3; a++) /* the root spans the part's box */
        assert_true(p->nodes[0].box[a] == 0 && p->nodes[0].box[a + 3] == 1);
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return p;
}

static char *print(const ag_grammar *g)
{
    char *text = NULL;
    size_t len = 0;
    ag_error err = {0};
    if (ag_grammar_text_print(g, &text, &len, &err))
        fail_msg("print: %s", err.text);
    return text;
}

/* fmt round trip: prints, parses and prints back to the same bytes. */
static void check_roundtrip(const ag_grammar *g)
{
    char *a = print(g);
    ag_grammar *back = NULL;
    ag_error err = {0};
    long col = 0;
    if (ag_grammar_text_parse(a, strlen(a), &back, &err, &col))
        fail_msg("composed grammar does not parse: %ld:%ld: %s\n%s", err.element, col, err.text, a);
    char *b = print(back);
    assert_string_equal(a, b);
    free(a);
    free(b);
    ag_grammar_free(back);
}

/* The along (horizontal, longer) axis of a window slot. */
static int along_axis(const ag_box *s)
{
    return s->max[0] - s->min[0] >= s->max[1] - s->min[1] ? 0 : 1;
}

/* Measures one window in the derived mesh: the components inside the slot, their count, the
 * two jambs' and the head's and bottom's widths, the mullions' widths, the glass. */
static void check_window(const ag_box *cb, size_t nc, const ag_box *slot, double fr,
                         unsigned mullions, const ag_box *building)
{
    int u = along_axis(slot);
    /* the outer face: along the thin horizontal axis, away from the building's centre */
    int v = 1 - u;
    int out_max = 0.5 * (slot->min[v] + slot->max[v]) > 0.5 * (building->min[v] + building->max[v]);
    double W = slot->max[u] - slot->min[u], H = slot->max[2] - slot->min[2];
    size_t n = 0, jambs = 0, rails = 0, mull = 0, glass = 0, casing = 0;
    for (size_t c = 0; c < nc; c++) {
        if (!pf_inside(&cb[c], slot, TOL))
            continue;
        n++;
        double du = cb[c].max[u] - cb[c].min[u], dz = cb[c].max[2] - cb[c].min[2];
        if (pf_same_box(&cb[c], slot, TOL))
            casing++;
        else if (fabs(du - W) < TOL && fabs(dz - fr) < TOL)
            rails++;
        else if (fabs(du - fr) < TOL && fabs(dz - (H - 2 * fr)) < TOL &&
                 (fabs(cb[c].min[u] - slot->min[u]) < TOL || fabs(cb[c].max[u] - slot->max[u]) < TOL))
            jambs++;
        else if (fabs(du - 0.05) < TOL && fabs(dz - (H - 2 * fr)) < TOL)
            mull++;
        else if (fabs(du - (W - 2 * fr)) < TOL && fabs(dz - (H - 2 * fr)) < TOL) {
            /* the glass sits 0.07 behind the outer face: the part is turned, not mirrored */
            double depth = out_max ? slot->max[v] - cb[c].max[v] : cb[c].min[v] - slot->min[v];
            assert_true(fabs(depth - 0.07) < TOL);
            glass++;
        }
        else
            print_message("unexpected piece %g x %g in slot\n", du, dz);
    }
    assert_int_equal(n, 6 + mullions);
    assert_int_equal(casing, 1);
    assert_int_equal(rails, 2);
    assert_int_equal(jambs, 2);
    assert_int_equal(glass, 1);
    assert_int_equal(mull, mullions);
}

static void rule_scope_replace(int depth, int turn_a, int turn_b, double ox, double oy)
{
    pf_options oa = design_a(depth, turn_a, ox, oy), ob = design_b(depth, turn_b, -ox, oy);
    ag_part *p = save_window(&oa, 1);
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(&ob, &slots, &ns);
    ag_proceduralize_result *r = pf_proc(m);
    int32_t target = pf_node_with_box(r, &slots[5], TOL);
    assert_true(target > 0);
    ag_compose_op op = {.target = target, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_RULE};
    ag_grammar *g = NULL;
    ag_compose_report rep;
    ag_error err = {0};
    if (ag_compose(r, p, &op, &g, &rep, &err))
        fail_msg("compose: %s", err.text);
    print_message("%s\n", rep.message);
    assert_int_equal(rep.instances, ns);
    check_roundtrip(g);
    ag_mesh *d = NULL;
    assert_int_equal(ag_grammar_derive(g, NULL, &d, &err), AG_OK);
    ag_box *cb = pf_component_boxes(d);
    ag_box bb = ag_mesh_bounds(d);
    /* every window slot of B holds A's design fitted to B's slot: frame 0.08, one mullion */
    for (size_t s = 0; s < ns; s++)
        check_window(cb, d->ncomponents, &slots[s], 0.08, 1, &bb);
    /* B's own window pieces are gone, its walls and roof stay: 5 + 7 per slot */
    assert_int_equal(d->ncomponents, 5 + 7 * ns);
    /* the part's terminals are the ones in the slots, under the part's labels */
    size_t part_comps = 0;
    for (size_t c = 0; c < d->ncomponents; c++) {
        int32_t gi = d->component_group[c];
        if (gi >= 0 && !strncmp(d->group_names[gi], "sash_window_", 12)) {
            part_comps++;
            int in = 0;
            for (size_t s = 0; s < ns && !in; s++)
                in = pf_inside(&cb[c], &slots[s], TOL);
            assert_true(in);
        }
    }
    assert_int_equal(part_comps, 7 * ns);
    /* editable like any model: it proceduralizes again */
    ag_edit_model *em = NULL;
    if (ag_edit_model_from_grammar(g, NULL, &em, &err))
        fail_msg("re-proceduralize: %s", err.text);
    ag_edit_model_free(em);
    free(cb);
    ag_mesh_free(d);
    ag_grammar_free(g);
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    ag_part_free(p);
}

static void test_rule_replace_recessed(void **state) { (void)state; rule_scope_replace(PF_RECESSED, 0, 0, 0, 0); }
static void test_rule_replace_flush_turned(void **state) { (void)state; rule_scope_replace(PF_FLUSH, 1, 0, 0, 0); }
static void test_rule_replace_proud_utm(void **state)
{
    (void)state;
    rule_scope_replace(PF_PROUD, 0, 3, 512345.0, 5403210.0);
}
static void test_rule_replace_both_turned(void **state) { (void)state; rule_scope_replace(PF_RECESSED, 2, 1, 0, 0); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rule_replace_recessed),
        cmocka_unit_test(test_rule_replace_flush_turned),
        cmocka_unit_test(test_rule_replace_proud_utm),
        cmocka_unit_test(test_rule_replace_both_turned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
