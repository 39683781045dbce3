/* Structure-preserving resize on generated buildings with known structure: a facade with a
 * row of identical windows stretched and squeezed, local and global window edits, the root,
 * the kept factorization of a drag, stable node ids and the exported grammar. */
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
#include "core/gen_facade.h"
#include "io/grammar_text.h"

typedef struct {
    ag_edit_model *model; /* read back through its grammar: the ids ops name */
    int32_t wall;         /* the visible node holding the window pattern */
    int32_t window;       /* one window */
    double win_size[3];
} facade;

static int32_t visible_ancestor(const ag_splittree *t, int32_t n)
{
    for (int32_t p = t->nodes[n].parent; p >= 0; p = t->nodes[p].parent)
        if (t->nodes[p].kind == AG_NODE_COMPONENT)
            return p;
    return 0;
}

static int setup(void **state)
{
    facade *f = calloc(1, sizeof *f);
    ag_gen_facade_options o = {.cols = 6, .rows = 1};
    ag_mesh *m = NULL;
    ag_error err = {0};
    assert_int_equal(ag_gen_facade(&o, &m, &err), AG_OK);
    ag_edit_model *first = NULL;
    assert_int_equal(ag_edit_model_create(m, NULL, &first, &err), AG_OK);
    assert_int_equal(ag_edit_model_from_grammar(first->proc->grammar, NULL, &f->model, &err),
                     AG_OK);
    ag_edit_model_free(first);
    ag_mesh_free(m);
    const ag_splittree *t = f->model->proc->tree;
    f->wall = f->window = -1;
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_PATTERN) {
            f->window = t->nodes[n].first_child;
            f->wall = visible_ancestor(t, (int32_t)n);
        }
    assert_true(f->wall > 0 && f->window > 0);
    for (int a = 0; a < 3; a++)
        f->win_size[a] = t->nodes[f->window].box.max[a] - t->nodes[f->window].box.min[a];
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    facade *f = *state;
    ag_edit_model_free(f->model);
    free(f);
    return 0;
}

/* Windows of a model: the visible nodes nested in another visible node. Checks that each
 * lies inside its wall and that no box is inverted; returns the count and the extreme
 * width ratios (x, the row's axis) against `ref`; heights must be kept. */
static size_t check_windows(const ag_edit_model *m, const double ref[3], double *rmin,
                            double *rmax, int32_t *label)
{
    const ag_splittree *t = m->proc->tree;
    double eps = 1e-6 * ag_box_diagonal(&t->nodes[0].box);
    size_t n = 0;
    *rmin = INFINITY;
    *rmax = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *x = &t->nodes[i];
        if (x->kind == AG_NODE_DEAD)
            continue;
        for (int a = 0; a < 3; a++)
            assert_true(x->box.max[a] >= x->box.min[a] - eps);
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        int32_t va = visible_ancestor(t, (int32_t)i);
        if (va <= 0)
            continue;
        n++;
        *label = x->label;
        const ag_box *w = &t->nodes[va].box;
        for (int a = 0; a < 3; a++) {
            assert_true(x->box.min[a] >= w->min[a] - eps);
            assert_true(x->box.max[a] <= w->max[a] + eps);
        }
        double r = (x->box.max[0] - x->box.min[0]) / ref[0];
        *rmin = fmin(*rmin, r);
        *rmax = fmax(*rmax, r);
        assert_true(fabs((x->box.max[2] - x->box.min[2]) / ref[2] - 1) < 1e-6);
    }
    return n;
}

static size_t label_count(const ag_edit_report *rep, int32_t label)
{
    char name[32];
    snprintf(name, sizeof name, "L%d", label + 1);
    for (size_t i = 0; i < rep->nlabels; i++)
        if (!strcmp(rep->labels[i].name, name))
            return rep->labels[i].count;
    return 0;
}

/* The exported grammar prints, parses back and derives one component per visible node. */
static void check_grammar(const ag_edit_model *m)
{
    ag_error err = {0};
    char *text = NULL;
    size_t len = 0;
    assert_int_equal(ag_grammar_text_print(m->proc->grammar, &text, &len, &err), AG_OK);
    ag_grammar *g = NULL;
    long col = 0;
    assert_int_equal(ag_grammar_text_parse(text, len, &g, &err, &col), AG_OK);
    ag_grammar_free(g);
    free(text);
    ag_mesh *d = NULL;
    assert_int_equal(ag_grammar_derive(m->proc->grammar, NULL, &d, &err), AG_OK);
    ag_splittree_stats st = ag_splittree_stats_of(m->proc->tree);
    assert_int_equal(d->ncomponents, st.visible);
    ag_mesh_free(d);
}

static ag_edit_model *apply_scale(facade *f, int32_t node, double sx, int mode,
                                  ag_edit_report *rep)
{
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = node, .has_scale = 1,
                     .scale = {sx, 1, 1}, .mode = mode};
    ag_edit_model *out = NULL;
    ag_error err = {0};
    ag_status st = ag_edit_apply(f->model, &op, &out, rep, &err);
    if (st)
        fail_msg("apply: %s", err.text);
    assert_true(rep->max_residual_rel <= 1e-6);
    return out;
}

static void test_stretch_doubles_windows(void **state)
{
    facade *f = *state;
    ag_edit_report rep = {0};
    ag_edit_model *m = apply_scale(f, f->wall, 2.0, AG_EDIT_GLOBAL, &rep);
    assert_true(rep.equations > 0 && rep.unknowns > 0 && rep.splits > 0);
    double rmin, rmax;
    int32_t label = -1;
    size_t n = check_windows(m, f->win_size, &rmin, &rmax, &label);
    /* about twelve windows of the original size, not six stretched ones */
    assert_true(n >= 11 && n <= 13);
    assert_true(rmin > 0.85 && rmax < 1.15);
    assert_int_equal(label_count(&rep, label), n);
    /* the building got twice as long */
    const ag_box *root = &m->proc->tree->nodes[0].box, *old = &f->model->proc->tree->nodes[0].box;
    assert_true((root->max[0] - root->min[0]) > 1.9 * (old->max[0] - old->min[0]));
    check_grammar(m);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
}

static void test_squeeze_joins_windows(void **state)
{
    facade *f = *state;
    ag_edit_report rep = {0};
    ag_edit_model *m = apply_scale(f, f->wall, 0.5, AG_EDIT_GLOBAL, &rep);
    assert_true(rep.joins > 0);
    double rmin, rmax;
    int32_t label = -1;
    size_t n = check_windows(m, f->win_size, &rmin, &rmax, &label);
    assert_true(n >= 2 && n < 6);
    /* joined cells are neither squeezed to half nor stretched past the split ratio */
    assert_true(rmin > 0.6 && rmax < 1.8);
    assert_int_equal(label_count(&rep, label), n);
    check_grammar(m);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
}

static void test_small_stretch_keeps_count(void **state)
{
    facade *f = *state;
    ag_edit_report rep = {0};
    ag_edit_model *m = apply_scale(f, f->wall, 1.3, AG_EDIT_GLOBAL, &rep);
    double rmin, rmax;
    int32_t label = -1;
    assert_int_equal(check_windows(m, f->win_size, &rmin, &rmax, &label), 6);
    assert_int_equal(rep.splits, 0);
    assert_true(rmax > 1.2 && rmax < 1.4);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
}

/* One window widened: local moves only it; global moves every window of its rule. */
static void test_window_local_and_global(void **state)
{
    facade *f = *state;
    const ag_box *w = &f->model->proc->tree->nodes[f->window].box;
    for (int mode = 0; mode < 2; mode++) {
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = f->window, .has_box = 1, .box = *w,
                         .mode = mode};
        op.box.max[0] += 0.4;
        ag_edit_model *m = NULL;
        ag_edit_report rep = {0};
        ag_error err = {0};
        assert_int_equal(ag_edit_apply(f->model, &op, &m, &rep, &err), AG_OK);
        assert_true(rep.max_residual_rel <= 1e-6);
        double rmin, rmax;
        int32_t label = -1;
        assert_int_equal(check_windows(m, f->win_size, &rmin, &rmax, &label), 6);
        double wider = (f->win_size[0] + 0.4) / f->win_size[0];
        assert_true(fabs(rmax - wider) < 1e-6);
        if (mode == AG_EDIT_GLOBAL)
            assert_true(fabs(rmin - 1) > 0.2); /* every window is wider */
        else
            assert_true(fabs(rmin - 1) < 1e-6); /* the others kept their size */
        ag_edit_report_clear(&rep);
        ag_edit_model_free(m);
    }
}

/* Hard attachments hold after the solve: the side walls keep touching the stretched
 * facade's ends and everything stays on the ground. */
static void test_attachments_hold(void **state)
{
    facade *f = *state;
    const ag_splittree *t = f->model->proc->tree;
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = f->wall, .has_scale = 1,
                     .scale = {1.37, 1, 1.2}};
    ag_box *b = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    assert_int_equal(ag_edit_preview(f->model, &op, &b, &rep, &err), AG_OK);
    assert_true(rep.max_residual_rel <= 1e-6);
    double diag = ag_box_diagonal(&t->nodes[0].box), eps = 1e-9 * diag;
    size_t touching = 0;
    for (size_t k = 0; k < t->nadj; k++) {
        uint32_t u = t->adj[2 * k], v = t->adj[2 * k + 1];
        for (int a = 0; a < 3; a++)
            for (int s = 0; s < 2; s++)
                for (int q = 0; q < 2; q++) {
                    double cu = s ? t->nodes[u].box.max[a] : t->nodes[u].box.min[a];
                    double cv = q ? t->nodes[v].box.max[a] : t->nodes[v].box.min[a];
                    if (fabs(cu - cv) > eps)
                        continue;
                    double nu = s ? b[u].max[a] : b[u].min[a], nv = q ? b[v].max[a] : b[v].min[a];
                    /* a window and its wall are not attached: the window is re-derived */
                    if (visible_ancestor(t, (int32_t)u) != visible_ancestor(t, (int32_t)v))
                        continue;
                    touching++;
                    assert_true(fabs(nu - nv) <= 1e-6 * diag);
                }
    }
    assert_true(touching > 4);
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && t->nodes[n].box.min[2] <= eps)
            assert_true(fabs(b[n].min[2]) <= 1e-6 * diag);
    assert_true(fabs(b[f->wall].max[0] - b[f->wall].min[0] -
                     1.37 * (t->nodes[f->wall].box.max[0] - t->nodes[f->wall].box.min[0])) <
                1e-9 * diag);
    free(b);
    ag_edit_report_clear(&rep);
}

/* A drag re-solves with the kept factorization and matches a fresh solve. */
static void test_drag_resolve_matches_fresh(void **state)
{
    facade *f = *state;
    const ag_splittree *t = f->model->proc->tree;
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = f->wall, .has_scale = 1,
                     .scale = {1.5, 1, 1}};
    ag_box *b1 = NULL, *b2 = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_preview(f->model, &op, &b1, NULL, &err), AG_OK);
    free(b1);
    op.scale[0] = 1.8;
    assert_int_equal(ag_edit_preview(f->model, &op, &b1, NULL, &err), AG_OK); /* kept */
    ag_edit_model *fresh = NULL;
    assert_int_equal(ag_edit_model_from_grammar(f->model->proc->grammar, NULL, &fresh, &err),
                     AG_OK);
    assert_int_equal(ag_edit_preview(fresh, &op, &b2, NULL, &err), AG_OK);
    for (size_t n = 0; n < t->nnodes; n++)
        for (int a = 0; a < 3; a++) {
            assert_true(fabs(b1[n].min[a] - b2[n].min[a]) < 1e-9);
            assert_true(fabs(b1[n].max[a] - b2[n].max[a]) < 1e-9);
        }
    free(b1);
    free(b2);
    ag_edit_model_free(fresh);
}

/* Editing the root scales the whole building; large stretches split recursively. */
static void test_root_scale(void **state)
{
    facade *f = *state;
    ag_edit_report rep = {0};
    ag_edit_model *m = apply_scale(f, AG_EDIT_ROOT, 4.0, AG_EDIT_GLOBAL, &rep);
    double rmin, rmax;
    int32_t label = -1;
    size_t n = check_windows(m, f->win_size, &rmin, &rmax, &label);
    assert_true(n >= 22 && n <= 26);
    assert_true(rmin > 0.85 && rmax < 1.15);
    check_grammar(m);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
}

/* Reading a model back through its grammar gives the same tree: ids are stable. */
static void test_ids_stable(void **state)
{
    facade *f = *state;
    ag_edit_model *again = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_model_from_grammar(f->model->proc->grammar, NULL, &again, &err),
                     AG_OK);
    const ag_splittree *a = f->model->proc->tree, *b = again->proc->tree;
    assert_int_equal(a->nnodes, b->nnodes);
    for (size_t n = 0; n < a->nnodes; n++) {
        assert_int_equal(a->nodes[n].kind, b->nodes[n].kind);
        assert_int_equal(a->nodes[n].parent, b->nodes[n].parent);
        for (int k = 0; k < 3; k++) {
            assert_true(fabs(a->nodes[n].box.min[k] - b->nodes[n].box.min[k]) < 1e-9);
            assert_true(fabs(a->nodes[n].box.max[k] - b->nodes[n].box.max[k]) < 1e-9);
        }
    }
    ag_edit_model_free(again);
}

static void test_bad_ops(void **state)
{
    facade *f = *state;
    ag_edit_model *m = NULL;
    ag_error err = {0};
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = 100000, .has_scale = 1, .scale = {1, 1, 1}};
    assert_int_equal(ag_edit_apply(f->model, &op, &m, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "node"));
    op.node = f->wall;
    op.has_scale = 0;
    assert_int_equal(ag_edit_apply(f->model, &op, &m, NULL, &err), AG_ERR_INVALID);
    op.has_box = 1;
    op.box = f->model->proc->tree->nodes[f->wall].box;
    op.box.max[1] = op.box.min[1] - 1;
    assert_int_equal(ag_edit_apply(f->model, &op, &m, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "box"));
    op.kind = 99;
    assert_int_equal(ag_edit_apply(f->model, &op, &m, NULL, &err), AG_ERR_INVALID);
    assert_null(m);
}

/* A box as one component of its own group. */
static void add_box(ag_mesh *m, const char *group, const double lo[3], const double hi[3])
{
    size_t g, c;
    assert_int_equal(ag_mesh_add_group(m, group, &g), AG_OK);
    assert_int_equal(ag_mesh_add_component(m, (int32_t)g, &c), AG_OK);
    uint32_t v0 = (uint32_t)m->nverts;
    for (int i = 0; i < 8; i++)
        assert_int_equal(ag_mesh_add_vertex(m, i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1],
                                            i & 4 ? hi[2] : lo[2]),
                         AG_OK);
    static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        assert_int_equal(ag_mesh_add_triangle(m, v0 + q[f][0], v0 + q[f][1], v0 + q[f][2],
                                              (uint32_t)c),
                         AG_OK);
        assert_int_equal(ag_mesh_add_triangle(m, v0 + q[f][0], v0 + q[f][2], v0 + q[f][3],
                                              (uint32_t)c),
                         AG_OK);
    }
}

/* An 8 m wall holding n identical 1.2 m windows 2 m apart, proceduralized with patterns of
 * n + 1 instances or more only: the windows are plain siblings of one rule. *wall gets the
 * wall's node, win_w the windows' width. */
static ag_edit_model *plain_siblings(unsigned n, int32_t *wall)
{
    ag_mesh *m = ag_mesh_create();
    assert_non_null(m);
    add_box(m, "wall", (double[]){0, 0, 0}, (double[]){8, 0.3, 3});
    for (unsigned i = 0; i < n; i++) {
        char name[24]; /* "window" and any unsigned */
        snprintf(name, sizeof name, "window%u", i);
        double x = 0.4 + 2.0 * i;
        add_box(m, name, (double[]){x, 0, 1}, (double[]){x + 1.2, 0.1, 2});
    }
    ag_proceduralize_options opt = {0};
    opt.patterns.min_instances = n + 1;
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_edit_model_create(m, &opt, &em, &err))
        fail_msg("%s", err.text);
    ag_mesh_free(m);
    const ag_splittree *t = em->proc->tree;
    *wall = -1;
    size_t windows = 0;
    int32_t rule = -2;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *x = &t->nodes[i];
        assert_true(x->kind != AG_NODE_PATTERN); /* no pattern groups them */
        if (x->kind != AG_NODE_COMPONENT)
            continue;
        if (visible_ancestor(t, (int32_t)i) > 0) {
            windows++;
            assert_true(x->rule >= 0 && (rule == -2 || rule == x->rule)); /* one rule */
            rule = x->rule;
        } else {
            *wall = (int32_t)i;
        }
    }
    assert_int_equal(windows, n);
    assert_true(*wall > 0);
    return em;
}

/* The windows of a model (visible nodes nested in another), their x sizes in *w. */
static size_t nested_widths(const ag_edit_model *m, double *w, size_t cap)
{
    const ag_splittree *t = m->proc->tree;
    size_t n = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT && visible_ancestor(t, (int32_t)i) > 0) {
            if (n < cap)
                w[n] = t->nodes[i].box.max[0] - t->nodes[i].box.min[0];
            n++;
        }
    return n;
}

static ag_edit_model *squeeze(ag_edit_model *em, int32_t node, double sx, ag_edit_report *rep)
{
    ag_edit_op op = {.kind = AG_EDIT_RESIZE, .node = node, .has_scale = 1, .scale = {sx, 1, 1}};
    ag_edit_model *out = NULL;
    ag_error err = {0};
    if (ag_edit_apply(em, &op, &out, rep, &err))
        fail_msg("apply: %s", err.text);
    return out;
}

/* Two same-rule siblings squeezed under the join ratio become one of their summed size; a
 * milder squeeze keeps both. */
static void test_squeezed_siblings_join(void **state)
{
    (void)state;
    int32_t wall;
    ag_edit_model *em = plain_siblings(2, &wall);
    double w[8];
    ag_edit_report rep = {0};
    ag_edit_model *m = squeeze(em, wall, 0.35, &rep);
    assert_int_equal(nested_widths(m, w, 8), 1);
    assert_int_equal(rep.joins, 1);
    assert_true(fabs(w[0] - 2 * 0.35 * 1.2) < 1e-6); /* 0.7 of a window, not 0.35 */
    const ag_box *nb = &m->proc->tree->nodes[0].box;
    assert_true(fabs(nb->max[0] - nb->min[0] - 0.35 * 8) < 1e-6);
    check_grammar(m);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);

    m = squeeze(em, wall, 0.7, &rep);
    assert_int_equal(nested_widths(m, w, 8), 2);
    assert_int_equal(rep.joins, 0);
    assert_true(fabs(w[0] - 0.7 * 1.2) < 1e-6 && fabs(w[1] - 0.7 * 1.2) < 1e-6);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
    ag_edit_model_free(em);
}

/* Joining is recursive: four windows squeezed to 0.35 pair up (each pair 0.7 of a window),
 * squeezed to 0.25 the pairs join again into one window of the original width. */
static void test_squeezed_siblings_join_recursively(void **state)
{
    (void)state;
    int32_t wall;
    ag_edit_model *em = plain_siblings(4, &wall);
    double w[8];
    ag_edit_report rep = {0};
    ag_edit_model *m = squeeze(em, wall, 0.35, &rep);
    assert_int_equal(nested_widths(m, w, 8), 2);
    assert_int_equal(rep.joins, 2);
    for (int i = 0; i < 2; i++)
        assert_true(fabs(w[i] - 0.7 * 1.2) < 1e-6);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);

    m = squeeze(em, wall, 0.25, &rep);
    assert_int_equal(nested_widths(m, w, 8), 1);
    assert_int_equal(rep.joins, 3);
    assert_true(fabs(w[0] - 1.2) < 1e-6);
    /* the joined window stays inside the squeezed wall */
    const ag_splittree *t = m->proc->tree;
    for (size_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].kind == AG_NODE_COMPONENT) {
            int32_t va = visible_ancestor(t, (int32_t)i);
            if (va > 0)
                for (int a = 0; a < 3; a++) {
                    assert_true(t->nodes[i].box.min[a] >= t->nodes[va].box.min[a] - 1e-9);
                    assert_true(t->nodes[i].box.max[a] <= t->nodes[va].box.max[a] + 1e-9);
                }
        }
    check_grammar(m);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(m);
    ag_edit_model_free(em);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stretch_doubles_windows),
        cmocka_unit_test(test_squeeze_joins_windows),
        cmocka_unit_test(test_small_stretch_keeps_count),
        cmocka_unit_test(test_window_local_and_global),
        cmocka_unit_test(test_attachments_hold),
        cmocka_unit_test(test_drag_resolve_matches_fresh),
        cmocka_unit_test(test_root_scale),
        cmocka_unit_test(test_ids_stable),
        cmocka_unit_test(test_bad_ops),
        cmocka_unit_test(test_squeezed_siblings_join),
        cmocka_unit_test(test_squeezed_siblings_join_recursively),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
