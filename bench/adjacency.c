/* Adjacency benchmark: what the visible nodes' adjacency (the pairs of boxes that meet) costs
 * an edit op. On the generated ~200k-triangle building of bench/edit: a window taller (global
 * mode), the front wall wider, a wall split, a window removed, pasted and two joined, each as
 * the service commits it (ag_edit_apply_ex without read-back), with the pairs of the result
 * recomputed from scratch as every op did before. Then the building of bench/parts with its
 * largest facade saved as a part and composed onto the largest blank wall eleven times
 * (grafted, as the service composes), and a window removed, one pasted and one resized after
 * that. Figures, not a test. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app/heap.h"
#include "core/edit/edit.h"
#include "core/gen_facade.h"
#include "core/parts/compose.h"
#include "core/parts/graft.h"
#include "core/parts/part.h"
#include "core/proc/adjacency.h"
#include "core/proc/grammar.h"
#include "edit_targets.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static size_t visible(const ag_splittree *t)
{
    size_t v = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        v += t->nodes[n].kind == AG_NODE_COMPONENT;
    return v;
}

#define REPEAT 5 /* each figure is the fastest of this many runs */

/* The pairs of t recomputed from scratch on a copy: ms, and the count. */
static double full_ms(const ag_splittree *t, size_t *npairs)
{
    double best = -1;
    for (int r = 0; r < REPEAT; r++) {
        ag_splittree *c = ag_splittree_copy(t);
        if (!c)
            return -1;
        double a = now_ms();
        ag_status s = ag_splittree_adjacency(c);
        double ms = now_ms() - a;
        *npairs = c->nadj;
        ag_splittree_free(c);
        if (s)
            return -1;
        best = best < 0 || ms < best ? ms : best;
    }
    return best;
}

/* The pairs of `after` brought up to date from those of `before` (its adjacency state moved
 * onto a copy of after, as an edited tree carries its input's): ms, whether they equal the
 * full recomputation's, and whether the update found them from scratch. */
static double update_ms(const ag_splittree *before, const ag_splittree *after, int *same,
                        int *scratch_out)
{
    ag_splittree *f = ag_splittree_copy(after);
    *same = 0;
    if (!f || ag_splittree_adjacency(f)) {
        ag_splittree_free(f);
        return -1;
    }
    double best = -1;
    for (int r = 0; r < REPEAT; r++) {
        ag_splittree *c = ag_splittree_copy(after), *b = ag_splittree_copy(before);
        if (!c || !b) {
            ag_splittree_free(c);
            ag_splittree_free(b);
            best = -1;
            break;
        }
        ag_splittree_adjacency_take(c, b);
        int scratch = 0;
        double a = now_ms();
        ag_status s = ag_splittree_adjacency_update(c, &scratch);
        double ms = now_ms() - a;
        *scratch_out = scratch;
        *same = !s && c->nadj == f->nadj &&
                (!f->nadj || !memcmp(c->adj, f->adj, 2 * f->nadj * sizeof *f->adj));
        ag_splittree_free(c);
        ag_splittree_free(b);
        if (s || !*same) {
            best = -1;
            break;
        }
        best = best < 0 || ms < best ? ms : best;
    }
    ag_splittree_free(f);
    return best;
}

static void row(const char *what, double op_ms, const ag_splittree *before,
                const ag_splittree *after)
{
    size_t np = 0;
    double full = full_ms(after, &np);
    int same = 0, scratch = 0;
    double upd = update_ms(before, after, &same, &scratch);
    printf("%-34s %8zu %9zu | %8.1f | %8.2f %8.2f %-7s %s\n", what, visible(after), np, op_ms,
           full, upd, scratch ? "scratch" : "search", same ? "equal" : "DIFFERENT");
}

static void header(void)
{
    printf("%-34s %8s %9s | %8s | %8s %8s %-7s\n", "op", "visible", "pairs", "op ms", "full ms",
           "update ms", "how");
}

/* One op as the service commits it; the model advances to the result. */
static void run_op(ag_edit_model **em, const ag_edit_op *op, const char *what)
{
    ag_edit_model *out = NULL;
    ag_edit_report rep = {0};
    ag_error err = {0};
    double a = now_ms();
    ag_status s = ag_edit_apply_ex(*em, op, 0, &out, &rep, &err);
    double ms = now_ms() - a;
    ag_edit_report_clear(&rep);
    if (s) {
        printf("%-34s failed: %s\n", what, err.text);
        return;
    }
    row(what, ms, (*em)->proc->tree, out->proc->tree);
    ag_edit_model_free(*em);
    *em = out;
}

static void edit_ops(void)
{
    ag_gen_facade_options go = {.cols = 40, .rows = 20, .side_cols = 30, .back = 1, .left = 1,
                                .annex = 1};
    ag_mesh *m = NULL;
    ag_edit_model *em = NULL;
    ag_error err = {0};
    if (ag_gen_facade(&go, &m, &err) || ag_edit_model_create(m, NULL, &em, &err)) {
        printf("generated building: %s\n", err.text);
        ag_mesh_free(m);
        return;
    }
    printf("\nedit ops on the generated ~200k-triangle building (%zu triangles)\n", m->ntris);
    ag_mesh_free(m);
    header();
    for (int k = 0; k < 6; k++) {
        const ag_splittree *t = em->proc->tree;
        int32_t w[2], wall;
        bench_pick_windows_and_wall(t, w, &wall);
        if (w[0] < 0 || w[1] < 0 || wall < 0) {
            printf("no wall or windows to edit\n");
            break;
        }
        ag_edit_op op = {.kind = AG_EDIT_RESIZE, .mode = AG_EDIT_GLOBAL};
        static const char *const what[6] = {"resize window taller (global)",
                                            "resize front wall 1.5x (global)", "split wall",
                                            "remove window", "paste window", "join 2 windows"};
        switch (k) {
        case 0:
            op.node = w[0];
            op.has_box = 1;
            op.box = t->nodes[w[0]].box;
            op.box.max[2] += 0.2;
            break;
        case 1:
            op.node = wall;
            op.has_scale = 1;
            op.scale[0] = 1.5, op.scale[1] = op.scale[2] = 1;
            break;
        case 2:
            op = (ag_edit_op){.kind = AG_EDIT_SPLIT, .node = wall, .axis = 0,
                              .at = 0.5 * (t->nodes[wall].box.min[0] + t->nodes[wall].box.max[0])};
            break;
        case 3:
            op = (ag_edit_op){.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = &w[0]};
            break;
        case 4:
            op = (ag_edit_op){.kind = AG_EDIT_PASTE, .node = w[1], .nnodes = 1, .nodes = &w[0],
                              .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
            break;
        default:
            op = (ag_edit_op){.kind = AG_EDIT_JOIN, .nnodes = 2, .nodes = w};
        }
        run_op(&em, &op, what[k]);
    }
    ag_edit_model_free(em);
}

static size_t subtree(const ag_splittree *t, int32_t n)
{
    size_t k = t->nodes[n].kind == AG_NODE_COMPONENT;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling)
        k += subtree(t, c);
    return k;
}

/* The visible node with the largest subtree (a facade) and the largest visible leaf (a blank
 * wall), as bench/parts picks them. */
static void pick_facade(const ag_splittree *t, int32_t *big, int32_t *leaf)
{
    size_t best_sub = 0;
    double best_area = 0;
    *big = *leaf = -1;
    for (size_t i = 1; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_COMPONENT)
            continue;
        size_t s = subtree(t, (int32_t)i);
        if (s > best_sub) {
            best_sub = s;
            *big = (int32_t)i;
        }
        double area = fmax(n->box.max[0] - n->box.min[0], n->box.max[1] - n->box.min[1]) *
                      (n->box.max[2] - n->box.min[2]);
        if (n->first_child < 0 && area > best_area) {
            best_area = area;
            *leaf = (int32_t)i;
        }
    }
}

/* The part composed onto r's target and grafted (r advances to the result): ms, or -1. */
static double compose_once(ag_proceduralize_result **r, const ag_part *p, int32_t target)
{
    ag_compose_op op = {.target = target, .mode = AG_COMPOSE_REPLACE, .scope = AG_COMPOSE_NODE};
    ag_compose_report rep;
    ag_grammar *g = NULL;
    ag_mesh *derived = NULL;
    ag_proceduralize_result *out = NULL;
    ag_graft_report gr;
    ag_error err = {0};
    double a = now_ms();
    ag_grammar_derive_options o = {0};
    ag_status s = ag_compose(*r, p, &op, &g, &rep, &err);
    if (!s)
        s = ag_grammar_derive(g, &o, &derived, &err);
    if (!s)
        s = ag_graft_compose(*r, &op, derived, NULL, &out, &gr, &err);
    double ms = now_ms() - a;
    ag_grammar_free(g);
    ag_mesh_free(derived);
    if (s) {
        printf("compose failed: %s\n", err.text);
        return -1;
    }
    ag_proceduralize_result_free(*r);
    *r = out;
    return ms;
}

static void compositions(void)
{
    ag_gen_facade_options go = {.cols = 34, .rows = 20, .side_cols = 26, .left = 1, .bars = 3,
                                .no_groups = 1, .annex = 1};
    ag_mesh *m = NULL;
    ag_proceduralize_result *r = NULL;
    ag_error err = {0};
    if (ag_gen_facade(&go, &m, &err) || ag_proceduralize_run(m, NULL, &r, &err)) {
        printf("parts building: %s\n", err.text);
        ag_mesh_free(m);
        return;
    }
    printf("\nthe facade composed onto the largest blank wall, grafted, on the building of "
           "bench/parts (%zu triangles); 'op ms' = composition, derivation and graft\n",
           m->ntris);
    ag_mesh_free(m);
    int32_t big, leaf;
    pick_facade(r->tree, &big, &leaf);
    ag_part *facade = NULL;
    ag_part_meta meta = {.name = "facade"};
    if (big < 0 || ag_part_extract(r, big, &meta, &facade, &err)) {
        printf("no facade part: %s\n", err.text);
        ag_proceduralize_result_free(r);
        return;
    }
    header();
    for (int k = 1; k <= 11; k++) {
        pick_facade(r->tree, &big, &leaf);
        ag_splittree *before = ag_splittree_copy(r->tree);
        double ms = before && leaf >= 0 ? compose_once(&r, facade, leaf) : -1;
        if (ms < 0) {
            ag_splittree_free(before);
            break;
        }
        char what[64];
        snprintf(what, sizeof what, "composition %d", k);
        row(what, ms, before, r->tree);
        ag_splittree_free(before);
    }
    ag_part_free(facade);
    ag_edit_model *em = NULL;
    if (ag_edit_model_wrap(r, NULL, &em, &err)) {
        printf("no edit model: %s\n", err.text);
        ag_proceduralize_result_free(r);
        return;
    }
    for (int k = 0; k < 3; k++) {
        const ag_splittree *t = em->proc->tree;
        int32_t w[2], wall;
        bench_pick_windows_and_wall(t, w, &wall);
        if (w[0] < 0 || w[1] < 0)
            break;
        ag_edit_op op = {.kind = AG_EDIT_REMOVE, .nnodes = 1, .nodes = &w[0]};
        static const char *const what[3] = {"remove window after 11 comp.",
                                            "paste window after 11 comp.",
                                            "resize window (global) after 11"};
        if (k == 1)
            op = (ag_edit_op){.kind = AG_EDIT_PASTE, .node = w[1], .nnodes = 1, .nodes = &w[0],
                              .placement = AG_EDIT_REPLACE, .fit = AG_EDIT_DERIVE};
        else if (k == 2) {
            op = (ag_edit_op){.kind = AG_EDIT_RESIZE, .mode = AG_EDIT_GLOBAL, .node = w[0],
                              .has_box = 1, .box = t->nodes[w[0]].box};
            op.box.max[2] += 0.2;
        }
        run_op(&em, &op, what[k]);
    }
    ag_edit_model_free(em);
}

int main(void)
{
    ag_heap_keep_large_blocks(); /* as archgramd runs */
    printf("adjacency per op: 'full ms' = the pairs of the result recomputed from scratch (what "
           "every op paid before), 'update ms' = brought up to date from the input's pairs "
           "(checked equal to the full recomputation), each the fastest of %d runs; 'how' = "
           "whether the update searched the changed nodes or started over\n", REPEAT);
    edit_ops();
    compositions();
    return 0;
}
