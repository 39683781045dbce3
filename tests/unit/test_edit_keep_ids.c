/* Split, join, paste and remove keep node ids: on generated box buildings
 * (edit_building_fixture.h: windows recessed, flush and proud, a turned building with a roof
 * overhang, UTM coordinates, jitter) each op is applied through ag_edit_apply_ex and checked
 * against what the test knows independently:
 *  (a) every visible node of the input the op did not touch has the same id, kind, label and
 *      box; what it touched is where the op puts it (a split's node on the lower half, its
 *      copies appended with the upper half's boxes; removed and joined-away nodes dead; the
 *      joined node with the union box; pasted copies appended, one set per cell);
 *  (b) the new model's mesh is the operation's own mesh (ag_edit_split etc., what the mesh path
 *      proceduralizes): the same number of triangles, the same welded vertex set and the same
 *      areas per group (as a multiset: a join's label is numbered differently), and the mesh its
 *      grammar derives has the same vertex set and area;
 *  (c) the grammar prints, re-parses and prints again byte for byte;
 *  (d) the input model is untouched (undo gives it back as it was) and the edited model reloads
 *      from what the store keeps node for node.
 * The same for a paste that turns its source (a front window onto the side facade) and one from
 * another building. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/model_kept.h"
#include "app/model_state.h"
#include "app/model_tree.h"
#include "core/edit/edit.h"
#include "core/edit/idmatch.h"
#include "core/proc/proceduralize.h"
#include "edit_building_fixture.h"
#include "edit_kept_fixture.h"
#include "io/grammar_text.h"
#include "io/meshblob.h"
#include "mesh_measure_fixture.h"

/* ---- what the test measures itself -------------------------------------------------------- */

static const char *label_of(const ag_edit_model *em, int32_t n)
{
    const ag_tnode *x = &em->proc->tree->nodes[n];
    const ag_mesh *m = em->proc->mesh;
    if (x->kind != AG_NODE_COMPONENT || x->component < 0 ||
        (size_t)x->component >= m->ncomponents || m->component_group[x->component] < 0)
        return "";
    return m->group_names[m->component_group[x->component]];
}

static int same_box(const ag_box *a, const ag_box *b, double tol)
{
    for (int k = 0; k < 3; k++)
        if (fabs(a->min[k] - b->min[k]) > tol || fabs(a->max[k] - b->max[k]) > tol)
            return 0;
    return 1;
}

/* Is n in the subtree of r (parent links of t)? */
static int in_subtree(const ag_splittree *t, int32_t n, int32_t r)
{
    for (int32_t x = n; x >= 0; x = t->nodes[x].parent)
        if (x == r)
            return 1;
    return 0;
}

/* The same vertex set (both ways) at tolerance tol, and the same total area. */
static void assert_same_surface(const ag_mesh *a, const ag_mesh *b, double tol, const char *what)
{
    double origin[3] = {a->pos[0], a->pos[1], a->pos[2]};
    size_t na, nb;
    mm_cell *ca = mm_welded(a, origin, tol, &na), *cb = mm_welded(b, origin, tol, &nb);
    size_t ab = mm_unmatched(ca, na, cb, nb), ba = mm_unmatched(cb, nb, ca, na);
    free(ca);
    free(cb);
    if (ab || ba)
        fail_msg("%s: %zu of %zu vertices have no counterpart, %zu of %zu the other way", what, ab,
                 na, ba, nb);
    double sa = mm_total_area(a), sb = mm_total_area(b);
    if (fabs(sa - sb) > 1e-6 * fmax(1, sa))
        fail_msg("%s: area %.9g vs %.9g", what, sa, sb);
}

static char *grammar_text(const ag_grammar *g)
{
    char *text = NULL;
    size_t len = 0;
    ag_error err = {0};
    if (ag_grammar_text_print(g, &text, &len, &err))
        fail_msg("print: %s", err.text);
    return text;
}

/* ---- the ops ------------------------------------------------------------------------------ */

typedef struct {
    const char *what;
    ag_edit_op op;
    uint8_t *touched;  /* per old node: the op moves or removes it */
    int removes;       /* touched nodes are dead afterwards (1), stay (0) or either (2) */
    size_t appended;   /* visible nodes the op appends */
} case_t;

/* Visible nodes of t in r's subtree. */
static size_t visible_below(const ag_splittree *t, int32_t r, uint8_t *mark)
{
    size_t n = 0;
    for (size_t v = 0; v < t->nnodes; v++)
        if (t->nodes[v].kind != AG_NODE_DEAD && in_subtree(t, (int32_t)v, r)) {
            if (mark)
                mark[v] = 1;
            n += t->nodes[v].kind == AG_NODE_COMPONENT;
        }
    return n;
}

/* Runs one case on em and checks (a) to (d). */
static void check_case(ag_edit_model *em, case_t *c, const bb_options *o)
{
    const ag_splittree *t0 = em->proc->tree;
    double diag = ag_box_diagonal(&t0->nodes[0].box);
    double btol = 1e-9 * fmax(1, fabs(t0->nodes[0].box.max[0]) + fabs(t0->nodes[0].box.max[1]));
    char *served_before = ag_model_tree_served_text(em);
    char what[160];
    snprintf(what, sizeof what, "%s: %s", o->name, c->what);

    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    if (ag_edit_apply_ex(em, &c->op, 0, &out, &rep, &err))
        fail_msg("%s: %s", what, err.text);
    const ag_splittree *t1 = out->proc->tree;
    assert_true(t1->nnodes >= t0->nnodes);

    /* (a) ids */
    for (size_t n = 0; n < t0->nnodes; n++) {
        const ag_tnode *a = &t0->nodes[n], *b = &t1->nodes[n];
        if (a->kind != AG_NODE_COMPONENT)
            continue;
        if (c->touched[n] && c->removes == 2)
            continue; /* checked by the case */
        if (c->touched[n] && c->removes) {
            if (b->kind != AG_NODE_DEAD)
                fail_msg("%s: node %zu should be removed", what, n);
            continue;
        }
        if (b->kind != AG_NODE_COMPONENT)
            fail_msg("%s: visible node %zu lost its id (kind %d now)", what, n, b->kind);
        if (c->touched[n])
            continue; /* checked by the case */
        if (strcmp(label_of(em, (int32_t)n), label_of(out, (int32_t)n)))
            fail_msg("%s: node %zu changed label %s -> %s", what, n, label_of(em, (int32_t)n),
                     label_of(out, (int32_t)n));
        if (!same_box(&a->box, &b->box, btol))
            fail_msg("%s: node %zu moved", what, n);
    }
    size_t appended = 0;
    for (size_t n = t0->nnodes; n < t1->nnodes; n++)
        appended += t1->nodes[n].kind == AG_NODE_COMPONENT;
    if (appended != c->appended)
        fail_msg("%s: %zu visible nodes appended, expected %zu", what, appended, c->appended);

    /* (b) the operation's own mesh */
    ag_mesh *oracle = NULL;
    ag_status s = AG_OK;
    switch (c->op.kind) {
    case AG_EDIT_SPLIT:
        s = ag_edit_split(em->proc, &c->op, &oracle, NULL, &err);
        break;
    case AG_EDIT_JOIN:
        s = ag_edit_join(em->proc, &c->op, &oracle, NULL, &err);
        break;
    case AG_EDIT_PASTE:
        s = ag_edit_paste(em->proc, &c->op, &oracle, NULL, &err);
        break;
    case AG_EDIT_REMOVE:
        s = ag_edit_remove(em->proc, &c->op, &oracle, NULL, &err);
        break;
    }
    if (s)
        fail_msg("%s: the mesh path: %s", what, err.text);
    const ag_mesh *mine = out->proc->mesh;
    if (mine->ntris != oracle->ntris)
        fail_msg("%s: %zu triangles, the mesh path %zu", what, mine->ntris, oracle->ntris);
    char part[200];
    snprintf(part, sizeof part, "%s (the new mesh)", what);
    assert_same_surface(mine, oracle, 1e-6 * fmax(1, diag), part);
    size_t ga, gb;
    double *aa = mm_group_areas(mine, &ga), *ab = mm_group_areas(oracle, &gb);
    if (ga != gb)
        fail_msg("%s: %zu groups with triangles, the mesh path %zu", what, ga, gb);
    for (size_t i = 0; i < ga; i++)
        if (fabs(aa[i] - ab[i]) > 1e-6 * fmax(1, ab[i]))
            fail_msg("%s: group areas differ (%.9g vs %.9g)", what, aa[i], ab[i]);
    free(aa);
    free(ab);
    ag_mesh *derived = NULL;
    if (ag_grammar_derive(out->proc->grammar, NULL, &derived, &err))
        fail_msg("%s: derive: %s", what, err.text);
    snprintf(part, sizeof part, "%s (the derived mesh)", what);
    assert_same_surface(derived, oracle, 1e-4 * fmax(1, diag), part);
    ag_mesh_free(derived);
    ag_mesh_free(oracle);

    /* (c) the grammar prints, re-parses and prints the same */
    char *text = grammar_text(out->proc->grammar);
    ag_grammar *g2 = NULL;
    if (ag_grammar_text_parse(text, strlen(text), &g2, &err, NULL))
        fail_msg("%s: re-parse: line %ld: %s", what, err.element, err.text);
    char *text2 = grammar_text(g2);
    if (strcmp(text, text2))
        fail_msg("%s: the grammar does not print the same after a re-parse", what);
    free(text);
    free(text2);
    ag_grammar_free(g2);

    /* (d) the input is as it was (undo), the edited model reloads node for node */
    char *served_now = ag_model_tree_served_text(em);
    if (strcmp(served_before, served_now))
        fail_msg("%s: the edit changed the input model", what);
    char *out_served = ag_model_tree_served_text(out), *out_stored = ek_served_after_store(out);
    if (strcmp(out_served, out_stored))
        fail_msg("%s: the edited model does not reload node for node", what);
    char *back = ek_served_after_store(em);
    if (strcmp(back, served_before))
        fail_msg("%s: the previous state does not reload as it was", what);
    free(back);
    free(out_served);
    free(out_stored);
    free(served_now);
    free(served_before);
    ag_edit_report_clear(&rep);
    ag_edit_model_free(out);
}

/* Checks a split's moved nodes: the node's subtree squeezed onto the lower half, the appended
 * copies' boxes those of the upper half (as a multiset of boxes). */
static void check_split_boxes(ag_edit_model *em, const ag_edit_op *op, const bb_options *o)
{
    ag_edit_model *out = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_apply_ex(em, op, 0, &out, NULL, &err), AG_OK);
    const ag_splittree *t0 = em->proc->tree, *t1 = out->proc->tree;
    const ag_box B = t0->nodes[op->node].box;
    int a = op->axis;
    double f = (op->at - B.min[a]) / (B.max[a] - B.min[a]);
    double tol = 1e-9 * fmax(1, fabs(B.max[0]) + fabs(B.max[1]) + fabs(B.max[2]));
    size_t found = 0, want = 0;
    for (size_t n = 0; n < t0->nnodes; n++) {
        if (t0->nodes[n].kind != AG_NODE_COMPONENT || !in_subtree(t0, (int32_t)n, op->node))
            continue;
        want++;
        ag_box lo = t0->nodes[n].box, hi = lo;
        lo.min[a] = B.min[a] + (lo.min[a] - B.min[a]) * f;
        lo.max[a] = B.min[a] + (lo.max[a] - B.min[a]) * f;
        hi.min[a] = op->at + (hi.min[a] - B.min[a]) * (1 - f);
        hi.max[a] = op->at + (hi.max[a] - B.min[a]) * (1 - f);
        if (!same_box(&t1->nodes[n].box, &lo, tol))
            fail_msg("%s: split: node %zu is not on the lower half", o->name, n);
        for (size_t k = t0->nnodes; k < t1->nnodes; k++)
            if (t1->nodes[k].kind == AG_NODE_COMPONENT && same_box(&t1->nodes[k].box, &hi, tol) &&
                !strcmp(label_of(out, (int32_t)k), label_of(em, (int32_t)n))) {
                found++;
                break;
            }
    }
    if (found != want)
        fail_msg("%s: split: %zu of %zu nodes have their copy on the upper half", o->name, found,
                 want);
    ag_edit_model_free(out);
}

/* Checks a paste derive of one unturned source node: every visible node of its subtree has an
 * appended copy of its label whose box is its box mapped from the source's box onto the
 * target's. */
static void check_paste_boxes(ag_edit_model *em, const ag_edit_op *op, const bb_options *o)
{
    ag_edit_model *out = NULL;
    ag_error err = {0};
    assert_int_equal(ag_edit_apply_ex(em, op, 0, &out, NULL, &err), AG_OK);
    const ag_splittree *t0 = em->proc->tree, *t1 = out->proc->tree;
    const ag_box S = t0->nodes[op->nodes[0]].box, D = t0->nodes[op->node].box;
    double tol = 1e-9 * fmax(1, fabs(D.max[0]) + fabs(D.max[1]) + fabs(D.max[2]));
    size_t found = 0, want = 0;
    for (size_t n = 0; n < t0->nnodes; n++) {
        if (t0->nodes[n].kind != AG_NODE_COMPONENT || !in_subtree(t0, (int32_t)n, op->nodes[0]))
            continue;
        want++;
        ag_box b = t0->nodes[n].box, m;
        for (int a = 0; a < 3; a++) {
            double f = ag_box_extent(&S, a) > 0 ? ag_box_extent(&D, a) / ag_box_extent(&S, a) : 1;
            m.min[a] = D.min[a] + (b.min[a] - S.min[a]) * f;
            m.max[a] = D.min[a] + (b.max[a] - S.min[a]) * f;
        }
        for (size_t k = t0->nnodes; k < t1->nnodes; k++)
            if (t1->nodes[k].kind == AG_NODE_COMPONENT && same_box(&t1->nodes[k].box, &m, tol) &&
                !strcmp(label_of(out, (int32_t)k), label_of(em, (int32_t)n))) {
                found++;
                break;
            }
    }
    if (found != want)
        fail_msg("%s: paste: %zu of %zu nodes have their copy in the target", o->name, found, want);
    ag_edit_model_free(out);
}

/* ---- the buildings ------------------------------------------------------------------------ */


/* The visible node with the largest box volume (a wall). */
static int32_t largest(const ag_splittree *t)
{
    int32_t best = -1;
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT &&
            (best < 0 || ag_box_volume(&t->nodes[n].box) > ag_box_volume(&t->nodes[best].box)))
            best = (int32_t)n;
    return best;
}

/* Do two boxes lie on one facade: the same thin horizontal axis, the same side of the
 * building's centre along it? */
static int same_facade(const ag_splittree *t, int32_t a, int32_t b)
{
    const ag_box *r = &t->nodes[0].box, *p = &t->nodes[a].box, *q = &t->nodes[b].box;
    int ax = ag_box_extent(p, 0) < ag_box_extent(p, 1) ? 0 : 1;
    int bx = ag_box_extent(q, 0) < ag_box_extent(q, 1) ? 0 : 1;
    double cp = ag_box_centre_axis(p, ax) - ag_box_centre_axis(r, ax);
    double cq = ag_box_centre_axis(q, ax) - ag_box_centre_axis(r, ax);
    return ax == bx && cp * cq > 0;
}

/* The first two visible leaves of the label with the most instances that face the way `like`
 * faces (the same thin horizontal axis, same side of the building): windows of one facade. */
static void two_windows(const ag_edit_model *em, int32_t *a, int32_t *b)
{
    const ag_splittree *t = em->proc->tree;
    size_t nl = em->proc->labels->nlabels;
    size_t *count = calloc(nl + 1, sizeof *count);
    for (size_t n = 0; n < t->nnodes; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && t->nodes[n].first_child < 0 &&
            t->nodes[n].label >= 0)
            count[t->nodes[n].label]++;
    int32_t lab = 0;
    for (size_t l = 0; l < nl; l++)
        if (count[l] > count[lab])
            lab = (int32_t)l;
    free(count);
    *a = *b = -1;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind != AG_NODE_COMPONENT || x->first_child >= 0 || x->label != lab)
            continue;
        if (*a < 0) {
            *a = (int32_t)n;
            continue;
        }
        if (same_facade(t, *a, (int32_t)n)) {
            *b = (int32_t)n;
            return;
        }
    }
}

static int32_t *list(int32_t a, int32_t b)
{
    int32_t *l = malloc(2 * sizeof *l);
    l[0] = a;
    l[1] = b;
    return l;
}

static void run_variant(const bb_options *o)
{
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_edit_model *em = bb_service_model(o, &m, &err);
    if (!em)
        fail_msg("%s: %s", o->name, err.text);
    const ag_splittree *t = em->proc->tree;
    size_t nn = t->nnodes;
    int32_t wall = largest(t), wa, wb;
    two_windows(em, &wa, &wb);
    assert_true(wall > 0 && wa > 0 && wb > 0);
    uint8_t *touched = calloc(nn, 1);

    /* split the wall across its length, then a window */
    const ag_box *W = &t->nodes[wall].box;
    int axis = ag_box_extent(W, 0) >= ag_box_extent(W, 1) ? 0 : 1;
    ag_edit_op split = {.kind = AG_EDIT_SPLIT, .node = wall, .axis = axis,
                        .at = W->min[axis] + 0.37 * ag_box_extent(W, axis)};
    memset(touched, 0, nn);
    size_t below = visible_below(t, wall, touched);
    case_t c1 = {"split the wall", split, touched, 0, below};
    check_case(em, &c1, o);
    check_split_boxes(em, &split, o);
    const ag_box *A = &t->nodes[wa].box;
    int wax = ag_box_extent(A, 0) >= ag_box_extent(A, 1) ? 0 : 1;
    ag_edit_op split_w = {.kind = AG_EDIT_SPLIT, .node = wa, .axis = wax,
                          .at = 0.5 * (A->min[wax] + A->max[wax])};
    memset(touched, 0, nn);
    below = visible_below(t, wa, touched);
    case_t c2 = {"split a window", split_w, touched, 0, below};
    check_case(em, &c2, o);
    check_split_boxes(em, &split_w, o);
    ag_edit_op split_z = {.kind = AG_EDIT_SPLIT, .node = AG_EDIT_ROOT, .axis = 2,
                          .at = t->nodes[0].box.min[2] + 0.5 * ag_box_extent(&t->nodes[0].box, 2)};
    memset(touched, 0, nn);
    below = visible_below(t, 0, touched);
    case_t c3 = {"split the whole building", split_z, touched, 0, below};
    check_case(em, &c3, o);

    /* remove a window, then the wall (its subtree with it) */
    ag_edit_op rm = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = list(wa, wa)};
    memset(touched, 0, nn);
    visible_below(t, wa, touched);
    case_t c4 = {"remove a window", rm, touched, 1, 0};
    check_case(em, &c4, o);
    rm.nodes[0] = wall;
    memset(touched, 0, nn);
    visible_below(t, wall, touched);
    case_t c5 = {"remove the wall", rm, touched, 1, 0};
    check_case(em, &c5, o);
    free(rm.nodes);

    /* join two windows of one facade */
    ag_edit_op join = {.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = list(wa, wb)};
    memset(touched, 0, nn);
    touched[wa] = touched[wb] = 1;
    case_t c6 = {"join two windows", join, touched, 2, 0};
    check_case(em, &c6, o);
    {
        /* one of them is the joined node (the union box), the other is dead */
        ag_edit_model *out = NULL;
        assert_int_equal(ag_edit_apply_ex(em, &join, 0, &out, NULL, &err), AG_OK);
        const ag_splittree *t1 = out->proc->tree;
        int32_t kept = t1->nodes[wa].kind == AG_NODE_COMPONENT ? wa : wb;
        int32_t gone = kept == wa ? wb : wa;
        ag_box u = t->nodes[wa].box;
        ag_box_extend_box(&u, &t->nodes[wb].box);
        assert_int_equal(t1->nodes[gone].kind, AG_NODE_DEAD);
        assert_true(same_box(&t1->nodes[kept].box, &u, 1e-9 * fmax(1, ag_box_diagonal(&u) + fabs(u.max[1]))));
        assert_string_not_equal(label_of(out, kept), label_of(em, kept));
        ag_edit_model_free(out);
    }
    /* the wall and a window (in it, when recessed): one node of both */
    join.nodes[0] = wall;
    join.nodes[1] = wa;
    memset(touched, 0, nn);
    touched[wall] = touched[wa] = 1;
    case_t c6b = {"join the wall and a window", join, touched, 2, 0};
    check_case(em, &c6b, o);
    free(join.nodes);

    /* paste a window onto another (replace, derive), and into itself (insert, derive) */
    ag_edit_op paste = {.kind = AG_EDIT_PASTE, .node = wb, .nnodes = 1, .nodes = list(wa, wa),
                        .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
    memset(touched, 0, nn);
    visible_below(t, wb, touched);
    case_t c7 = {"paste a window onto another", paste, touched, 1, visible_below(t, wa, NULL)};
    check_case(em, &c7, o);
    check_paste_boxes(em, &paste, o);
    paste.node = wa;
    paste.nodes[0] = wb;
    paste.placement = AG_EDIT_INSERT;
    memset(touched, 0, nn);
    case_t c8 = {"paste a window into another", paste, touched, 0, visible_below(t, wb, NULL)};
    check_case(em, &c8, o);
    check_paste_boxes(em, &paste, o);
    /* fill the window's wall with it (a grid of copies): the largest node of its facade */
    int32_t front = -1;
    for (size_t n = 0; n < nn; n++)
        if (t->nodes[n].kind == AG_NODE_COMPONENT && (int32_t)n != wa && same_facade(t, wa, (int32_t)n) &&
            (front < 0 || ag_box_volume(&t->nodes[n].box) > ag_box_volume(&t->nodes[front].box)))
            front = (int32_t)n;
    assert_true(front > 0);
    paste.node = front;
    paste.nodes[0] = wa;
    paste.fit = AG_EDIT_FILL;
    {
        ag_edit_model *out = NULL;
        ag_edit_report rep = {0};
        assert_int_equal(ag_edit_apply_ex(em, &paste, 0, &out, &rep, &err), AG_OK);
        unsigned cx = 0, cy = 0, cz = 0;
        assert_int_equal(sscanf(strchr(rep.message, '(') + 1, "%u x %u x %u", &cx, &cy, &cz), 3);
        memset(touched, 0, nn);
        case_t c9 = {"fill the wall with a window", paste, touched, 0,
                     (size_t)cx * cy * cz * visible_below(t, wa, NULL)};
        assert_true(c9.appended > 4);
        check_case(em, &c9, o);
        ag_edit_report_clear(&rep);
        ag_edit_model_free(out);
    }
    free(paste.nodes);

    /* a pattern: split (its cells squeezed, a copy of it appended), removed, its cells joined */
    int32_t pat = -1;
    for (size_t n = 0; n < nn && pat < 0; n++)
        if (t->nodes[n].kind == AG_NODE_PATTERN)
            pat = (int32_t)n;
    if (pat < 0)
        fail_msg("%s: the building has no pattern", o->name);
    const ag_box *P = &t->nodes[pat].box;
    ag_edit_op split_p = {.kind = AG_EDIT_SPLIT, .node = pat, .axis = 2,
                          .at = P->min[2] + 0.5 * ag_box_extent(P, 2)};
    memset(touched, 0, nn);
    below = visible_below(t, pat, touched);
    case_t c10 = {"split a pattern", split_p, touched, 0, below};
    check_case(em, &c10, o);
    check_split_boxes(em, &split_p, o);
    ag_edit_op rm_p = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = list(pat, pat)};
    memset(touched, 0, nn);
    visible_below(t, pat, touched);
    case_t c11 = {"remove a pattern", rm_p, touched, 1, 0};
    check_case(em, &c11, o);
    rm_p.kind = AG_EDIT_JOIN; /* a pattern stands for its cells */
    memset(touched, 0, nn);
    visible_below(t, pat, touched);
    case_t c12 = {"join a pattern's cells", rm_p, touched, 2, 0};
    check_case(em, &c12, o);
    free(rm_p.nodes);
    free(touched);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

static void ids_survive_split_join_paste_remove(void **state)
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

/* The front window and the side window of a building (thin along y, thin along x). */
static void front_and_side(const ag_splittree *t, int32_t *front, int32_t *side)
{
    *front = *side = -1;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind != AG_NODE_COMPONENT || x->first_child >= 0 || ag_box_extent(&x->box, 2) > 3)
            continue;
        int thin_y = ag_box_extent(&x->box, 1) < ag_box_extent(&x->box, 0);
        if (thin_y && *front < 0 && ag_box_extent(&x->box, 0) < 3)
            *front = (int32_t)n;
        if (!thin_y && *side < 0 && ag_box_extent(&x->box, 1) < 3)
            *side = (int32_t)n;
    }
}

/* A paste that turns its source (a front window onto a window of the side facade), and one from
 * another building, keep ids too: the turned copy is the operation's mesh's. */
static void turned_and_cross_model_pastes_keep_ids(void **state)
{
    (void)state;
    size_t nv;
    const bb_options *variants = bb_id_variants(&nv);
    for (size_t v = 0; v < nv; v++) {
        const bb_options *o = &variants[v];
        ag_mesh *m = NULL;
        ag_error err = {0};
        ag_edit_model *em = bb_service_model(o, &m, &err);
        assert_non_null(em);
        const ag_splittree *t = em->proc->tree;
        int32_t front, side;
        front_and_side(t, &front, &side);
        assert_true(front > 0 && side > 0);
        int32_t src[1] = {front};
        ag_edit_op paste = {.kind = AG_EDIT_PASTE, .node = side, .nnodes = 1, .nodes = src,
                            .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
        ag_edit_report rep = {0};
        ag_edit_model *out = NULL;
        if (ag_edit_apply_ex(em, &paste, 0, &out, &rep, &err))
            fail_msg("turned paste: %s", err.text);
        if (!strstr(rep.message, "turned by 1 quarter turn") && !strstr(rep.message, "turned by 3"))
            fail_msg("%s: not a turned paste: %s", o->name, rep.message);
        ag_edit_report_clear(&rep);
        ag_edit_model_free(out);
        uint8_t *touched = calloc(t->nnodes, 1);
        visible_below(t, side, touched);
        case_t c = {"paste a front window onto a side window", paste, touched, 1,
                    visible_below(t, front, NULL)};
        check_case(em, &c, o);
        /* from another building (the flush one): its labels are new ones here */
        ag_mesh *m2 = NULL;
        ag_edit_model *other = bb_service_model(&variants[1], &m2, &err);
        assert_non_null(other);
        int32_t f2, s2;
        front_and_side(other->proc->tree, &f2, &s2);
        src[0] = f2;
        paste.source = other->proc;
        paste.node = front;
        memset(touched, 0, t->nnodes);
        visible_below(t, front, touched);
        case_t c2 = {"paste another building's window", paste, touched, 1,
                     visible_below(other->proc->tree, f2, NULL)};
        check_case(em, &c2, o);
        paste.node = side; /* and turned */
        memset(touched, 0, t->nnodes);
        visible_below(t, side, touched);
        case_t c3 = {"paste another building's window turned", paste, touched, 1,
                     visible_below(other->proc->tree, f2, NULL)};
        check_case(em, &c3, o);
        free(touched);
        ag_edit_model_free(other);
        ag_mesh_free(m2);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

/* The nearest visible ancestor of n (a wall holding a recessed window), or -1. */
static int32_t holder_wall(const ag_splittree *t, int32_t n)
{
    for (int32_t x = t->nodes[n].parent; x > 0; x = t->nodes[x].parent)
        if (t->nodes[x].kind == AG_NODE_COMPONENT)
            return x;
    return -1;
}

/* A turned paste of mirrored terminals keeps ids too: on buildings whose windows are mirror
 * images of each other (handles left and right), a front window that is a mirror image of its
 * label's exemplar pasted onto a side window (a quarter turn), checked as every case is
 * (against the operation's own mesh); and the copy is still marked as a mirror image. */
static void turned_paste_of_mirrored_terminals_keeps_ids(void **state)
{
    (void)state;
    size_t nh;
    const bb_options *handed = bb_handed_variants(&nh);
    for (size_t v = 0; v < nh; v++) {
        const bb_options *o = &handed[v];
        ag_mesh *m = NULL;
        ag_error err = {0};
        ag_edit_model *em = bb_service_model(o, &m, &err);
        if (!em)
            fail_msg("%s: %s", o->name, err.text);
        const ag_splittree *t = em->proc->tree;
        const ag_labels *L = em->proc->labels;
        /* a mirrored window of one facade and a window of a facade at a quarter turn to it */
        int32_t src = -1, dst = -1;
        for (size_t n = 0; n < t->nnodes && src < 0; n++) {
            const ag_tnode *x = &t->nodes[n];
            if (x->kind == AG_NODE_COMPONENT && x->first_child < 0 && x->component >= 0 &&
                L->mirror[x->component] && ag_box_extent(&x->box, 2) < 3)
                src = (int32_t)n;
        }
        if (src < 0)
            fail_msg("%s: no window is a mirror image of another", o->name);
        const ag_box *S = &t->nodes[src].box;
        int sthin = ag_box_extent(S, 0) < ag_box_extent(S, 1) ? 0 : 1;
        for (size_t n = 0; n < t->nnodes && dst < 0; n++) {
            const ag_tnode *x = &t->nodes[n];
            int thin = ag_box_extent(&x->box, 0) < ag_box_extent(&x->box, 1) ? 0 : 1;
            if (x->kind == AG_NODE_COMPONENT && x->first_child < 0 && thin != sthin &&
                ag_box_extent(&x->box, 2) < 3 && ag_box_extent(&x->box, 2) > 1 &&
                ag_box_extent(&x->box, 1 - thin) < 3)
                dst = (int32_t)n;
        }
        assert_true(dst > 0);
        int32_t nodes[1] = {src};
        ag_edit_op paste = {.kind = AG_EDIT_PASTE, .node = dst, .nnodes = 1, .nodes = nodes,
                            .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
        ag_edit_report rep = {0};
        ag_edit_model *out = NULL;
        if (ag_edit_apply_ex(em, &paste, 0, &out, &rep, &err))
            fail_msg("%s: turned paste: %s", o->name, err.text);
        if (!strstr(rep.message, "turned by 1 quarter turn") && !strstr(rep.message, "turned by 3"))
            fail_msg("%s: not a turned paste: %s", o->name, rep.message);
        /* the copy: appended, a mirror image of its label's exemplar, of the source's label */
        const ag_splittree *t1 = out->proc->tree;
        size_t copies = 0;
        for (size_t n = t->nnodes; n < t1->nnodes; n++) {
            const ag_tnode *x = &t1->nodes[n];
            if (x->kind != AG_NODE_COMPONENT)
                continue;
            copies++;
            assert_string_equal(label_of(out, (int32_t)n), label_of(em, src));
        }
        assert_int_equal(copies, 1);
        ag_edit_report_clear(&rep);
        ag_edit_model_free(out);
        uint8_t *touched = calloc(t->nnodes, 1);
        visible_below(t, dst, touched);
        case_t c = {"paste a mirrored window turned", paste, touched, 1, 1};
        check_case(em, &c, o);
        /* and inserted into a wall of the other facade (kept beside what is there) */
        int32_t wall = holder_wall(t, dst);
        if (wall > 0) {
            paste.node = wall;
            paste.placement = AG_EDIT_INSERT;
            memset(touched, 0, t->nnodes);
            case_t c2 = {"insert a mirrored window turned", paste, touched, 0, 1};
            check_case(em, &c2, o);
        }
        free(touched);
        ag_edit_model_free(em);
        ag_mesh_free(m);
    }
}

/* ---- ids matched after proceduralizing again ---------------------------------------------- */

/* op's mesh proceduralized again (the mesh path: every node renumbered), then matched to the
 * input (core/edit/idmatch.h) with `changed` (what the op names as replaced; NULL: nothing
 * named): every visible node of the input outside `touched` has its id, label and box again;
 * the touched ones are dead when the op removes or moves them; `appended` visible nodes get new
 * ids; the renumbered model's mesh is the mesh path's (vertex set, areas), its grammar derives
 * it, and it reloads from what the store keeps node for node. Returns how many of the kept
 * nodes the mesh path alone had numbered as before. */
static size_t check_matched(ag_edit_model *em, const ag_edit_op *op, const uint8_t *touched,
                            const uint8_t *changed, int removes, size_t appended,
                            const char *what, const bb_options *o)
{
    ag_edit_model *mp = NULL, *out = NULL;
    ag_proceduralize_result *r = NULL;
    ag_idmatch_report rep = {0};
    ag_error err = {0};
    if (ag_edit_apply_ex(em, op, AG_EDIT_MESH_PATH, &mp, NULL, &err))
        fail_msg("%s: %s: the mesh path: %s", o->name, what, err.text);
    if (ag_idmatch_renumber(em->proc, mp->proc, changed, &em->opt.patterns, &r, &rep, &err))
        fail_msg("%s: %s: match: %s", o->name, what, err.text);
    assert_non_null(r); /* the mesh path numbers otherwise */
    assert_int_equal(ag_edit_model_wrap(r, &em->opt, &out, &err), AG_OK);
    const ag_splittree *t0 = em->proc->tree, *t1 = out->proc->tree, *tm = mp->proc->tree;
    double btol = 1e-9 * fmax(1, fabs(t0->nodes[0].box.max[0]) + fabs(t0->nodes[0].box.max[1]));
    assert_true(t1->nnodes >= t0->nnodes);
    size_t by_chance = 0, kept = 0;
    for (size_t n = 0; n < t0->nnodes; n++) {
        const ag_tnode *a = &t0->nodes[n], *b = &t1->nodes[n];
        if (a->kind != AG_NODE_COMPONENT)
            continue;
        if (touched[n]) {
            if (removes && b->kind != AG_NODE_DEAD)
                fail_msg("%s: %s: node %zu should be dead, it is %s", o->name, what, n,
                         label_of(out, (int32_t)n));
            continue;
        }
        if (b->kind != AG_NODE_COMPONENT)
            fail_msg("%s: %s: visible node %zu (%s) lost its id", o->name, what, n,
                     label_of(em, (int32_t)n));
        if (strcmp(label_of(em, (int32_t)n), label_of(out, (int32_t)n)))
            fail_msg("%s: %s: node %zu changed label %s -> %s", o->name, what, n,
                     label_of(em, (int32_t)n), label_of(out, (int32_t)n));
        if (!same_box(&a->box, &b->box, btol))
            fail_msg("%s: %s: node %zu moved", o->name, what, n);
        kept++;
        by_chance += n < tm->nnodes && tm->nodes[n].kind == AG_NODE_COMPONENT &&
                     same_box(&tm->nodes[n].box, &a->box, btol) &&
                     !strcmp(label_of(mp, (int32_t)n), label_of(em, (int32_t)n));
    }
    size_t added = 0, visible = 0;
    for (size_t n = 0; n < t1->nnodes; n++) {
        visible += t1->nodes[n].kind == AG_NODE_COMPONENT;
        added += n >= t0->nnodes && t1->nodes[n].kind == AG_NODE_COMPONENT;
    }
    if (added != appended)
        fail_msg("%s: %s: %zu visible nodes appended, expected %zu", o->name, what, added,
                 appended);
    assert_int_equal(rep.kept, kept);
    assert_int_equal(rep.kept + rep.appended, visible);
    double diag = ag_box_diagonal(&t0->nodes[0].box);
    char part[200];
    snprintf(part, sizeof part, "%s: %s (matched mesh)", o->name, what);
    assert_same_surface(out->proc->mesh, mp->proc->mesh, 1e-6 * fmax(1, diag), part);
    ag_mesh *derived = NULL;
    if (ag_grammar_derive(out->proc->grammar, NULL, &derived, &err))
        fail_msg("%s: %s: derive: %s", o->name, what, err.text);
    snprintf(part, sizeof part, "%s: %s (matched grammar)", o->name, what);
    assert_same_surface(derived, mp->proc->mesh, 1e-4 * fmax(1, diag), part);
    ag_mesh_free(derived);
    char *served = ag_model_tree_served_text(out), *stored = ek_served_after_store(out);
    if (strcmp(served, stored))
        fail_msg("%s: %s: the matched model does not reload node for node", o->name, what);
    free(served);
    free(stored);
    ag_edit_model_free(out);
    ag_edit_model_free(mp);
    return by_chance;
}

static void match_variant(const bb_options *o, size_t *chance, size_t *total)
{
    ag_mesh *m = NULL;
    ag_error err = {0};
    ag_edit_model *em = bb_service_model(o, &m, &err);
    if (!em)
        fail_msg("%s: %s", o->name, err.text);
    const ag_splittree *t = em->proc->tree;
    size_t nn = t->nnodes, vis = visible_below(t, 0, NULL);
    int32_t wall = largest(t), wa, wb;
    two_windows(em, &wa, &wb);
    assert_true(wall > 0 && wa > 0 && wb > 0);
    uint8_t *touched = calloc(nn, 1);
    int32_t pair[2] = {wa, wb};
#define MATCHED(op, changed, removes, appended, what)                                          \
    do {                                                                                      \
        *chance += check_matched(em, &(op), touched, changed, removes, appended, what, o);    \
        *total += vis;                                                                        \
    } while (0)
    /* a window removed, the wall removed (with what it holds) */
    ag_edit_op rm = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = pair};
    visible_below(t, wa, touched);
    MATCHED(rm, NULL, 1, 0, "remove a window");
    memset(touched, 0, nn);
    int32_t w1[1] = {wall};
    rm.nodes = w1;
    visible_below(t, wall, touched);
    MATCHED(rm, NULL, 1, 0, "remove the wall");
    /* two windows joined: one node of a new label */
    ag_edit_op join = {.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = pair};
    memset(touched, 0, nn);
    touched[wa] = touched[wb] = 1;
    MATCHED(join, NULL, 1, 1, "join two windows");
    /* a window pasted onto another (what it replaces named), and into another */
    int32_t src[1] = {wa};
    ag_edit_op paste = {.kind = AG_EDIT_PASTE, .node = wb, .nnodes = 1, .nodes = src,
                        .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
    memset(touched, 0, nn);
    visible_below(t, wb, touched);
    MATCHED(paste, touched, 1, visible_below(t, wa, NULL), "paste a window onto another");
    paste.placement = AG_EDIT_INSERT;
    memset(touched, 0, nn);
    MATCHED(paste, NULL, 0, visible_below(t, wa, NULL), "paste a window into another");
    /* the wall split: both halves (and what it holds) are new boxes */
    const ag_box *W = &t->nodes[wall].box;
    int axis = ag_box_extent(W, 0) >= ag_box_extent(W, 1) ? 0 : 1;
    ag_edit_op split = {.kind = AG_EDIT_SPLIT, .node = wall, .axis = axis,
                        .at = W->min[axis] + 0.37 * ag_box_extent(W, axis)};
    memset(touched, 0, nn);
    size_t below = visible_below(t, wall, touched);
    MATCHED(split, NULL, 1, 2 * below, "split the wall");
#undef MATCHED
    free(touched);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

/* A model proceduralized again gets the ids of the model it replaces (core/edit/idmatch.h):
 * on every generated building, for ops made by their mesh and proceduralized again. */
static void ids_matched_after_proceduralizing_again(void **state)
{
    (void)state;
    size_t chance = 0, total = 0;
    for (int set = 0; set < 2; set++) {
        size_t nv;
        const bb_options *v = set ? bb_handed_variants(&nv) : bb_id_variants(&nv);
        for (size_t i = 0; i < nv; i++)
            match_variant(&v[i], &chance, &total);
    }
    /* a model matched to itself read back through its grammar: every visible node kept, none
     * new, none dead */
    for (int set = 0; set < 2; set++) {
        size_t nv;
        const bb_options *v = set ? bb_handed_variants(&nv) : bb_id_variants(&nv);
        for (size_t i = 0; i < nv; i++) {
            ag_mesh *m = NULL;
            ag_error err = {0};
            ag_edit_model *em = bb_service_model(&v[i], &m, &err), *again = NULL;
            assert_non_null(em);
            assert_int_equal(ag_edit_model_from_grammar(em->proc->grammar, &em->opt, &again, &err), AG_OK);
            ag_proceduralize_result *r = NULL;
            ag_idmatch_report rep = {0};
            assert_int_equal(ag_idmatch_renumber(em->proc, again->proc, NULL, &em->opt.patterns, &r, &rep, &err), AG_OK);
            ag_proceduralize_result_free(r); /* NULL when numbered as before */
            assert_int_equal(rep.appended, 0);
            assert_int_equal(rep.dead, 0);
            assert_int_equal(rep.kept, visible_below(em->proc->tree, 0, NULL));
            ag_edit_model_free(again);
            ag_edit_model_free(em);
            ag_mesh_free(m);
        }
    }
    /* what the matching is for: without it most ids name other nodes */
    print_message("ids the mesh path alone kept: %zu of %zu\n", chance, total);
    assert_true(chance < total / 2);
}

/* Bad ops get the same precise error from the tree path as from the mesh path, and no model. */
static void bad_ops_are_refused_as_before(void **state)
{
    (void)state;
    ag_mesh *m = NULL;
    ag_error err = {0};
    size_t nv;
    ag_edit_model *em = bb_service_model(&bb_id_variants(&nv)[0], &m, &err);
    assert_non_null(em);
    const ag_splittree *t = em->proc->tree;
    int32_t wall = largest(t), wa, wb;
    two_windows(em, &wa, &wb);
    const ag_box *W = &t->nodes[wall].box;
    int32_t one[1] = {wa}, root[2] = {wa, AG_EDIT_ROOT}, far[1] = {(int32_t)t->nnodes + 5};
    const struct {
        ag_edit_op op;
        const char *says;
    } bad[] = {
        {{.kind = AG_EDIT_SPLIT, .node = wall, .axis = 0, .at = W->max[0] + 1}, "not inside"},
        {{.kind = AG_EDIT_SPLIT, .node = wall, .axis = 3, .at = 0}, "axis"},
        {{.kind = AG_EDIT_SPLIT, .node = (int32_t)t->nnodes, .axis = 0, .at = 0}, "not in the split tree"},
        {{.kind = AG_EDIT_REMOVE}, "nodes is empty"},
        {{.kind = AG_EDIT_REMOVE, .nnodes = 2, .nodes = root}, "the root cannot be removed"},
        {{.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = far}, "not in the split tree"},
        {{.kind = AG_EDIT_JOIN, .nnodes = 1, .nodes = one}, "at least two distinct visible nodes"},
        {{.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = root}, "the root cannot be joined"},
        {{.kind = AG_EDIT_PASTE, .node = wb}, "source selection"},
        {{.kind = AG_EDIT_PASTE, .node = wb, .nnodes = 1, .nodes = one, .placement = 7}, "placement"},
        {{.kind = AG_EDIT_PASTE, .node = wb, .nnodes = 1, .nodes = far}, "not in the split tree"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_edit_model *out = NULL;
        ag_error e1 = {0}, e2 = {0};
        ag_status s1 = ag_edit_apply_ex(em, &bad[i].op, 0, &out, NULL, &e1);
        assert_null(out);
        ag_status s2 = ag_edit_apply_ex(em, &bad[i].op, AG_EDIT_MESH_PATH, &out, NULL, &e2);
        assert_null(out);
        if (!s1 || s1 != s2 || strcmp(e1.text, e2.text) || !strstr(e1.text, bad[i].says))
            fail_msg("bad op %zu: %d \"%s\" vs the mesh path %d \"%s\"", i, s1, e1.text, s2,
                     e2.text);
    }
    /* removing everything leaves nothing: refused, as before */
    int32_t all[1] = {0};
    ag_edit_op rm = {.kind = AG_EDIT_REMOVE, .nnodes = 0, .nodes = all};
    size_t k = 0;
    int32_t *tops = malloc((t->nnodes + 1) * sizeof *tops);
    for (int32_t c = t->nodes[0].first_child; c >= 0; c = t->nodes[c].next_sibling)
        tops[k++] = c;
    rm.nodes = tops;
    rm.nnodes = k;
    ag_edit_model *out = NULL;
    ag_error e1 = {0};
    assert_int_not_equal(ag_edit_apply_ex(em, &rm, 0, &out, NULL, &e1), AG_OK);
    assert_null(out);
    assert_non_null(strstr(e1.text, "no geometry"));
    free(tops);
    ag_edit_model_free(em);
    ag_mesh_free(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ids_survive_split_join_paste_remove),
        cmocka_unit_test(turned_and_cross_model_pastes_keep_ids),
        cmocka_unit_test(turned_paste_of_mirrored_terminals_keeps_ids),
        cmocka_unit_test(ids_matched_after_proceduralizing_again),
        cmocka_unit_test(bad_ops_are_refused_as_before),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
