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

static ag_part *save_window(const pf_options *o, int which)
{
    ag_box slot;
    ag_part *p = pf_window_part(o, which, &slot);
    ag_error err = {0};
    /* the part's grammar derives the window as it stood: 1 casing, 4 bars, glass, mullions */
    ag_mesh *d = NULL;
    assert_int_equal(ag_grammar_derive(p->grammar, NULL, &d, &err), AG_OK);
    ag_box *cb = pf_component_boxes(d);
    size_t inside = 0;
    for (size_t c = 0; c < d->ncomponents; c++)
        inside += pf_inside(&cb[c], &slot, TOL);
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
    return p;
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

static ag_proceduralize_result *building(const pf_options *o, ag_mesh **m, ag_box **slots,
                                         size_t *ns)
{
    *m = pf_building(o, slots, ns);
    return pf_proc(*m);
}

static ag_grammar *compose(const ag_proceduralize_result *r, const ag_part *p, int32_t target,
                           int mode, int scope, ag_compose_report *rep)
{
    ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
    ag_grammar *g = NULL;
    ag_error err = {0};
    if (ag_compose(r, p, &op, &g, rep, &err))
        fail_msg("compose: %s", err.text);
    print_message("%s\n", rep->message);
    pf_check_roundtrip(g);
    return g;
}

static ag_mesh *derive(const ag_grammar *g)
{
    ag_mesh *d = NULL;
    ag_error err = {0};
    if (ag_grammar_derive(g, NULL, &d, &err))
        fail_msg("derive: %s", err.text);
    return d;
}

/* A part saved from building A (window `which`) and building B to compose it into; after
 * scene_compose, the composed grammar, its derived mesh and the mesh's component boxes. */
typedef struct {
    ag_part *part;
    ag_mesh *m;
    ag_box *slots;
    size_t ns;
    ag_proceduralize_result *r;
    ag_grammar *g;
    ag_mesh *d;
    ag_box *cb, bounds;
    ag_compose_report rep;
} scene;

static void scene_open(scene *sc, const pf_options *oa, int which, const pf_options *ob)
{
    memset(sc, 0, sizeof *sc);
    sc->part = save_window(oa, which);
    sc->m = pf_building(ob, &sc->slots, &sc->ns);
    sc->r = pf_proc(sc->m);
}

static void scene_compose(scene *sc, int32_t target, int mode, int scope)
{
    sc->g = compose(sc->r, sc->part, target, mode, scope, &sc->rep);
    sc->d = derive(sc->g);
    sc->cb = pf_component_boxes(sc->d);
    sc->bounds = ag_mesh_bounds(sc->d);
}

static void scene_close(scene *sc)
{
    free(sc->cb);
    ag_mesh_free(sc->d);
    ag_grammar_free(sc->g);
    free(sc->slots);
    ag_proceduralize_result_free(sc->r);
    ag_mesh_free(sc->m);
    ag_part_free(sc->part);
}

/* Components of the part's labels (groups "sash_window_*") and how many lie in one of boxes. */
static size_t part_components(const scene *sc, const ag_box *boxes, size_t nb, size_t *inside)
{
    size_t n = 0;
    *inside = 0;
    for (size_t c = 0; c < sc->d->ncomponents; c++) {
        int32_t gi = sc->d->component_group[c];
        if (gi < 0 || strncmp(sc->d->group_names[gi], "sash_window_", 12))
            continue;
        n++;
        int in = 0;
        for (size_t k = 0; k < nb && !in; k++)
            in = pf_inside(&sc->cb[c], &boxes[k], TOL);
        *inside += in;
    }
    return n;
}

static void rule_scope_replace_ex(int depth, int turn_a, int turn_b, double ox, double oy,
                                  double jitter, int flip)
{
    pf_options oa = pf_design_a(depth, turn_a, ox, oy), ob = pf_design_b(depth, turn_b, -ox, oy);
    oa.flip = flip;
    ob.jitter = jitter;
    scene sc;
    scene_open(&sc, &oa, 1, &ob);
    int32_t target = pf_node_with_box(sc.r, &sc.slots[5], TOL);
    assert_true(target > 0);
    scene_compose(&sc, target, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE);
    assert_int_equal(sc.rep.instances, sc.ns);
    /* every window slot of B holds A's design fitted to B's slot: frame 0.08, one mullion */
    for (size_t s = 0; s < sc.ns; s++)
        check_window(sc.cb, sc.d->ncomponents, &sc.slots[s], 0.08, 1, &sc.bounds);
    /* B's own window pieces are gone, its walls and roof stay: 5 + 7 per slot */
    assert_int_equal(sc.d->ncomponents, 5 + 7 * sc.ns);
    /* the part's terminals are the ones in the slots, under the part's labels */
    size_t inside, n = part_components(&sc, sc.slots, sc.ns, &inside);
    assert_int_equal(n, 7 * sc.ns);
    assert_int_equal(inside, n);
    /* editable like any model: it proceduralizes again */
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_from_grammar(sc.g, NULL, &em, &err))
        fail_msg("re-proceduralize: %s", err.text);
    ag_edit_model_free(em);
    scene_close(&sc);
}

static void rule_scope_replace(int depth, int turn_a, int turn_b, double ox, double oy)
{
    rule_scope_replace_ex(depth, turn_a, turn_b, ox, oy, 0, 0);
}

/* B's windows off their grid by up to 3 mm (no pattern holds them), A's boxes triangulated
 * the other way. */
static void test_rule_replace_jittered_flipped(void **state)
{
    (void)state;
    rule_scope_replace_ex(PF_RECESSED, 0, 1, 0, 0, 0.003, 1);
}

static void test_rule_replace_recessed(void **state) { (void)state; rule_scope_replace(PF_RECESSED, 0, 0, 0, 0); }
static void test_rule_replace_flush_turned(void **state) { (void)state; rule_scope_replace(PF_FLUSH, 1, 0, 0, 0); }
static void test_rule_replace_proud_utm(void **state)
{
    (void)state;
    rule_scope_replace(PF_PROUD, 0, 3, 512345.0, 5403210.0);
}

static void test_rule_replace_both_turned(void **state) { (void)state; rule_scope_replace(PF_RECESSED, 2, 1, 0, 0); }

/* Scope node: one window of B gets A's design, the others keep B's. */
static void test_node_replace(void **state)
{
    (void)state;
    for (int turn = 0; turn < 4; turn += 3) {
        pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, turn, 0, 0);
        scene sc;
        scene_open(&sc, &oa, 0, &ob);
        size_t which = 13; /* on the right facade */
        int32_t target = pf_node_with_box(sc.r, &sc.slots[which], TOL);
        assert_true(target > 0);
        scene_compose(&sc, target, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE);
        assert_int_equal(sc.rep.instances, 1);
        assert_true(sc.rep.cloned >= 1);
        for (size_t s = 0; s < sc.ns; s++)
            if (s == which)
                check_window(sc.cb, sc.d->ncomponents, &sc.slots[s], 0.08, 1, &sc.bounds);
            else
                check_window(sc.cb, sc.d->ncomponents, &sc.slots[s], 0.12, 2, &sc.bounds);
        assert_int_equal(sc.d->ncomponents, 5 + 8 * (sc.ns - 1) + 7);
        scene_close(&sc);
    }
}

/* Fill: B's blank back wall becomes a grid of A's window, each fitted to its cell (frames kept),
 * flush with the wall's outer face. */
static void test_fill_blank_wall(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_FLUSH, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 2, &ob);
    /* the back wall: 11.2 x 0.3 x 10.6 at y in [D - 0.3, D] */
    ag_box bounds = ag_mesh_bounds(sc.m);
    double Dp = bounds.max[1] - 0.2; /* the roof overhangs by 0.2 */
    ag_box back = {{0, Dp - 0.3, 0}, {11.2, Dp, 10.6}};
    int32_t target = pf_node_with_box(sc.r, &back, TOL);
    assert_true(target > 0);
    scene_compose(&sc, target, AG_COMPOSE_FILL, AG_COMPOSE_NODE);
    /* 11.2 / 1.2 -> 9 columns, 10.6 / 1.8 -> 6 rows, one layer */
    assert_int_equal(sc.rep.counts[0], 9);
    assert_int_equal(sc.rep.counts[1], 1);
    assert_int_equal(sc.rep.counts[2], 6);
    double cw = 11.2 / 9, ch = 10.6 / 6;
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 9; i++) {
            /* the back faces +y: the cell is flush with y = Dp, 0.16 deep */
            ag_box cell = {{i * cw, Dp - 0.16, j * ch}, {(i + 1) * cw, Dp, (j + 1) * ch}};
            check_window(sc.cb, sc.d->ncomponents, &cell, 0.08, 1, &sc.bounds);
        }
    /* B's windows are untouched */
    for (size_t s = 0; s < sc.ns; s++)
        check_window(sc.cb, sc.d->ncomponents, &sc.slots[s], 0.12, 2, &sc.bounds);
    assert_int_equal(sc.d->ncomponents, 5 + 8 * sc.ns + 7 * 54);
    scene_close(&sc);
}

/* Insert: a balcony part stands between B's front wall and its windows. */
static void test_insert_balcony(void **state)
{
    (void)state;
    pf_options oc = pf_design_a(PF_FLUSH, 0, 0, 0);
    oc.balcony = 1;
    ag_mesh *mc;
    ag_box *sc;
    size_t nsc;
    ag_proceduralize_result *rc = building(&oc, &mc, &sc, &nsc);
    ag_box bal = {{0.9, -1.0, 1.0}, {3.9, 0, 2.1}};
    int32_t bn = pf_node_with_box(rc, &bal, TOL);
    assert_true(bn > 0);
    ag_part_meta meta = {.name = "balcony", .tags = (const char *const[]){"balcony", "steel"}, .ntags = 2};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(rc, bn, &meta, &p, &err))
        fail_msg("extract: %s", err.text);
    pf_options ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_mesh *m;
    ag_box *slots;
    size_t ns;
    ag_proceduralize_result *r = building(&ob, &m, &slots, &ns);
    ag_box front = {{0, 0, 0}, {11.2, 0.3, 10.6}};
    int32_t target = pf_node_with_box(r, &front, TOL);
    assert_true(target > 0);
    ag_compose_report rep;
    ag_grammar *g = compose(r, p, target, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, &rep);
    ag_mesh *d = derive(g);
    ag_box *cb = pf_component_boxes(d);
    ag_box bb = ag_mesh_bounds(d);
    /* the wall and all of B's windows are where they were */
    size_t walls = 0, slabs = 0, in_wall = 0;
    for (size_t c = 0; c < d->ncomponents; c++) {
        walls += pf_same_box(&cb[c], &front, TOL);
        int32_t gi = d->component_group[c];
        if (gi >= 0 && !strncmp(d->group_names[gi], "balcony_", 8)) {
            in_wall += pf_inside(&cb[c], &front, TOL);
            /* the slab keeps its 0.15 thickness, spanning the wall's width */
            slabs += fabs(cb[c].max[2] - cb[c].min[2] - 0.15) < TOL &&
                     fabs(cb[c].max[0] - cb[c].min[0] - 11.2) < TOL;
        }
    }
    assert_true(walls >= 2); /* the wall's own terminal and the balcony's volume */
    assert_int_equal(slabs, 1);
    assert_int_equal(in_wall, 8); /* volume, slab, rail, 5 posts */
    for (size_t s = 0; s < ns; s++)
        check_window(cb, d->ncomponents, &slots[s], 0.12, 2, &bb);
    assert_int_equal(d->ncomponents, 5 + 8 * ns + 8);
    /* in the grammar the windows hang below the inserted rule, after the part's root */
    int32_t ins = -1;
    for (size_t i = 0; i < g->nrules; i++)
        if (strstr(g->rules[i].name, "balcony_over_"))
            ins = (int32_t)i;
    assert_true(ins >= 0);
    const ag_grule *ir = &g->rules[ins];
    assert_string_equal(ir->stmts[0].callee, rep.root);
    size_t applies = 0;
    for (size_t i = 1; i < ir->nstmts; i++)
        applies += ir->stmts[i].kind == AG_GSTMT_APPLY;
    assert_true(applies >= 1);
    free(cb);
    ag_mesh_free(d);
    ag_grammar_free(g);
    free(slots);
    free(sc);
    ag_proceduralize_result_free(r);
    ag_proceduralize_result_free(rc);
    ag_mesh_free(m);
    ag_mesh_free(mc);
    ag_part_free(p);
}

/* Target and part with rules of the same names: both kept (the part's renamed), the target's
 * other rules unchanged; composing a building's own window into itself shares everything. */
static void test_names_clash_and_share(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_part *p = save_window(&oa, 0);
    ag_mesh *m;
    ag_box *slots;
    size_t ns;
    ag_proceduralize_result *r = building(&ob, &m, &slots, &ns);
    int32_t target = pf_node_with_box(r, &slots[0], TOL);
    ag_compose_report rep;
    ag_grammar *g = compose(r, p, target, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, &rep);
    size_t clashes = 0;
    for (size_t i = 0; i < p->grammar->nrules; i++)
        for (size_t k = 0; k < r->grammar->nrules; k++)
            clashes += !strcmp(p->grammar->rules[i].name, r->grammar->rules[k].name);
    assert_true(clashes > 0);
    assert_true(rep.renamed > 0);
    /* every rule of B is still there under its name, unchanged but for the rewritten one */
    for (size_t k = 0; k < r->grammar->nrules; k++) {
        const ag_grule *o = &r->grammar->rules[k];
        int found = 0;
        for (size_t i = 0; i < g->nrules && !found; i++)
            if (!strcmp(g->rules[i].name, o->name)) {
                found = 1;
                if (strcmp(o->name, rep.target_rule))
                    assert_int_equal(g->rules[i].nstmts, o->nstmts);
            }
        assert_true(found);
    }
    ag_grammar_free(g);
    /* a window of A composed into A: its rules and terminals are A's own */
    ag_mesh *ma;
    ag_box *sa;
    size_t na;
    ag_proceduralize_result *ra = building(&oa, &ma, &sa, &na);
    int32_t ta = pf_node_with_box(ra, &sa[3], TOL);
    g = compose(ra, p, ta, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, &rep);
    assert_int_equal(rep.terminals_added, 0);
    assert_true(rep.terminals_shared > 0);
    assert_true(rep.rules_shared > 0);
    ag_mesh *d = derive(g);
    ag_box *cb = pf_component_boxes(d);
    ag_box bb = ag_mesh_bounds(d);
    for (size_t s = 0; s < na; s++)
        check_window(cb, d->ncomponents, &sa[s], 0.08, 1, &bb);
    free(cb);
    ag_mesh_free(d);
    ag_grammar_free(g);
    free(sa);
    ag_proceduralize_result_free(ra);
    ag_mesh_free(ma);
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    ag_part_free(p);
}

/* Scope rule on a terminal (B's glass, inlined in its window rule): every application of the
 * terminal gives way to the part, fitted to the pane. */
static void test_rule_scope_terminal(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 0, &ob);
    /* the glass of the first window: inset by the frame, 0.07 behind the casing's face */
    const ag_box *w0 = &sc.slots[0];
    ag_box glass = {{w0->min[0] + 0.12, w0->min[1] + 0.07, w0->min[2] + 0.12},
                    {w0->max[0] - 0.12, w0->min[1] + 0.08, w0->max[2] - 0.12}};
    int32_t target = pf_node_with_box(sc.r, &glass, TOL);
    assert_true(target > 0);
    scene_compose(&sc, target, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE);
    assert_int_equal(sc.rep.instances, sc.ns);
    /* the panes of every slot: inset by B's frame */
    ag_box *panes = malloc(sc.ns * sizeof *panes);
    for (size_t s = 0; s < sc.ns; s++) {
        int u = along_axis(&sc.slots[s]);
        panes[s] = sc.slots[s];
        panes[s].min[u] += 0.12;
        panes[s].max[u] -= 0.12;
        panes[s].min[2] += 0.12;
        panes[s].max[2] -= 0.12;
    }
    size_t inside, n = part_components(&sc, panes, sc.ns, &inside);
    assert_int_equal(n, 7 * sc.ns);
    assert_int_equal(inside, n);
    /* B's window keeps its casing, bars and mullions around the new content */
    assert_int_equal(sc.d->ncomponents, 5 + (7 + 7) * sc.ns);
    free(panes);
    scene_close(&sc);
}

/* A pattern node (B's front window grid): scope node replaces the whole grid by one part fitted
 * to it; scope rule is refused with the rule named. */
static void test_pattern_target(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 0, &ob);
    const ag_splittree *t = sc.r->tree;
    int32_t pat = t->nodes[pf_node_with_box(sc.r, &sc.slots[0], TOL)].parent;
    while (pat >= 0 && t->nodes[pat].kind == AG_NODE_SPLIT)
        pat = t->nodes[pat].parent;
    assert_int_equal(t->nodes[pat].kind, AG_NODE_PATTERN);
    ag_box grid = t->nodes[pat].box;
    ag_compose_op op = {.target = pat, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_RULE};
    ag_grammar *g = NULL;
    ag_error err = {0};
    assert_int_equal(ag_compose(sc.r, sc.part, &op, &g, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "pattern"));
    scene_compose(&sc, pat, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE);
    size_t inside, n = part_components(&sc, &grid, 1, &inside), in_grid = 0;
    for (size_t c = 0; c < sc.d->ncomponents; c++)
        in_grid += pf_inside(&sc.cb[c], &grid, TOL);
    assert_int_equal(n, 7);
    assert_int_equal(inside, 7);
    assert_int_equal(in_grid, 7); /* nothing of B's front windows is left in the grid */
    /* the part's casing spans the grid: the frame bars keep 0.08 */
    check_window(sc.cb, sc.d->ncomponents, &grid, 0.08, 1, &sc.bounds);
    scene_close(&sc);
}

/* Bad ops: a node that does not exist, an inlined target with scope rule, a bad mode. */
static void test_bad_ops(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_part *p = save_window(&oa, 0);
    ag_mesh *m;
    ag_box *slots;
    size_t ns;
    ag_proceduralize_result *r = building(&ob, &m, &slots, &ns);
    ag_grammar *g = NULL;
    ag_error err = {0};
    ag_compose_op op = {.target = 100000, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_NODE};
    assert_int_equal(ag_compose(r, p, &op, &g, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "100000"));
    op.target = -1;
    assert_int_equal(ag_compose(r, p, &op, &g, NULL, &err), AG_ERR_NOT_FOUND);
    op.target = 0;
    op.scope = AG_COMPOSE_RULE;
    assert_int_equal(ag_compose(r, p, &op, &g, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "scope node"));
    op.mode = 7;
    assert_int_equal(ag_compose(r, p, &op, &g, NULL, &err), AG_ERR_INVALID);
    assert_null(g);
    ag_part_meta meta = {.name = ""};
    ag_part *q = NULL;
    assert_int_equal(ag_part_extract(r, 1, &meta, &q, &err), AG_ERR_INVALID);
    meta.name = "x";
    assert_int_equal(ag_part_extract(r, 99999, &meta, &q, &err), AG_ERR_NOT_FOUND);
    assert_null(q);
    free(slots);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    ag_part_free(p);
}

/* b turned by `turn` quarter turns about z (as pf_building turns its building). */
static ag_box turned_box(const ag_box *b, int turn)
{
    ag_box r = {{INFINITY, INFINITY, b->min[2]}, {-INFINITY, -INFINITY, b->max[2]}};
    for (int i = 0; i < 4; i++) {
        double x = i & 1 ? b->max[0] : b->min[0], y = i & 2 ? b->max[1] : b->min[1];
        for (int k = 0; k < (turn & 3); k++) {
            double t = x;
            x = -y;
            y = t;
        }
        r.min[0] = fmin(r.min[0], x);
        r.max[0] = fmax(r.max[0], x);
        r.min[1] = fmin(r.min[1], y);
        r.max[1] = fmax(r.max[1], y);
    }
    return r;
}

static int by_min_along(const void *x, const void *y, void *ctx)
{
    int u = *(const int *)ctx;
    double a = ((const ag_box *)x)->min[u], b = ((const ag_box *)y)->min[u];
    return a < b ? -1 : a > b;
}

/* The top node above n that is not the root (visible, or a pattern when grid is set). */
static int32_t top_above(const ag_splittree *t, int32_t n, int grid)
{
    int32_t up = n;
    for (int32_t p = t->nodes[n].parent; p > 0; p = t->nodes[p].parent)
        if (t->nodes[p].kind == (grid ? AG_NODE_PATTERN : AG_NODE_COMPONENT))
            up = p;
    return up;
}

/* A facade part (A's front wall with two rows of ten windows) replaces B's blank left wall of
 * `ratio` times its length: the wall holds more or fewer columns of A's window at the window's
 * own size and spacing (as a resize does), measured on the derived mesh: the casings found by
 * their boxes, counted (as many as fit in the wall at A's density), their widths and spacing
 * within 1 %, every piece of the part inside the wall's box, each window's frame bars 0.08
 * wide. Proud windows stand out of their wall, so no node holds both: there A's grid of
 * windows replaces B's (two columns as long as the ratio says). */
static void facade_onto_wall(int depth, int turn_a, int turn_b, double ratio)
{
    const unsigned N = 10, rows = 2;
    int grid = depth == PF_PROUD;
    pf_options oa = pf_design_a(depth, turn_a, 0, 0);
    oa.cols = N;
    oa.rows = rows;
    double sx = oa.ww + 1.0; /* the fixture's spacing */
    double Wa = grid ? (N - 1) * sx + oa.ww : 2 * 0.9 + (N - 1) * sx + oa.ww, L = ratio * Wa;
    ag_mesh *ma;
    ag_box *sa;
    size_t nsa;
    ag_proceduralize_result *ra = building(&oa, &ma, &sa, &nsa);
    /* the facade: the top node above a window, below the building's root */
    const ag_splittree *ta = ra->tree;
    int32_t fnode = pf_node_with_box(ra, &sa[0], TOL);
    assert_true(fnode > 0);
    fnode = top_above(ta, fnode, grid);
    for (size_t s = 0; s < nsa; s++) /* it holds every window */
        assert_true(pf_inside(&sa[s], &ta->nodes[fnode].box, TOL));
    ag_part_meta meta = {.name = "row facade", .source = "A"};
    ag_part *part = NULL;
    ag_error err = {0};
    if (ag_part_extract(ra, fnode, &meta, &part, &err))
        fail_msg("extract: %s", err.text);
    /* B: as tall as A, its left wall (blank) L long, or its grid of two columns L long */
    pf_options ob = pf_design_b(depth, turn_b, 0, 0);
    ob.side_cols = 0;
    ob.rows = rows;
    ob.wh = oa.wh;
    if (grid) {
        ob.cols = 2;
        ob.sx = L - ob.ww;
    } else {
        ob.sx = L - 1.8 - ob.ww; /* the left wall: 2 * 0.9 + sx + ww */
    }
    ag_mesh *mb;
    ag_box *sb;
    size_t nsb;
    ag_proceduralize_result *rb = building(&ob, &mb, &sb, &nsb);
    double Ht = 1.0 + rows * (ob.wh + 1.2);
    ag_box left0 = {{0, 0, 0}, {0.3, L, Ht}}, T = turned_box(&left0, turn_b);
    int32_t target = grid ? top_above(rb->tree, pf_node_with_box(rb, &sb[0], TOL), 1)
                          : pf_node_with_box(rb, &T, TOL);
    assert_true(target > 0);
    if (grid)
        T = rb->tree->nodes[target].box;
    ag_compose_report rep;
    ag_grammar *g = compose(rb, part, target, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, &rep);
    ag_mesh *d = derive(g);
    ag_box *cb = pf_component_boxes(d), bounds = ag_mesh_bounds(d);
    /* the columns at A's density, fewer while they do not fit at A's spacing */
    unsigned k = (unsigned)lround(N * ratio);
    while (k > 1 && (k - 1) * sx + oa.ww > L + TOL)
        k--;
    print_message("ratio %.2f: %u columns expected\n", ratio, k);
    int u = along_axis(&T), v = 1 - u;
    ag_box *cas = malloc((d->ncomponents + 1) * sizeof *cas);
    size_t ncas = 0, npart = 0;
    for (size_t c = 0; c < d->ncomponents; c++) {
        int32_t gi = d->component_group[c];
        if (gi < 0 || strncmp(d->group_names[gi], "row_facade_", 11))
            continue;
        npart++;
        if (!pf_inside(&cb[c], &T, TOL))
            fail_msg("a piece of the part lies outside the target's box");
        double eu = cb[c].max[u] - cb[c].min[u], ev = cb[c].max[v] - cb[c].min[v];
        double ez = cb[c].max[2] - cb[c].min[2];
        if (fabs(eu - oa.ww) <= 0.01 * oa.ww && fabs(ez - oa.wh) <= 0.01 * oa.wh &&
            fabs(ev - 0.16) <= 0.01 * 0.16)
            cas[ncas++] = cb[c];
    }
    assert_int_equal(ncas, k * rows);
    /* seven pieces per window, and A's wall */
    assert_int_equal(npart, 7 * k * rows + !grid);
    qsort_r(cas, ncas, sizeof *cas, by_min_along, &u);
    /* per column (two casings at one place along the wall): the spacing of A's windows */
    for (size_t i = 0; i + rows < ncas; i += rows) {
        double gap = cas[i + rows].min[u] - cas[i].min[u];
        if (fabs(gap - sx) > 0.01 * sx)
            fail_msg("columns %zu and %zu are %g apart, not %g", i / rows, i / rows + 1, gap, sx);
    }
    for (size_t i = 0; i < ncas; i++) /* each a window of A: frame 0.08, one mullion */
        check_window(cb, d->ncomponents, &cas[i], oa.frame, oa.mullions, &bounds);
    free(cas);
    free(cb);
    ag_mesh_free(d);
    ag_grammar_free(g);
    free(sb);
    ag_proceduralize_result_free(rb);
    ag_mesh_free(mb);
    ag_part_free(part);
    free(sa);
    ag_proceduralize_result_free(ra);
    ag_mesh_free(ma);
}

static void test_facade_narrower_recessed(void **state) { (void)state; facade_onto_wall(PF_RECESSED, 0, 0, 0.77); }
static void test_facade_much_narrower_flush(void **state) { (void)state; facade_onto_wall(PF_FLUSH, 0, 0, 0.6); }
static void test_facade_wider_proud(void **state) { (void)state; facade_onto_wall(PF_PROUD, 0, 0, 1.5); }
static void test_facade_twice_turned(void **state) { (void)state; facade_onto_wall(PF_RECESSED, 1, 3, 2.0); }
static void test_facade_narrower_both_turned(void **state) { (void)state; facade_onto_wall(PF_FLUSH, 2, 1, 0.77); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rule_replace_recessed),
        cmocka_unit_test(test_rule_replace_flush_turned),
        cmocka_unit_test(test_rule_replace_proud_utm),
        cmocka_unit_test(test_rule_replace_both_turned),
        cmocka_unit_test(test_rule_replace_jittered_flipped),
        cmocka_unit_test(test_node_replace),
        cmocka_unit_test(test_fill_blank_wall),
        cmocka_unit_test(test_insert_balcony),
        cmocka_unit_test(test_names_clash_and_share),
        cmocka_unit_test(test_rule_scope_terminal),
        cmocka_unit_test(test_pattern_target),
        cmocka_unit_test(test_bad_ops),
        cmocka_unit_test(test_facade_narrower_recessed),
        cmocka_unit_test(test_facade_much_narrower_flush),
        cmocka_unit_test(test_facade_wider_proud),
        cmocka_unit_test(test_facade_twice_turned),
        cmocka_unit_test(test_facade_narrower_both_turned),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
