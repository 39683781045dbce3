/* Parts library timings (figures, not pass/fail): save (ag_part_extract) and compose
 * (ag_compose) on a generated ~200k-triangle building, the core operations a service runs on
 * a proceduralize result in memory. Target: both <= 50 ms. Median of 5 runs each. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/gen_facade.h"
#include "core/parts/compose.h"
#include "core/parts/part.h"
#include "core/proc/proceduralize.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

#define RUNS 5

static size_t subtree(const ag_splittree *t, int32_t n)
{
    size_t k = t->nodes[n].kind == AG_NODE_COMPONENT;
    for (int32_t c = t->nodes[n].first_child; c >= 0; c = t->nodes[c].next_sibling)
        k += subtree(t, c);
    return k;
}

static void bench_save(const ag_proceduralize_result *r, int32_t node, const char *what,
                       ag_part **keep)
{
    double ms[RUNS];
    ag_part_meta meta = {.name = what};
    for (int i = 0; i < RUNS; i++) {
        ag_part *p = NULL;
        ag_error err = {0};
        double t0 = now_ms();
        if (ag_part_extract(r, node, &meta, &p, &err)) {
            fprintf(stderr, "save %s: %s\n", what, err.text);
            exit(1);
        }
        ms[i] = now_ms() - t0;
        if (i == RUNS - 1)
            *keep = p;
        else
            ag_part_free(p);
    }
    qsort(ms, RUNS, sizeof *ms, cmp);
    printf("save    %-34s node %6d, %6zu visible nodes: %8.2f ms (min %.2f)\n", what, (int)node,
           subtree(r->tree, node), ms[RUNS / 2], ms[0]);
}

static void bench_compose(const ag_proceduralize_result *r, const ag_part *p, int32_t target,
                          int mode, int scope, const char *what)
{
    double ms[RUNS];
    ag_compose_report rep;
    for (int i = 0; i < RUNS; i++) {
        ag_compose_op op = {.target = target, .mode = mode, .scope = scope};
        ag_grammar *g = NULL;
        ag_error err = {0};
        double t0 = now_ms();
        if (ag_compose(r, p, &op, &g, &rep, &err)) {
            fprintf(stderr, "compose %s: %s\n", what, err.text);
            exit(1);
        }
        ms[i] = now_ms() - t0;
        ag_grammar_free(g);
    }
    qsort(ms, RUNS, sizeof *ms, cmp);
    printf("compose %-34s %-7s %-4s %6zu instances: %8.2f ms (min %.2f)\n", what,
           ag_compose_mode_name(mode), ag_compose_scope_name(scope), rep.instances, ms[RUNS / 2],
           ms[0]);
}

int main(void)
{
    /* every box its own component: 1720 windows of 9 boxes on three facades, a blank back */
    ag_gen_facade_options go = {.cols = 34, .rows = 20, .side_cols = 26, .left = 1, .bars = 3,
                                .no_groups = 1, .annex = 1};
    ag_mesh *m = NULL;
    ag_error err = {0};
    if (ag_gen_facade(&go, &m, &err)) {
        fprintf(stderr, "generate: %s\n", err.text);
        return 1;
    }
    double t0 = now_ms();
    ag_proceduralize_result *r = NULL;
    if (ag_proceduralize_run(m, NULL, &r, &err)) {
        fprintf(stderr, "proceduralize: %s\n", err.text);
        return 1;
    }
    const ag_splittree *t = r->tree;
    printf("generated building: %zu triangles, %zu components, %zu tree nodes, %zu rules; "
           "proceduralized in %.0f ms (not counted below)\n",
           m->ntris, r->mesh->ncomponents, t->nnodes, r->grammar->nrules, now_ms() - t0);
    /* the most repeated visible node, the node with the largest subtree, the largest leaf */
    int32_t rep = -1, big = -1, leaf = -1;
    size_t best_rep = 0, best_sub = 0;
    double best_area = 0;
    for (size_t i = 1; i < t->nnodes; i++) {
        const ag_tnode *n = &t->nodes[i];
        if (n->kind != AG_NODE_COMPONENT)
            continue;
        if (n->rule >= 0 && t->rule_count[n->rule] > best_rep) {
            best_rep = t->rule_count[n->rule];
            rep = (int32_t)i;
        }
        size_t s = subtree(t, (int32_t)i);
        if (s > best_sub) {
            best_sub = s;
            big = (int32_t)i;
        }
        /* a wall: wide and tall */
        double area = fmax(n->box.max[0] - n->box.min[0], n->box.max[1] - n->box.min[1]) *
                      (n->box.max[2] - n->box.min[2]);
        if (n->first_child < 0 && area > best_area) {
            best_area = area;
            leaf = (int32_t)i;
        }
    }
    /* a facade of another width: the visible node with the second largest subtree */
    int32_t side = -1;
    size_t second = 0;
    for (size_t i = 1; i < t->nnodes; i++) {
        if (t->nodes[i].kind != AG_NODE_COMPONENT || (int32_t)i == big)
            continue;
        size_t s = subtree(t, (int32_t)i);
        double w = t->nodes[i].box.max[0] - t->nodes[i].box.min[0] + t->nodes[i].box.max[1] -
                   t->nodes[i].box.min[1];
        double wb = t->nodes[big].box.max[0] - t->nodes[big].box.min[0] + t->nodes[big].box.max[1] -
                    t->nodes[big].box.min[1];
        if (s > second && w < 0.95 * wb) {
            second = s;
            side = (int32_t)i;
        }
    }
    ag_part *small = NULL, *facade = NULL;
    bench_save(r, rep, "a window piece (most repeated)", &small);
    bench_save(r, big, "a facade with its windows", &facade);
    bench_compose(r, small, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_RULE, "window piece into its rule");
    bench_compose(r, small, rep, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "window piece into one node");
    bench_compose(r, small, big, AG_COMPOSE_INSERT, AG_COMPOSE_NODE, "window piece under a facade");
    bench_compose(r, small, leaf, AG_COMPOSE_FILL, AG_COMPOSE_NODE, "window piece filling a wall");
    bench_compose(r, facade, leaf, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "facade onto the blank wall");
    bench_compose(r, facade, side, AG_COMPOSE_REPLACE, AG_COMPOSE_NODE, "facade onto a narrower wall");
    ag_part_free(small);
    ag_part_free(facade);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return 0;
}
