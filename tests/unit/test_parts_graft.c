/* Parts: the composed model grafted into the target's tree (core/parts/graft.c) is the model
 * the composed grammar's derivation proceduralized would be. On the generated buildings of the
 * compose tests (parts_fixture.h: windows recessed, flush or proud, buildings turned, at
 * UTM-sized offsets, jittered, triangulated the other way) and on every mode and scope, the
 * graft's mesh and what its grammar derives are compared with the slow path's (the
 * derivation proceduralized), independently of either's own verdict: welded vertex sets,
 * per-label area lists, component counts, every component's edges shared by exactly two
 * faces. The grafted grammar prints, parses and prints to the same bytes; nodes outside the
 * target keep their ids and boxes; a resize of the grafted model works. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "app/model_kept.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "core/parts/compose.h"
#include "core/parts/graft.h"
#include "core/parts/part.h"
#include "io/grammar_text.h"
#include "parts_fixture.h"

#define TOL 1e-6

static ag_edit_model *model_of(const ag_mesh *m)
{
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_create(m, NULL, &em, &err))
        fail_msg("proceduralize: %s", err.text);
    return em;
}

static ag_part *save_node(const ag_proceduralize_result *r, int32_t node, const char *name)
{
    ag_part_meta meta = {.name = name};
    ag_part *p = NULL;
    ag_error err = {0};
    if (ag_part_extract(r, node, &meta, &p, &err))
        fail_msg("extract: %s", err.text);
    return p;
}

/* Window `which` of a building of design o, as a part. */
static ag_part *save_window(const pf_options *o, int which)
{
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(o, &slots, &ns);
    ag_edit_model *em = model_of(m);
    int32_t node = pf_node_with_box(em->proc, &slots[which], TOL);
    assert_true(node > 0);
    ag_part *p = save_node(em->proc, node, "sash window");
    free(slots);
    ag_edit_model_free(em);
    ag_mesh_free(m);
    return p;
}

/* A window of design oa (window `which`) as a part and a building of design ob, proceduralized
 * as the service keeps it. */
typedef struct {
    ag_part *part;
    ag_mesh *m;
    ag_box *slots;
    size_t ns;
    ag_edit_model *em;
} scene;

static void scene_open(scene *sc, const pf_options *oa, int which, const pf_options *ob)
{
    sc->part = save_window(oa, which);
    sc->m = pf_building(ob, &sc->slots, &sc->ns);
    sc->em = model_of(sc->m);
}

static void scene_close(scene *sc)
{
    ag_edit_model_free(sc->em);
    free(sc->slots);
    ag_mesh_free(sc->m);
    ag_part_free(sc->part);
}

/* ---- independent measures -------------------------------------------------------------------- */

static void same_label_areas(const ag_mesh *a, const ag_mesh *b, const char *what)
{
    size_t na, nb;
    double *x = mm_group_areas(a, &na), *y = mm_group_areas(b, &nb);
    if (na != nb)
        fail_msg("%s: %zu labels with geometry, the slow path %zu", what, na, nb);
    for (size_t i = 0; i < na; i++)
        if (fabs(x[i] - y[i]) > 1e-6 * fmax(1, y[i]))
            fail_msg("%s: label area %g, the slow path %g", what, x[i], y[i]);
    free(x);
    free(y);
}

static int cmp_edge(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b;
    return *x < *y ? -1 : *x > *y;
}

/* Every component closed: welded by position, each of its edges in exactly two triangles. */
static void components_closed(const ag_mesh *m, const char *what)
{
    ag_box bb = ag_mesh_bounds(m);
    size_t *start = calloc(m->ncomponents + 2, sizeof *start);
    for (size_t t = 0; t < m->ntris; t++)
        start[m->tri_component[t] + 1]++;
    for (size_t c = 0; c < m->ncomponents; c++)
        start[c + 1] += start[c];
    size_t *fill = malloc((m->ncomponents + 1) * sizeof *fill);
    memcpy(fill, start, m->ncomponents * sizeof *fill);
    size_t *tris = malloc((m->ntris + 1) * sizeof *tris);
    for (size_t t = 0; t < m->ntris; t++)
        tris[fill[m->tri_component[t]]++] = t;
    for (size_t c = 0; c < m->ncomponents; c++) {
        size_t nt = start[c + 1] - start[c];
        if (!nt)
            continue;
        mm_cell *p = malloc(3 * nt * sizeof *p);
        for (size_t i = 0; i < nt; i++)
            for (int j = 0; j < 3; j++)
                for (int a = 0; a < 3; a++)
                    p[3 * i + j].k[a] =
                        llround((m->pos[3 * m->tri[3 * tris[start[c] + i] + j] + a] - bb.min[a]) * 1e5);
        /* weld: a vertex's id is the index of its first equal point */
        uint32_t *id = malloc(3 * nt * sizeof *id);
        for (size_t i = 0; i < 3 * nt; i++) {
            id[i] = (uint32_t)i;
            for (size_t k = 0; k < i; k++)
                if (!mm_cmp_cell(&p[i], &p[k])) {
                    id[i] = id[k];
                    break;
                }
        }
        uint64_t *e = malloc(3 * nt * sizeof *e);
        for (size_t i = 0; i < nt; i++)
            for (int j = 0; j < 3; j++) {
                uint64_t a = id[3 * i + j], b = id[3 * i + (j + 1) % 3];
                e[3 * i + j] = a < b ? a << 32 | b : b << 32 | a;
            }
        qsort(e, 3 * nt, sizeof *e, cmp_edge);
        for (size_t i = 0; i < 3 * nt;) {
            size_t k = i;
            while (k < 3 * nt && e[k] == e[i])
                k++;
            if (k - i != 2)
                fail_msg("%s: component %zu has an edge in %zu triangles", what, c, k - i);
            i = k;
        }
        free(p);
        free(id);
        free(e);
    }
    free(start);
    free(fill);
    free(tris);
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return x < y ? -1 : x > y;
}

/* Per visible node, the size of its rule class (0 without one), sorted: what repeats in one
 * tree repeats as often in the other (a part turned onto other facades is one class). */
static size_t *class_sizes(const ag_splittree *t, size_t *n)
{
    size_t *z = malloc((t->nnodes + 1) * sizeof *z), k = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT)
            z[k++] = t->nodes[i].rule >= 0 ? t->rule_count[t->nodes[i].rule] : 0;
    qsort(z, k, sizeof *z, cmp_size);
    *n = k;
    return z;
}

/* Compositions into a model grafted before may group rule classes otherwise than the slow
 * path does (the derivation's mesh is the same; a part composed twice can stay two classes):
 * those only print the difference. */
static int classes_may_differ;

static void same_classes(const ag_splittree *a, const ag_splittree *b, const char *what)
{
    size_t na, nb;
    size_t *x = class_sizes(a, &na), *y = class_sizes(b, &nb);
    assert_int_equal(na, nb);
    size_t differ = 0;
    for (size_t i = 0; i < na; i++)
        differ += x[i] != y[i];
    if (differ && classes_may_differ)
        print_message("%s: %zu visible nodes are in rule classes of other sizes than the slow "
                      "path's\n", what, differ);
    else if (differ)
        fail_msg("%s: %zu visible nodes are in rule classes of other sizes than the slow path's "
                 "(largest %zu, the slow path's %zu)",
                 what, differ, x[na - 1], y[nb - 1]);
    free(x);
    free(y);
}

static int under(const ag_splittree *t, int32_t n, int32_t anc)
{
    for (int32_t p = n; p >= 0; p = t->nodes[p].parent)
        if (p == anc)
            return 1;
    return 0;
}

/* ---- the comparison ------------------------------------------------------------------------- */

/* Composes part into em's node target both ways and compares; returns the grafted model. */
static ag_edit_model *compare(ag_edit_model *em, const ag_part *part, int32_t target, int mode,
                              int scope, const char *what)
{
    ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
    ag_grammar *g = NULL;
    ag_compose_report crep;
    ag_error err = {0};
    if (ag_compose(em->proc, part, &op, &g, &crep, &err))
        fail_msg("%s: compose: %s", what, err.text);
    ag_mesh *d = NULL;
    if (ag_grammar_derive(g, NULL, &d, &err))
        fail_msg("%s: derive: %s", what, err.text);
    ag_edit_model *slow = model_of(d);
    ag_proceduralize_result *fast = NULL;
    ag_graft_report rep;
    if (ag_graft_compose(em->proc, &op, d, &em->opt.patterns, &fast, &rep, &err))
        fail_msg("%s: the graft does not apply: %s", what, err.text);
    print_message("%s: %zu sites, %zu kept, %zu removed, %zu added\n", what, rep.sites, rep.kept,
                  rep.removed, rep.added);
    assert_true(rep.added > 0);
    /* the model's mesh, and what its grammar derives, are the slow path's */
    assert_int_equal(fast->mesh->ncomponents, slow->proc->mesh->ncomponents);
    pf_same_welded(fast->mesh, slow->proc->mesh, what);
    same_label_areas(fast->mesh, slow->proc->mesh, what);
    components_closed(fast->mesh, what);
    ag_mesh *fd = NULL;
    if (ag_grammar_derive(fast->grammar, NULL, &fd, &err))
        fail_msg("%s: the grafted grammar does not derive: %s", what, err.text);
    assert_int_equal(fd->ncomponents, d->ncomponents);
    pf_same_welded(fd, d, what);
    same_label_areas(fd, d, what);
    pf_check_roundtrip(fast->grammar);
    same_classes(fast->tree, slow->proc->tree, what);
    /* visible nodes away from the sites keep their ids and boxes */
    const ag_splittree *T = em->proc->tree, *F = fast->tree;
    size_t kept = 0;
    for (size_t n = 0; n < T->nnodes; n++) {
        const ag_tnode *x = &T->nodes[n];
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int touched = 0;
        if (scope == AG_COMPOSE_NODE)
            touched = under(T, (int32_t)n, target) && (mode != AG_COMPOSE_INSERT);
        else
            for (int32_t p = (int32_t)n; p >= 0 && !touched; p = T->nodes[p].parent)
                touched = T->nodes[p].kind == AG_NODE_COMPONENT &&
                          T->nodes[p].rule == T->nodes[target].rule;
        if (touched)
            continue;
        assert_true(n < F->nnodes);
        assert_int_equal(F->nodes[n].kind, AG_NODE_COMPONENT);
        assert_true(pf_same_box(&F->nodes[n].box, &x->box, TOL));
        kept++;
    }
    assert_true(kept > 0);
    ag_edit_model *out = NULL;
    if (ag_edit_model_wrap(fast, &em->opt, &out, &err))
        fail_msg("wrap: %s", err.text);
    /* as the store keeps it (the mesh and the tree text) it reloads node for node */
    char *kept_text = ag_model_kept_tree_text(out);
    assert_non_null(kept_text);
    ag_edit_model *back = NULL;
    if (ag_model_kept_reload(out->proc->mesh, kept_text, &back, &err))
        fail_msg("%s: the kept model does not reload: %s", what, err.text);
    assert_int_equal(back->proc->tree->nnodes, out->proc->tree->nnodes);
    for (size_t n = 0; n < out->proc->tree->nnodes; n++) {
        assert_int_equal(back->proc->tree->nodes[n].kind, out->proc->tree->nodes[n].kind);
        /* a dead node keeps only its id: no box to compare */
        if (out->proc->tree->nodes[n].kind != AG_NODE_DEAD)
            assert_true(pf_same_box(&back->proc->tree->nodes[n].box, &out->proc->tree->nodes[n].box, TOL));
    }
    ag_edit_model_free(back);
    free(kept_text);
    ag_mesh_free(fd);
    ag_edit_model_free(slow);
    ag_mesh_free(d);
    ag_grammar_free(g);
    return out;
}

/* A resize of the grafted model: the whole building 1.1 times wider. */
static void resize_works(ag_edit_model *m)
{
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 0, .has_scale = 1, .scale = {1.1, 1, 1}};
    ag_edit_model *out = NULL;
    ag_error err = {0};
    if (ag_edit_apply_ex(m, &op, 0, &out, NULL, &err))
        fail_msg("resize the grafted model: %s", err.text);
    ag_box a = ag_mesh_bounds(m->proc->mesh), b = ag_mesh_bounds(out->proc->mesh);
    assert_true(fabs((b.max[0] - b.min[0]) - 1.1 * (a.max[0] - a.min[0])) < 1e-6);
    assert_true(out->proc->mesh->ncomponents >= m->proc->mesh->ncomponents);
    ag_edit_model_free(out);
}

static void rule_replace(int depth, int turn_a, int turn_b, double ox, double oy, double jitter,
                         int flip)
{
    pf_options oa = pf_design_a(depth, turn_a, ox, oy), ob = pf_design_b(depth, turn_b, -ox, oy);
    oa.flip = flip;
    ob.jitter = jitter;
    scene sc;
    scene_open(&sc, &oa, 1, &ob);
    ag_part *p = sc.part;
    ag_box *slots = sc.slots;
    ag_edit_model *em = sc.em;
    int32_t target = pf_node_with_box(em->proc, &slots[5], TOL);
    assert_true(target > 0);
    ag_edit_model *g = compare(em, p, target, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "rule replace");
    resize_works(g);
    ag_edit_model_free(g);
    scene_close(&sc);
}

static void test_rule_replace_recessed(void **state) { (void)state; rule_replace(PF_RECESSED, 0, 0, 0, 0, 0, 0); }
static void test_rule_replace_flush_turned(void **state) { (void)state; rule_replace(PF_FLUSH, 1, 0, 0, 0, 0, 0); }
static void test_rule_replace_proud_utm(void **state)
{
    (void)state;
    rule_replace(PF_PROUD, 0, 3, 512345.0, 5403210.0, 0, 0);
}
static void test_rule_replace_both_turned(void **state) { (void)state; rule_replace(PF_RECESSED, 2, 1, 0, 0, 0, 0); }
static void test_rule_replace_jittered_flipped(void **state)
{
    (void)state;
    rule_replace(PF_RECESSED, 0, 1, 0, 0, 0.003, 1);
}

/* Scope node, replace: one window, the building turned two ways; then the same on a model
 * that was composed before (ids kept across two grafts). */
static void test_node_replace(void **state)
{
    (void)state;
    for (int turn = 0; turn < 4; turn += 3) {
        pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, turn, 0, 0);
        scene sc;
        scene_open(&sc, &oa, 0, &ob);
        ag_part *p = sc.part;
        ag_box *slots = sc.slots;
        ag_edit_model *em = sc.em;
        int32_t target = pf_node_with_box(em->proc, &slots[13], TOL);
        assert_true(target > 0);
        ag_edit_model *g = compare(em, p, target, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "node replace");
        int32_t again = pf_node_with_box(g->proc, &slots[2], TOL);
        assert_true(again > 0);
        classes_may_differ = 1;
        ag_edit_model *g2 = compare(g, p, again, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE,
                                    "node replace, again");
        classes_may_differ = 0;
        resize_works(g2);
        ag_edit_model_free(g2);
        ag_edit_model_free(g);
        scene_close(&sc);
    }
}

/* Fill: the blank back wall becomes a grid of the window (flush or proud of the wall). */
static void test_fill_blank_wall(void **state)
{
    (void)state;
    for (int depth = PF_FLUSH; depth <= PF_PROUD; depth++) {
        pf_options oa = pf_design_a(depth, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
        scene sc;
        scene_open(&sc, &oa, 2, &ob);
        ag_part *p = sc.part;
        ag_edit_model *em = sc.em;
        ag_box bounds = ag_mesh_bounds(sc.m);
        double Dp = bounds.max[1] - 0.2;
        ag_box back = {{0, Dp - 0.3, 0}, {11.2, Dp, 10.6}};
        int32_t target = pf_node_with_box(em->proc, &back, TOL);
        assert_true(target > 0);
        ag_edit_model *g = compare(em, p, target, AG_COMPOSE_FILL, AG_COMPOSE_NODE, "fill");
        resize_works(g);
        ag_edit_model_free(g);
        scene_close(&sc);
    }
}

/* Insert: a balcony part between the front wall and its windows. */
static void test_insert_balcony(void **state)
{
    (void)state;
    pf_options oc = pf_design_a(PF_FLUSH, 0, 0, 0);
    oc.balcony = 1;
    ag_box *sc;
    size_t nsc;
    ag_mesh *mc = pf_building(&oc, &sc, &nsc);
    ag_edit_model *ec = model_of(mc);
    ag_box bal = {{0.9, -1.0, 1.0}, {3.9, 0, 2.1}};
    int32_t bn = pf_node_with_box(ec->proc, &bal, TOL);
    assert_true(bn > 0);
    ag_part *p = save_node(ec->proc, bn, "balcony");
    pf_options ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    ag_box *slots;
    size_t ns;
    ag_mesh *m = pf_building(&ob, &slots, &ns);
    ag_edit_model *em = model_of(m);
    ag_box front = {{0, 0, 0}, {11.2, 0.3, 10.6}};
    int32_t target = pf_node_with_box(em->proc, &front, TOL);
    assert_true(target > 0);
    ag_edit_model *g = compare(em, p, target, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "insert");
    resize_works(g);
    ag_edit_model_free(g);
    ag_edit_model_free(em);
    ag_edit_model_free(ec);
    free(slots);
    free(sc);
    ag_mesh_free(m);
    ag_mesh_free(mc);
    ag_part_free(p);
}

/* Scope rule on a terminal (B's glass): every pane gives way to the part. */
static void test_rule_scope_terminal(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 0, &ob);
    ag_part *p = sc.part;
    ag_box *slots = sc.slots;
    ag_edit_model *em = sc.em;
    const ag_box *w0 = &slots[0];
    ag_box glass = {{w0->min[0] + 0.12, w0->min[1] + 0.07, w0->min[2] + 0.12},
                    {w0->max[0] - 0.12, w0->min[1] + 0.08, w0->max[2] - 0.12}};
    int32_t target = pf_node_with_box(em->proc, &glass, TOL);
    assert_true(target > 0);
    ag_edit_model *g = compare(em, p, target, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "rule terminal");
    ag_edit_model_free(g);
    scene_close(&sc);
}

/* A pattern node (the front window grid) replaced by one part, scope node. */
static void test_pattern_target(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 0, &ob);
    ag_part *p = sc.part;
    ag_box *slots = sc.slots;
    ag_edit_model *em = sc.em;
    const ag_splittree *t = em->proc->tree;
    int32_t pat = t->nodes[pf_node_with_box(em->proc, &slots[0], TOL)].parent;
    while (pat >= 0 && t->nodes[pat].kind == AG_NODE_SPLIT)
        pat = t->nodes[pat].parent;
    assert_int_equal(t->nodes[pat].kind, AG_NODE_PATTERN);
    ag_edit_model *g = compare(em, p, pat, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "pattern node");
    ag_edit_model_free(g);
    scene_close(&sc);
}

/* The graft refuses (AG_ERR_NOT_AVAILABLE, so a service proceduralizes instead) a derivation
 * that does not pair with the model: a kept component moved, or other geometry in its box. */
static void test_refuses_what_does_not_pair(void **state)
{
    (void)state;
    pf_options oa = pf_design_a(PF_RECESSED, 0, 0, 0), ob = pf_design_b(PF_RECESSED, 0, 0, 0);
    scene sc;
    scene_open(&sc, &oa, 0, &ob);
    ag_part *p = sc.part;
    ag_box *slots = sc.slots;
    ag_edit_model *em = sc.em;
    int32_t target = pf_node_with_box(em->proc, &slots[13], TOL);
    ag_compose_op op = {.target = target, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_NODE};
    ag_grammar *g = NULL;
    ag_error err = {0};
    assert_int_equal(ag_compose(em->proc, p, &op, &g, NULL, &err), AG_OK);
    for (int how = 0; how < 2; how++) {
        ag_mesh *d = NULL;
        assert_int_equal(ag_grammar_derive(g, NULL, &d, &err), AG_OK);
        /* the largest component (a wall, away from the target) */
        ag_box *cb = pf_component_boxes(d);
        size_t wall = 0;
        for (size_t c = 1; c < d->ncomponents; c++)
            if (ag_box_volume(&cb[c]) > ag_box_volume(&cb[wall]))
                wall = c;
        uint8_t *mine = calloc(d->nverts, 1);
        for (size_t t = 0; t < d->ntris; t++)
            if (d->tri_component[t] == wall)
                for (int j = 0; j < 3; j++)
                    mine[d->tri[3 * t + j]] = 1;
        for (size_t v = 0; v < d->nverts; v++) {
            if (!mine[v])
                continue;
            double *x = &d->pos[3 * v];
            if (how == 0) /* moved by 1 m */
                x[0] += 1.0;
            else if (x[0] == cb[wall].max[0] && x[1] == cb[wall].min[1] && x[2] == cb[wall].max[2])
                x[1] = cb[wall].max[1]; /* one corner pulled through: the same box, another surface */
        }
        ag_box after = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (size_t v = 0; v < d->nverts; v++)
            if (mine[v])
                ag_box_extend_point(&after, &d->pos[3 * v]);
        if (how == 1)
            assert_true(pf_same_box(&after, &cb[wall], 1e-12));
        ag_proceduralize_result *r = NULL;
        ag_error e = {0};
        assert_int_equal(ag_graft_compose(em->proc, &op, d, &em->opt.patterns, &r, NULL, &e),
                         AG_ERR_NOT_AVAILABLE);
        assert_null(r);
        print_message("refused: %s\n", e.text);
        assert_non_null(strstr(e.text, "node"));
        free(mine);
        free(cb);
        ag_mesh_free(d);
    }
    ag_grammar_free(g);
    scene_close(&sc);
}

static size_t visible_under(const ag_splittree *t, int32_t n)
{
    size_t k = t->nodes[n].kind == AG_NODE_COMPONENT;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling)
        k += visible_under(t, c);
    return k;
}

/* The bench's building (bench/parts.c) at a small size: every box its own component, windows
 * of several pieces on three facades in patterns, a blank back, an annex. As the bench picks:
 * the most repeated visible node, the one with the largest subtree (a facade), the largest
 * leaf (the blank wall). Each case is composed into the previous case's grafted model, as the
 * service's ops follow one another. */
static void test_generated_facade(void **state)
{
    (void)state;
    for (int bars = 0; bars <= 3; bars += 3) {
        ag_gen_facade_options go = {.cols = 6, .rows = 4, .side_cols = 4, .left = 1, .bars = (unsigned)bars,
                                    .no_groups = 1, .annex = 1};
        ag_mesh *m = NULL;
        assert_int_equal(ag_gen_facade(&go, &m, NULL), AG_OK);
        ag_edit_model *em = model_of(m);
        const ag_splittree *t = em->proc->tree;
        int32_t rep = -1, big = -1;
        size_t best_rep = 0, best_sub = 0;
        for (size_t i = 1; i < t->nnodes; i++) {
            const ag_tnode *n = &t->nodes[i];
            if (n->kind != AG_NODE_COMPONENT)
                continue;
            if (n->rule >= 0 && t->rule_count[n->rule] > best_rep) {
                best_rep = t->rule_count[n->rule];
                rep = (int32_t)i;
            }
            size_t sub = visible_under(t, (int32_t)i);
            if (sub > best_sub) {
                best_sub = sub;
                big = (int32_t)i;
            }
        }
        assert_true(rep > 0 && big > 0 && best_sub > 10);
        ag_part *piece = save_node(em->proc, rep, "window piece");
        ag_part *facade = save_node(em->proc, big, "facade");
        ag_edit_model *a = compare(em, piece, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "piece into its rule");
        /* the same node id names the same place in the grafted model */
        assert_true(pf_same_box(&a->proc->tree->nodes[big].box, &t->nodes[big].box, TOL));
        classes_may_differ = 1;
        ag_edit_model *b = compare(a, piece, big, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "piece under a facade");
        /* the largest leaf of the grafted model: a blank wall */
        const ag_splittree *tb = b->proc->tree;
        int32_t leaf = -1;
        double best_area = 0;
        for (size_t i = 1; i < tb->nnodes; i++) {
            const ag_tnode *n = &tb->nodes[i];
            if (n->kind != AG_NODE_COMPONENT || n->first_child >= 0)
                continue;
            double area = fmax(n->box.max[0] - n->box.min[0], n->box.max[1] - n->box.min[1]) *
                          (n->box.max[2] - n->box.min[2]);
            if (area > best_area) {
                best_area = area;
                leaf = (int32_t)i;
            }
        }
        assert_true(leaf > 0);
        ag_edit_model *c = compare(b, facade, leaf, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "facade onto the blank wall");
        classes_may_differ = 0;
        resize_works(c);
        /* the facade onto a narrower facade: fewer columns of its windows (core/parts/fitcount.h),
         * grafted as the slow path proceduralizes them */
        int32_t side = -1;
        size_t best_side = 0;
        const ag_box *bb = &t->nodes[big].box;
        for (size_t i = 1; i < t->nnodes; i++) {
            const ag_box *b2 = &t->nodes[i].box;
            size_t sub = t->nodes[i].kind == AG_NODE_COMPONENT && (int32_t)i != big
                             ? visible_under(t, (int32_t)i)
                             : 0;
            double w = b2->max[0] - b2->min[0] + b2->max[1] - b2->min[1];
            if (sub > best_side && w < 0.95 * (bb->max[0] - bb->min[0] + bb->max[1] - bb->min[1])) {
                best_side = sub;
                side = (int32_t)i;
            }
        }
        assert_true(side > 0);
        /* the mesh is the slow path's; two visible nodes may fall in rule classes of other
         * sizes (as for the blank wall above) */
        classes_may_differ = 1;
        ag_edit_model *e = compare(em, facade, side, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE,
                                   "facade onto a narrower facade");
        classes_may_differ = 0;
        /* the side's four columns give way to four of the front's (the same window): as many
         * components as before, where the front's six columns would add two columns more */
        assert_int_equal(e->proc->mesh->ncomponents, em->proc->mesh->ncomponents);
        ag_edit_model_free(e);
        ag_edit_model_free(c);
        ag_edit_model_free(b);
        ag_edit_model_free(a);
        ag_part_free(piece);
        ag_part_free(facade);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

/* a and b are one model exactly: the grammar's text byte for byte, the tree node for node
 * (links, classes, boxes bit for bit), the mesh vertex for vertex. */
static void same_model(const ag_edit_model *a, const ag_edit_model *b, const char *what)
{
    ag_error err = {0};
    char *ta = NULL, *tb = NULL;
    size_t la = 0, lb = 0;
    if (ag_grammar_text_print(a->proc->grammar, &ta, &la, &err) ||
        ag_grammar_text_print(b->proc->grammar, &tb, &lb, &err))
        fail_msg("%s: print: %s", what, err.text);
    if (la != lb || memcmp(ta, tb, la) != 0)
        fail_msg("%s: the grammars differ", what);
    free(ta);
    free(tb);
    const ag_splittree *x = a->proc->tree, *y = b->proc->tree;
    assert_int_equal(x->nnodes, y->nnodes);
    assert_int_equal(x->ncomponents, y->ncomponents);
    assert_int_equal(x->nrules, y->nrules);
    assert_int_equal(x->npatterns, y->npatterns);
    for (size_t n = 0; n < x->nnodes; n++) {
        const ag_tnode *p = &x->nodes[n], *q = &y->nodes[n];
        if (p->kind != q->kind || p->parent != q->parent || p->first_child != q->first_child ||
            p->next_sibling != q->next_sibling || p->component != q->component ||
            p->label != q->label || p->variant != q->variant || p->rule != q->rule ||
            (p->kind != AG_NODE_DEAD && memcmp(&p->box, &q->box, sizeof p->box) != 0))
            fail_msg("%s: node %zu differs (kind %d %d, parent %d %d, first %d %d, next %d %d, "
                     "component %d %d, label %d %d, variant %d %d, rule %d %d, box x %.17g %.17g)",
                     what, n, p->kind, q->kind, p->parent, q->parent, p->first_child,
                     q->first_child, p->next_sibling, q->next_sibling, p->component,
                     q->component, p->label, q->label, p->variant, q->variant, p->rule, q->rule,
                     p->box.min[0], q->box.min[0]);
    }
    const ag_mesh *m = a->proc->mesh, *k = b->proc->mesh;
    assert_int_equal(m->nverts, k->nverts);
    assert_int_equal(m->ntris, k->ntris);
    assert_int_equal(m->ncomponents, k->ncomponents);
    assert_memory_equal(m->pos, k->pos, 3 * m->nverts * sizeof *m->pos);
    assert_memory_equal(m->tri, k->tri, 3 * m->ntris * sizeof *m->tri);
    assert_memory_equal(m->tri_component, k->tri_component, m->ntris * sizeof *m->tri_component);
}

/* One composition by the graft alone (the service's fast path), without the slow path. */
static ag_edit_model *graft_op(const ag_edit_model *em, const ag_part *part, int32_t target,
                               int mode, int scope, const char *what)
{
    ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
    ag_grammar *g = NULL;
    ag_compose_report crep;
    ag_error err = {0};
    ag_mesh *d = NULL;
    ag_proceduralize_result *r = NULL;
    ag_edit_model *out = NULL;
    if (ag_compose(em->proc, part, &op, &g, &crep, &err) || ag_grammar_derive(g, NULL, &d, &err) ||
        ag_graft_compose(em->proc, &op, d, &em->opt.patterns, &r, NULL, &err) ||
        ag_edit_model_wrap(r, &em->opt, &out, &err))
        fail_msg("%s: %s", what, err.text);
    /* the state a store keeps (mesh and tree text) rebuilt in full is this model exactly */
    char *text = ag_model_kept_tree_text(out);
    assert_non_null(text);
    ag_edit_model *back = NULL;
    if (ag_model_kept_reload(out->proc->mesh, text, &back, &err))
        fail_msg("%s: reload: %s", what, err.text);
    same_model(out, back, what);
    ag_edit_model_free(back);
    free(text);
    ag_mesh_free(d);
    ag_grammar_free(g);
    return out;
}

/* The model of a small generated facade (every box its own component), its mesh in *m. */
static ag_edit_model *small_facade_model(ag_mesh **m)
{
    ag_gen_facade_options go = {.cols = 6, .rows = 4, .side_cols = 4, .left = 1, .bars = 3,
                                .no_groups = 1, .annex = 1};
    *m = NULL;
    assert_int_equal(ag_gen_facade(&go, m, NULL), AG_OK);
    return model_of(*m);
}

/* The fast path's state after several ops in a row equals the full rebuild's (the kept state
 * reloaded) after each, and an op undone and done again (from the state kept before it, as
 * undo restores it) gives the same model exactly: nothing of an op stays behind in the model
 * it started from. */
static void test_graft_state_is_the_rebuilds(void **state)
{
    (void)state;
    ag_mesh *m = NULL;
    ag_edit_model *em = small_facade_model(&m);
    const ag_splittree *t = em->proc->tree;
    int32_t rep = ag_splittree_most_repeated(t), big = -1;
    size_t best_sub = 0;
    for (size_t i = 1; i < t->nnodes; i++) {
        size_t sub = t->nodes[i].kind == AG_NODE_COMPONENT ? visible_under(t, (int32_t)i) : 0;
        if (sub > best_sub) {
            best_sub = sub;
            big = (int32_t)i;
        }
    }
    assert_true(rep > 0 && big > 0);
    ag_part *piece = save_node(em->proc, rep, "window piece");
    ag_edit_model *a = graft_op(em, piece, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "rule");
    /* as the service picks: the most repeated node of the current model */
    int32_t other = ag_splittree_most_repeated(a->proc->tree);
    assert_true(other > 0);
    ag_edit_model *b = graft_op(a, piece, other, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "node");
    ag_edit_model *c = graft_op(b, piece, big, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "insert");
    /* c undone, then b undone: composing b's op again from a gives b */
    ag_edit_model *b2 = graft_op(a, piece, other, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "redo");
    same_model(b2, b, "b done again");
    ag_edit_model *c2 = graft_op(b2, piece, big, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "redo c");
    same_model(c2, c, "c done again");
    ag_edit_model_free(c2);
    ag_edit_model_free(b2);
    ag_edit_model_free(c);
    ag_edit_model_free(b);
    ag_edit_model_free(a);
    ag_part_free(piece);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

/* A composition replacing a pattern's cells by copies of one part fitted to them keeps the
 * pattern: its node stays (not dissolved and found again), its cells in lattice order on their
 * boxes, the replaced ones new nodes in their cells' places. */
static void test_cells_keep_their_pattern(void **state)
{
    (void)state;
    ag_mesh *m = NULL;
    ag_edit_model *em = small_facade_model(&m);
    const ag_splittree *t = em->proc->tree;
    int32_t rep = ag_splittree_most_repeated(t);
    assert_true(rep > 0);
    int32_t pn = t->nodes[rep].parent;
    assert_true(pn > 0 && t->nodes[pn].kind == AG_NODE_PATTERN);
    ag_part *piece = save_node(em->proc, rep, "window piece");
    const int scopes[2] = {AG_COMPOSE_RULE, AG_COMPOSE_NODE};
    for (int k = 0; k < 2; k++) {
        int scope = scopes[k];
        ag_edit_model *a = graft_op(em, piece, rep, AG_COMPOSE_REPLACE, scope, "cells");
        const ag_splittree *x = a->proc->tree;
        assert_int_equal(x->nodes[pn].kind, AG_NODE_PATTERN);
        int32_t c = t->nodes[pn].first_child, y = x->nodes[pn].first_child;
        size_t fresh = 0;
        for (; c >= 0 && y >= 0; c = t->nodes[c].next_sibling, y = x->nodes[y].next_sibling) {
            assert_int_equal(x->nodes[y].kind, AG_NODE_COMPONENT);
            assert_true(pf_same_box(&x->nodes[y].box, &t->nodes[c].box, TOL));
            if (c == rep)
                assert_true((size_t)y >= t->nnodes);
            fresh += (size_t)y >= t->nnodes;
        }
        assert_true(c < 0 && y < 0);
        /* scope rule replaces every cell of the rule, scope node the target alone */
        if (scope == AG_COMPOSE_NODE)
            assert_int_equal(fresh, 1);
        else
            assert_true(fresh > 1);
        ag_edit_model_free(a);
    }
    ag_part_free(piece);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

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
        cmocka_unit_test(test_rule_scope_terminal),
        cmocka_unit_test(test_pattern_target),
        cmocka_unit_test(test_generated_facade),
        cmocka_unit_test(test_graft_state_is_the_rebuilds),
        cmocka_unit_test(test_cells_keep_their_pattern),
        cmocka_unit_test(test_refuses_what_does_not_pair),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
