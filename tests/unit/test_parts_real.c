/* Parts saved from real buildings (../shared/data/lod3_ingolstadt, read z-up) and composed into
 * other Ingolstadt buildings and into 0 A.D. buildings: the results derive, print back
 * canonically, and the part's terminals land inside the target boxes. Skipped when the data
 * is absent. Models are read as the CLI reads a proceduralized folder (the grammar derived and
 * proceduralized again). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <cmocka.h>

#include "core/edit/edit.h"
#include "core/parts/compose.h"
#include "core/parts/graft.h"
#include "core/parts/part.h"
#include "io/grammar_text.h"
#include "io/obj.h"
#include "parts_fixture.h"

#define SHARED AG_REPO_DIR "/../shared/data"

static const char *SOURCES[] = {"lod3_ingolstadt/obj/4018128.obj", "lod3_ingolstadt/obj/4018147.obj",
                                "lod3_ingolstadt/obj/4018150a.obj"};
static const char *TARGETS[] = {"lod3_ingolstadt/obj/4018148.obj", "lod3_ingolstadt/obj/4018156.obj",
                                "meshes_0ad/han_temple.obj", "meshes_0ad/pers_civic.obj"};

static ag_edit_model *load(const char *rel)
{
    char path[512];
    snprintf(path, sizeof path, SHARED "/%s", rel);
    ag_obj_read_options ro = {.up = strstr(rel, "ingolstadt") ? AG_UP_Z : AG_UP_Y};
    ag_mesh *m = NULL;
    ag_error err = {0};
    if (ag_obj_read_file(path, &ro, &m, &err))
        fail_msg("%s: %s", path, err.text);
    ag_proceduralize_result *r = NULL;
    if (ag_proceduralize_run(m, NULL, &r, &err))
        fail_msg("%s: %s", path, err.text);
    ag_edit_model *em = NULL;
    if (ag_edit_model_from_grammar(r->grammar, NULL, &em, &err))
        fail_msg("%s: %s", path, err.text);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return em;
}

/* The visible nodes worth saving or composing into: repeated (a rule with several instances),
 * the largest first by volume; up to max. */
static size_t repeated_nodes(const ag_proceduralize_result *r, int32_t *out, size_t max)
{
    const ag_splittree *t = r->tree;
    size_t n = 0;
    for (size_t i = 0; i < t->nnodes && n < max; i++) {
        const ag_tnode *nd = &t->nodes[i];
        if (nd->kind != AG_NODE_COMPONENT || nd->rule < 0 || t->rule_count[nd->rule] < 2)
            continue;
        int dup = 0;
        for (size_t k = 0; k < n && !dup; k++)
            dup = t->nodes[out[k]].rule == nd->rule;
        if (!dup)
            out[n++] = (int32_t)i;
    }
    return n;
}

static int32_t largest_visible(const ag_proceduralize_result *r)
{
    const ag_splittree *t = r->tree;
    int32_t best = -1;
    double bv = -1;
    for (size_t i = 0; i < t->nnodes; i++) {
        const ag_box *b = &t->nodes[i].box;
        double v = (b->max[0] - b->min[0]) * (b->max[1] - b->min[1]) + (b->max[2] - b->min[2]);
        if (t->nodes[i].kind == AG_NODE_COMPONENT && v > bv) {
            bv = v;
            best = (int32_t)i;
        }
    }
    return best;
}

/* Derives g, checks the canonical round trip, and that every component of the part's labels
 * lies inside one of the boxes. Returns the part's components. */
static size_t check(const ag_grammar *g, const char *ident, const ag_box *boxes, size_t nb,
                    double tol, const char *what)
{
    char *a = NULL, *b = NULL;
    size_t la, lb;
    ag_error err = {0};
    assert_int_equal(ag_grammar_text_print(g, &a, &la, NULL), AG_OK);
    ag_grammar *back = NULL;
    long col;
    if (ag_grammar_text_parse(a, la, &back, &err, &col))
        fail_msg("%s: does not parse: %s", what, err.text);
    assert_int_equal(ag_grammar_text_print(back, &b, &lb, NULL), AG_OK);
    assert_string_equal(a, b);
    free(a);
    free(b);
    ag_grammar_free(back);
    ag_mesh *d = NULL;
    if (ag_grammar_derive(g, NULL, &d, &err))
        fail_msg("%s: does not derive: %s", what, err.text);
    ag_box *cb = pf_component_boxes(d);
    size_t n = 0, pl = strlen(ident);
    for (size_t c = 0; c < d->ncomponents; c++) {
        int32_t gi = d->component_group[c];
        if (gi < 0 || strncmp(d->group_names[gi], ident, pl) || d->group_names[gi][pl] != '_')
            continue;
        n++;
        int in = 0;
        for (size_t k = 0; k < nb && !in; k++)
            in = pf_inside(&cb[c], &boxes[k], tol);
        if (!in)
            fail_msg("%s: a terminal of the part lies outside the target", what);
    }
    free(cb);
    ag_mesh_free(d);
    return n;
}

/* Area per component. */
static double *component_areas(const ag_mesh *m)
{
    double *a = calloc(m->ncomponents + 1, sizeof *a);
    for (size_t t = 0; t < m->ntris; t++) {
        const double *p = &m->pos[3 * m->tri[3 * t]], *q = &m->pos[3 * m->tri[3 * t + 1]],
                     *r = &m->pos[3 * m->tri[3 * t + 2]];
        double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
        a[m->tri_component[t]] += 0.5 * sqrt(x * x + y * y + z * z);
    }
    return a;
}

/* Every component of a pairs with a distinct one of b: the same box within tol and the same
 * area within 1 % (real buildings' terminals are shared within the labels' tolerance, so the
 * graft, which keeps the model's own geometry where nothing changed, and the derivation
 * differ by that much). */
static void same_components(const ag_mesh *a, const ag_mesh *b, double tol, const char *what)
{
    ag_box *ba = pf_component_boxes(a), *bb = pf_component_boxes(b);
    double *aa = component_areas(a), *ab = component_areas(b);
    uint8_t *used = calloc(b->ncomponents + 1, 1);
    size_t na = 0, nb = 0;
    for (size_t j = 0; j < b->ncomponents; j++)
        nb += ab[j] > 0;
    for (size_t i = 0; i < a->ncomponents; i++) {
        if (!(aa[i] > 0))
            continue;
        na++;
        size_t j = 0;
        for (; j < b->ncomponents; j++)
            if (!used[j] && ab[j] > 0 && pf_same_box(&ba[i], &bb[j], tol) &&
                fabs(aa[i] - ab[j]) <= 0.01 * fmax(aa[i], ab[j]) + tol * tol)
                break;
        if (j == b->ncomponents)
            fail_msg("%s: grafted component %zu has no counterpart in the derivation", what, i);
        used[j] = 1;
    }
    assert_int_equal(na, nb);
    free(ba);
    free(bb);
    free(aa);
    free(ab);
    free(used);
}

static void test_real_compose(void **state)
{
    (void)state;
    struct stat sb;
    if (stat(SHARED "/lod3_ingolstadt/obj", &sb) || stat(SHARED "/meshes_0ad", &sb)) {
        print_message("skipping: %s is absent\n", SHARED);
        skip();
    }
    size_t compositions = 0, placed = 0, grafted = 0;
    for (size_t s = 0; s < sizeof SOURCES / sizeof *SOURCES; s++) {
        ag_edit_model *src = load(SOURCES[s]);
        int32_t nodes[2];
        size_t nn = repeated_nodes(src->proc, nodes, 2);
        assert_true(nn >= 1);
        for (size_t k = 0; k < nn; k++) {
            char name[64];
            snprintf(name, sizeof name, "part%zu_%zu", s, k);
            ag_part_meta meta = {.name = name, .source = SOURCES[s]};
            ag_part *p = NULL;
            ag_error err = {0};
            if (ag_part_extract(src->proc, nodes[k], &meta, &p, &err))
                fail_msg("%s node %d: %s", SOURCES[s], nodes[k], err.text);
            for (size_t t = 0; t < sizeof TARGETS / sizeof *TARGETS; t++) {
                ag_edit_model *dst = load(TARGETS[t]);
                const ag_splittree *tr = dst->proc->tree;
                double tol = 1e-6 * ag_box_diagonal(&tr->nodes[0].box);
                int32_t rep[1];
                size_t nr = repeated_nodes(dst->proc, rep, 1);
                int32_t big = largest_visible(dst->proc);
                struct {
                    int32_t node;
                    int mode, scope;
                } ops[3] = {{big, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE},
                            {big, AG_COMPOSE_FILL, AG_COMPOSE_NODE},
                            {nr ? rep[0] : big, AG_COMPOSE_REPLACE,
                             nr ? AG_COMPOSE_RULE : AG_COMPOSE_NODE}};
                for (int o = 0; o < 3; o++) {
                    ag_compose_op op = {.target = ops[o].node, .mode = ops[o].mode,
                                        .scope = ops[o].scope};
                    ag_grammar *g = NULL;
                    ag_compose_report cr;
                    char what[256];
                    snprintf(what, sizeof what, "%s node %d -> %s node %d %s/%s", SOURCES[s],
                             nodes[k], TARGETS[t], op.target, ag_compose_mode_name(op.mode),
                             ag_compose_scope_name(op.scope));
                    if (ag_compose(dst->proc, p, &op, &g, &cr, &err))
                        fail_msg("%s: %s", what, err.text);
                    /* where the part may land: the target, or every node of its class */
                    ag_box boxes[4096];
                    size_t nb = 0;
                    if (op.scope == AG_COMPOSE_RULE) {
                        for (size_t i = 0; i < tr->nnodes && nb < 4096; i++)
                            if (tr->nodes[i].kind == AG_NODE_COMPONENT &&
                                tr->nodes[i].rule == tr->nodes[op.target].rule)
                                boxes[nb++] = tr->nodes[i].box;
                    } else {
                        boxes[nb++] = tr->nodes[op.target].box;
                    }
                    size_t n = check(g, name, boxes, nb, tol, what);
                    assert_true(n > 0);
                    /* the service's graft (core/parts/graft.h): where it applies, the mesh is
                     * the derivation's; where it does not, it says why (counted) */
                    ag_mesh *d = NULL;
                    assert_int_equal(ag_grammar_derive(g, NULL, &d, &err), AG_OK);
                    ag_proceduralize_result *fast = NULL;
                    ag_error ge = {0};
                    ag_status gs = ag_graft_compose(dst->proc, &op, d, &dst->opt.patterns, &fast,
                                                    NULL, &ge);
                    if (gs == AG_OK) {
                        same_components(fast->mesh, d, fast->labels->tol + tol, what);
                        grafted++;
                    } else {
                        assert_int_equal(gs, AG_ERR_NOT_AVAILABLE);
                        print_message("%s: not grafted: %s\n", what, ge.text);
                    }
                    ag_proceduralize_result_free(fast);
                    ag_mesh_free(d);
                    placed += n;
                    compositions++;
                    ag_grammar_free(g);
                }
                ag_edit_model_free(dst);
            }
            ag_part_free(p);
        }
        ag_edit_model_free(src);
    }
    print_message("%zu compositions, %zu terminals of parts placed inside their targets, %zu "
                  "grafted (the others proceduralized)\n",
                  compositions, placed, grafted);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_real_compose),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
