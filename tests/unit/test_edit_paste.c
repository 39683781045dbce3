/* Copy / paste (edit/paste.c) on generated buildings whose structure is known.
 *
 * The building's bays are sized so that the empty back wall (13 x 0.3 x 13.02 m) holds exactly
 * 10 x 7 windows (1.3 x 0.2 x 1.86 m with the sill): filled copies keep their size exactly and
 * proceduralize into the same label as the original windows. */
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
#include "edit_fixture.h"

/* W = 13, D = 4.84, H = 13.02; front: 6 x 4 windows, right: 2 x 4, back and left empty. */
#define W 13.0
#define D 4.84
#define H 13.02
static ag_mesh *facade_mesh(unsigned bars)
{
    ag_gen_facade_options o = {.cols = 6, .rows = 4, .side_cols = 2, .step_x = 2.04,
                               .step_z = 3.03, .bars = bars};
    ag_mesh *m = NULL;
    assert_int_equal(ag_gen_facade(&o, &m, NULL), AG_OK);
    return m;
}

static ag_proceduralize_result *facade(size_t *tris)
{
    ag_mesh *m = facade_mesh(0);
    ag_proceduralize_result *r = proc(m);
    if (tris)
        *tris = m->ntris;
    ag_mesh_free(m);
    return r;
}

/* Front window (i, j) centre-ish point; right-facade window (i, j). */
static int32_t front_window(const ag_proceduralize_result *r, int i, int j)
{
    return node_at(r, 1.4 + 2.04 * i, 0.15, 1.8 + 3.03 * j);
}
static int32_t right_window(const ag_proceduralize_result *r, int i, int j)
{
    return node_at(r, W - 0.15, 1.4 + 2.04 * i, 1.8 + 3.03 * j);
}
static int32_t back_wall(const ag_proceduralize_result *r) { return node_at(r, 6.5, D - 0.27, 0.3); }
static int32_t left_wall(const ag_proceduralize_result *r) { return node_at(r, 0.27, 2.4, 0.3); }
static int32_t front_wall(const ag_proceduralize_result *r) { return node_at(r, 6.5, 0.27, 0.3); }

static ag_mesh *paste(const ag_proceduralize_result *r, const ag_proceduralize_result *src,
                      int32_t from, int32_t to, int placement, int fit, ag_edit_report *rep)
{
    ag_edit_op op = {.kind = AG_EDIT_PASTE, .node = to, .nnodes = 1, .nodes = &from,
                     .placement = placement, .fit = fit, .source = src};
    ag_mesh *out = NULL;
    ag_error err = {0};
    if (ag_edit_paste(r, &op, &out, rep, &err))
        fail_msg("paste: %s", err.text);
    return out;
}

static int inside(const ag_box *in, const ag_box *out, double tol)
{
    for (int a = 0; a < 3; a++)
        if (in->min[a] < out->min[a] - tol || in->max[a] > out->max[a] + tol)
            return 0;
    return 1;
}

/* Checks the windows pasted into the back wall: n of them, all of the front windows' label,
 * the original size, turned by a half turn from the front windows (the back faces +y), in the
 * wall's outer face and below the wall in the tree. */
static void check_back_fill(const ag_proceduralize_result *s, size_t n)
{
    const ag_splittree *t = s->tree;
    int32_t f = front_window(s, 0, 0), bw = back_wall(s);
    int32_t label = t->nodes[f].label;
    assert_int_equal(label_instances(t, label), 24 + 8 + n);
    const ag_box *wb = &t->nodes[bw].box;
    size_t back = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *x = &t->nodes[i];
        if (x->kind != AG_NODE_COMPONENT || x->label != label || x->box.min[1] < D - 1)
            continue;
        back++;
        assert_true(fabs(x->box.max[0] - x->box.min[0] - 1.3) < 1e-9);
        assert_true(fabs(x->box.max[1] - x->box.min[1] - 0.2) < 1e-9);
        assert_true(fabs(x->box.max[2] - x->box.min[2] - 1.86) < 1e-9);
        assert_true(fabs(x->box.max[1] - D) < 1e-9);
        assert_true(inside(&x->box, wb, 1e-9));
        assert_int_equal((x->rot - t->nodes[f].rot) & 3, 2);
        assert_true(below(t, (int32_t)i, bw));
    }
    assert_int_equal(back, n);
}

static void test_fill_empty_wall_with_a_window(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = facade(&tris);
    int32_t win = front_window(r, 0, 0), wall = back_wall(r);
    size_t wt = r->labels->ntris[r->tree->nodes[win].component];
    ag_edit_report rep = {0};
    ag_mesh *out = paste(r, NULL, win, wall, AG_EDIT_INSERT, AG_EDIT_FILL, &rep);
    /* counts = round(13 / 1.3) x round(13.02 / 1.86) = 10 x 7; the wall is kept */
    assert_non_null(strstr(rep.message, "10 x 1 x 7"));
    assert_int_equal(out->ntris, tris + 70 * wt);
    ag_proceduralize_result *s = proc(out);
    check_back_fill(s, 70);
    /* the 70 copies are one pattern of 10 x 7 */
    int found = 0;
    for (size_t p = 0; p < s->tree->npatterns; p++) {
        const ag_pattern *pt = &s->tree->patterns[p];
        found |= pt->counts[0] * pt->counts[1] * pt->counts[2] == 70;
    }
    assert_true(found);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_turned_source_is_turned_to_the_destination(void **state)
{
    (void)state;
    ag_proceduralize_result *r = facade(NULL);
    /* a right-facade window faces +x (long along y); the back wall faces +y */
    int32_t win = right_window(r, 1, 2);
    const ag_box *sb = &r->tree->nodes[win].box;
    assert_true(sb->max[1] - sb->min[1] > sb->max[0] - sb->min[0]);
    ag_mesh *out = paste(r, NULL, win, back_wall(r), AG_EDIT_INSERT, AG_EDIT_FILL, NULL);
    ag_proceduralize_result *s = proc(out);
    check_back_fill(s, 70);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);

    /* the left wall faces -x and is 4.84 m long: round(4.84 / 1.3) = 4 windows per row,
     * squeezed a little (1.21 m) and turned a quarter from the front's */
    int32_t lw = left_wall(r);
    ag_edit_report rep = {0};
    out = paste(r, NULL, front_window(r, 2, 1), lw, AG_EDIT_INSERT, AG_EDIT_FILL, &rep);
    assert_non_null(strstr(rep.message, "1 x 4 x 7"));
    s = proc(out);
    const ag_splittree *t = s->tree;
    lw = left_wall(s);
    const ag_box *wb = &t->nodes[lw].box;
    size_t n = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_tnode *x = &t->nodes[i];
        if (x->kind != AG_NODE_COMPONENT || (int32_t)i == lw || !below(t, (int32_t)i, lw))
            continue;
        n++;
        assert_true(inside(&x->box, wb, 1e-9));
        assert_true(fabs(x->box.min[0]) < 1e-9); /* flush with the outer face x = 0 */
        assert_true(fabs(x->box.max[0] - 0.2) < 1e-9);
        assert_true(fabs(x->box.max[1] - x->box.min[1] - D / 4) < 1e-9);
        assert_true(fabs(x->box.max[2] - x->box.min[2] - 1.86) < 1e-9);
    }
    assert_int_equal(n, 28);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_derive_scales_the_source_into_the_box(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = facade(&tris);
    int32_t win = front_window(r, 0, 0), wall = back_wall(r);
    size_t wt = r->labels->ntris[r->tree->nodes[win].component];
    ag_mesh *out = paste(r, NULL, win, wall, AG_EDIT_INSERT, AG_EDIT_DERIVE, NULL);
    assert_int_equal(out->ntris, tris + wt);
    /* one window, stretched relatively over the whole wall */
    ag_proceduralize_result *s = proc(out);
    const ag_box wb = r->tree->nodes[wall].box;
    size_t matches = 0;
    for (size_t i = 0; i < s->tree->nnodes; i++) {
        const ag_tnode *x = &s->tree->nodes[i];
        if (x->kind != AG_NODE_COMPONENT || s->labels->ntris[x->component] != wt)
            continue;
        int same = 1;
        for (int a = 0; a < 3; a++)
            same &= fabs(x->box.min[a] - wb.min[a]) < 1e-9 && fabs(x->box.max[a] - wb.max[a]) < 1e-9;
        matches += same;
    }
    assert_int_equal(matches, 1);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_replace_across_models(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = facade(&tris);
    ag_mesh *bm = facade_mesh(2); /* windows with two glazing bars: another style */
    ag_proceduralize_result *b = proc(bm);
    ag_mesh_free(bm);
    int32_t dst = front_window(r, 3, 2), from = front_window(b, 0, 0);
    size_t old_t = r->labels->ntris[r->tree->nodes[dst].component];
    size_t new_t = b->labels->ntris[b->tree->nodes[from].component];
    assert_true(new_t > old_t);
    const ag_box db = r->tree->nodes[dst].box;
    int32_t label = r->tree->nodes[dst].label;
    size_t windows = label_instances(r->tree, label);
    ag_edit_report rep = {0};
    ag_mesh *out = paste(r, b, from, dst, AG_EDIT_REPLACE, AG_EDIT_DERIVE, &rep);
    assert_int_equal(out->ntris, tris - old_t + new_t);
    /* pasted components are grouped apart from this model's labels */
    int src_group = 0;
    for (size_t g = 0; g < out->ngroups; g++)
        src_group |= !strncmp(out->group_names[g], "src_", 4);
    assert_true(src_group);
    ag_proceduralize_result *s = proc(out);
    int32_t x = front_window(s, 3, 2);
    const ag_box *xb = &s->tree->nodes[x].box;
    for (int a = 0; a < 3; a++)
        assert_true(fabs(xb->min[a] - db.min[a]) < 1e-9 && fabs(xb->max[a] - db.max[a]) < 1e-9);
    assert_int_equal(s->labels->ntris[s->tree->nodes[x].component], new_t);
    assert_int_equal(label_instances(s->tree, s->tree->nodes[front_window(s, 0, 0)].label),
                     windows - 1);
    assert_int_equal(label_instances(s->tree, s->tree->nodes[x].label), 1);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(b);
    ag_proceduralize_result_free(r);
}

static void test_replace_fill_removes_what_was_there(void **state)
{
    (void)state;
    size_t tris = 0;
    ag_proceduralize_result *r = facade(&tris);
    int32_t win = right_window(r, 0, 0), wall = front_wall(r);
    size_t wt = r->labels->ntris[r->tree->nodes[win].component];
    /* the front wall (12 triangles) and its 24 windows go; 10 x 7 windows take their place */
    ag_mesh *out = paste(r, NULL, win, wall, AG_EDIT_REPLACE, AG_EDIT_FILL, NULL);
    assert_int_equal(out->ntris, tris - 12 - 24 * wt + 70 * wt);
    ag_proceduralize_result *s = proc(out);
    size_t front = 0;
    int32_t label = s->tree->nodes[right_window(s, 0, 0)].label;
    for (size_t i = 0; i < s->tree->nnodes; i++) {
        const ag_tnode *x = &s->tree->nodes[i];
        if (x->kind != AG_NODE_COMPONENT || x->box.max[1] > 0.3 + 1e-9)
            continue;
        /* only windows are left in the front's slab, flush with its outer face y = 0 */
        assert_int_equal(x->label, label);
        assert_true(fabs(x->box.min[1]) < 1e-9);
        front++;
    }
    assert_int_equal(front, 70);
    ag_proceduralize_result_free(s);
    ag_mesh_free(out);
    ag_proceduralize_result_free(r);
}

static void test_paste_bad_requests(void **state)
{
    (void)state;
    ag_proceduralize_result *r = facade(NULL);
    int32_t win = front_window(r, 0, 0), wall = back_wall(r);
    ag_mesh *out = NULL;
    ag_error err = {0};
    ag_edit_op op = {.kind = AG_EDIT_PASTE, .node = wall};
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "empty"));
    int32_t sel[2] = {win, -1};
    op.nodes = sel;
    op.nnodes = 2;
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "nodes[1]"));
    op.source = r; /* an explicit source model names itself in messages only when it differs */
    op.nnodes = 1;
    op.node = 1 << 20;
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "destination"));
    op.node = wall;
    op.placement = 7;
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "placement"));
    op.placement = AG_EDIT_INSERT;
    op.fit = -1;
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "fit"));
    /* a source node that exists only in the other model */
    ag_gen_facade_options o = {.cols = 1, .rows = 1};
    ag_mesh *sm = NULL;
    assert_int_equal(ag_gen_facade(&o, &sm, NULL), AG_OK);
    ag_proceduralize_result *small = proc(sm);
    ag_mesh_free(sm);
    op.fit = AG_EDIT_FILL;
    op.source = small;
    sel[0] = (int32_t)small->tree->nnodes + 5;
    assert_int_equal(ag_edit_paste(r, &op, &out, NULL, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "source model"));
    assert_null(out);
    ag_proceduralize_result_free(small);
    ag_proceduralize_result_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fill_empty_wall_with_a_window),
        cmocka_unit_test(test_turned_source_is_turned_to_the_destination),
        cmocka_unit_test(test_derive_scales_the_source_into_the_box),
        cmocka_unit_test(test_replace_across_models),
        cmocka_unit_test(test_replace_fill_removes_what_was_there),
        cmocka_unit_test(test_paste_bad_requests),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
