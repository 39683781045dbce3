/* Node ids survive edits: on generated box buildings (edit_building_fixture.h; windows recessed,
 * flush and proud, turned, at UTM coordinates, jittered, handed: mirror images alternating) a
 * window picked by its place before the front wall is stretched 2x is named by the same id
 * after it (same label, same size, still the first window of its row); no visible node of the
 * input loses its id or changes its kind or label; an op naming the window by that id (made
 * before the stretch) applies to it, its rule and its mirror images (handed: the mirror images
 * are a rule of their own, which a global resize reaches too); and the edited model reloads
 * from what the store keeps (mesh and stored tree) node for node. Windows are measured on the
 * output mesh. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/model_kept.h"
#include "app/model_state.h"
#include "app/model_tree.h"
#include "edit_building_fixture.h"
#include "edit_kept_fixture.h"
#include "core/edit/edit.h"
#include "core/proc/proceduralize.h"
#include "io/meshblob.h"

/* The visible node whose box holds the building-frame point most tightly, -1 for none. */
static int32_t node_at(const ag_edit_model *em, const bb_options *o, double x, double y, double z)
{
    const ag_splittree *t = em->proc->tree;
    double w[3];
    bb_to_world(o, x, y, z, w);
    int32_t best = -1;
    double bv = INFINITY;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *nd = &t->nodes[n];
        if (nd->kind != AG_NODE_COMPONENT)
            continue;
        int in = 1;
        for (int a = 0; a < 3 && in; a++)
            in = w[a] >= nd->box.min[a] - 1e-6 && w[a] <= nd->box.max[a] + 1e-6;
        double v = ag_box_volume(&nd->box);
        if (in && v < bv) {
            bv = v;
            best = (int32_t)n;
        }
    }
    return best;
}

/* The label name of a visible node: its component's group in the model's mesh. */
static const char *label_of(const ag_edit_model *em, int32_t n)
{
    const ag_tnode *x = &em->proc->tree->nodes[n];
    const ag_mesh *m = em->proc->mesh;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 ||
        (size_t)x->component >= m->ncomponents || m->component_group[x->component] < 0)
        return "";
    return m->group_names[m->component_group[x->component]];
}

/* The visible nodes of node n's rule. */
static size_t rule_members(const ag_edit_model *em, int32_t n)
{
    const ag_splittree *t = em->proc->tree;
    size_t k = 0;
    for (size_t i = 0; i < t->nnodes; i++)
        k += t->nodes[i].kind == AG_NODE_COMPONENT && t->nodes[i].rule == t->nodes[n].rule;
    return k;
}

static int front_axis(const bb_options *o)
{
    return o->turn & 1 ? 1 : 0;
}

static ag_edit_model *resize(ag_edit_model *em, ag_edit_op *op, const char *what,
                             const bb_options *o)
{
    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    if (ag_edit_apply_ex(em, op, 0, &out, &rep, &err))
        fail_msg("%s %s: %s", o->name, what, err.text);
    ag_edit_report_clear(&rep);
    return out;
}

/* Heights (building frame) of every component in group `name` of m: all equal to want? */
static size_t count_with_height(const ag_mesh *m, const bb_options *o, const char *name,
                                double want, size_t *total)
{
    size_t n, ok = 0;
    bb_part *p = bb_parts(m, o, &n);
    *total = 0;
    for (size_t i = 0; i < n; i++) {
        if (p[i].group < 0 || strcmp(m->group_names[p[i].group], name))
            continue;
        (*total)++;
        ok += fabs(bb_extent(&p[i], 2) - want) <= 1e-6 * fmax(1, want);
    }
    free(p);
    return ok;
}


static void run_variant(const bb_options *o)
{
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_edit_model *em = bb_service_model(o, &m, &err);
    if (!em)
        fail_msg("%s: proceduralize: %s", o->name, err.text);

    /* the window a person selects: the first of the bottom front row; and the front wall */
    double fr[2], gl[2], si[2];
    bb_depths(o->mount, fr, gl, si);
    int32_t win = node_at(em, o, BB_MARGIN + 0.6, 0.5 * (fr[0] + fr[1]), BB_ROW0 + 0.7);
    int32_t wall = node_at(em, o, 0.3, 0.5 * BB_WALL, 1.0);
    assert_true(win > 0 && wall > 0 && win != wall);
    char label[64], wall_label[64];
    snprintf(label, sizeof label, "%s", label_of(em, win));
    snprintf(wall_label, sizeof wall_label, "%s", label_of(em, wall));
    ag_box wb = em->proc->tree->nodes[win].box;

    ag_edit_op stretch = {.kind = AG_EDIT_RESIZE, .node = wall, .has_scale = 1,
                          .scale = {1, 1, 1}, .mode = AG_EDIT_GLOBAL};
    stretch.scale[front_axis(o)] = 2;
    ag_edit_model *wide = resize(em, &stretch, "front wall x2", o);

    /* no visible node of the input lost its id, kind or label */
    const ag_splittree *t0 = em->proc->tree, *t1 = wide->proc->tree;
    assert_true(t1->nnodes >= t0->nnodes);
    for (size_t n = 0; n < t0->nnodes; n++) {
        if (t0->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        if (t1->nodes[n].kind != AG_NODE_COMPONENT)
            fail_msg("%s: visible node %zu is %d after the stretch", o->name, n,
                     t1->nodes[n].kind);
        if (strcmp(label_of(em, (int32_t)n), label_of(wide, (int32_t)n)))
            fail_msg("%s: node %zu was %s, is %s", o->name, n, label_of(em, (int32_t)n),
                     label_of(wide, (int32_t)n));
    }
    /* the selected window: same label and size, still the window at the row's first place */
    assert_string_equal(label_of(wide, win), label);
    assert_string_equal(label_of(wide, wall), wall_label);
    const ag_box *nb = &t1->nodes[win].box;
    for (int a = 0; a < 3; a++)
        if (fabs((nb->max[a] - nb->min[a]) - (wb.max[a] - wb.min[a])) > 1e-6)
            fail_msg("%s: the window changed its size along %d: %.9f to %.9f", o->name, a, wb.max[a] - wb.min[a], nb->max[a] - nb->min[a]);
    if (node_at(wide, o, BB_MARGIN + 0.6, 0.5 * (fr[0] + fr[1]), BB_ROW0 + 0.7) != win)
        fail_msg("%s: another node is the first window of the row now", o->name);

    /* an op naming the window by its id from before the stretch: every window of its rule and
     * every mirror image of it 0.3 m taller (measured on the mesh) */
    ag_edit_op taller = {.kind = AG_EDIT_RESIZE, .node = win, .has_box = 1, .box = *nb,
                         .mode = AG_EDIT_GLOBAL};
    taller.box.max[2] += 0.3;
    ag_edit_model *tall = resize(wide, &taller, "window taller", o);
    size_t total = 0;
    size_t ok = count_with_height(tall->proc->mesh, o, label, BB_WIN_H + 0.08 + 0.3, &total);
    if (total < 2 * o->cols * o->rows - o->rows)
        fail_msg("%s: %zu windows after the stretch", o->name, total);
    /* handed windows: the mirror images are a rule of their own, and the op is theirs too */
    size_t own = rule_members(tall, win);
    if (ok != total || (o->handed && (own < total / 3 || own > total - total / 3)))
        fail_msg("%s: %zu of %zu windows are 0.3 m taller (%zu of the op's rule), want all",
                 o->name, ok, total, own);
    assert_string_equal(label_of(tall, win), label);

    /* the served tree printed directly is the one jansson prints, character for character */
    {
        char *text = ag_model_tree_served_text(tall);
        json_t *want = ag_model_tree_served(tall);
        char *wt = json_dumps(want, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(15));
        assert_non_null(text);
        assert_string_equal(text, wt);
        free(wt);
        json_decref(want);
        free(text);
    }

    /* the store keeps the edited model: reloaded node for node */
    ag_model_state st;
    ag_edit_model *made = tall;
    if (ag_model_state_make(&made, 0, &st, &err))
        fail_msg("%s: state: %s", o->name, err.text);
    char *served = ag_model_tree_served_text(st.em);
    char *again = ek_served_after_store(st.em);
    if (strcmp(served, again))
        fail_msg("%s: the reloaded tree differs from the edited one", o->name);
    free(served);
    free(again);
    ag_model_state_clear(&st);
    ag_edit_model_free(wide);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

static void ids_survive_a_facade_stretch(void **state)
{
    (void)state;
    size_t nv;
    const bb_options *variants = bb_id_variants(&nv);
    for (size_t i = 0; i < nv; i++)
        run_variant(&variants[i]);
    variants = bb_handed_variants(&nv);
    for (size_t i = 0; i < nv; i++)
        run_variant(&variants[i]);
}

/* A kept model that does not fit the mesh is refused with what is wrong, never trusted. */
static void a_broken_kept_model_is_refused(void **state)
{
    (void)state;
    size_t nv;
    const bb_options *o = &bb_id_variants(&nv)[2];
    ag_mesh *m = bb_generate(o);
    ag_edit_model *em = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_model_create(m, NULL, &em, &err), AG_OK);
    char *text = ag_model_kept_tree_text(em);
    assert_non_null(text);
    static const struct {
        const char *from, *to;
    } breaks[] = {
        {"\"format\":4", "\"format\":7"},
        {"\"ncomponents\":", "\"ncomponents\":1"},
        {"\"nnodes\":", "\"nnodes\":9"},
        {"\"data\":\"", "\"data\":\"AAAA"},
        {"\"data\":\"", "\"data\":\"*"},
        {"\"data\":\"AAAA", "\"data\":\"AQAA"}, /* the root's kind: a split */
    };
    for (size_t i = 0; i < sizeof breaks / sizeof *breaks; i++) {
        const char *at = strstr(text, breaks[i].from);
        assert_non_null(at);
        size_t n = strlen(text), fl = strlen(breaks[i].from), tl = strlen(breaks[i].to);
        char *bad = malloc(n + tl + 1);
        memcpy(bad, text, (size_t)(at - text));
        memcpy(bad + (at - text), breaks[i].to, tl);
        strcpy(bad + (at - text) + tl, at + fl);
        ag_edit_model *re = NULL;
        ag_status s = ag_model_state_reload_kept(em->proc->mesh, bad, &re, &err);
        if (s != AG_ERR_PARSE)
            fail_msg("break %zu: %d (%s)", i, s, err.text);
        assert_null(re);
        assert_non_null(strstr(err.text, "kept model"));
        free(bad);
    }
    /* a tree that keeps nothing proceduralizes the mesh */
    ag_edit_model *re = NULL;
    assert_int_equal(ag_model_state_reload_kept(em->proc->mesh, "{\"root\":0,\"nodes\":[]}", &re,
                                                &err),
                     AG_OK);
    ag_edit_model_free(re);
    free(text);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ids_survive_a_facade_stretch),
        cmocka_unit_test(a_broken_kept_model_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
