#include "trace.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const ag_grammar *g;
    ag_trace *t;
    size_t cap_inst, cap_sites, max_inst;
    ag_status st;
    ag_error *err;
} tctx;

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 64;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, n * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

static ag_box world_box(const ag_gframe *F, const ag_box *b)
{
    double p[3], q[3];
    ag_box w;
    for (int c = 0; c < 8; c++) {
        for (int a = 0; a < 3; a++)
            p[a] = (c >> a) & 1 ? b->max[a] : b->min[a];
        ag_gframe_apply(F, p, q);
        for (int a = 0; a < 3; a++) {
            if (c == 0 || q[a] < w.min[a])
                w.min[a] = q[a];
            if (c == 0 || q[a] > w.max[a])
                w.max[a] = q[a];
        }
    }
    return w;
}

const ag_grule *ag_trace_body(const ag_grammar *g, const ag_trace_instance *in)
{
    return in->rule < 0 ? &g->axiom : &g->rules[in->rule];
}

static int32_t visit(tctx *x, int32_t rule, int32_t parent, int32_t stmt, uint32_t cell,
                     int rot, const ag_gframe *F, const ag_box *p, uint32_t depth)
{
    ag_trace *t = x->t;
    if (x->st)
        return -1;
    if (t->ninstances >= x->max_inst) {
        x->st = ag_error_set(x->err, AG_ERR_TOO_LARGE, 0,
                             "the grammar applies more than %zu rules", x->max_inst);
        return -1;
    }
    if (depth > 512) {
        x->st = ag_error_set(x->err, AG_ERR_TOO_LARGE, 0, "rules are nested more than 512 deep");
        return -1;
    }
    const ag_grule *r = rule < 0 ? &x->g->axiom : &x->g->rules[rule];
    size_t nn = r->nnodes ? r->nnodes : 1;
    if (grow((void **)&t->inst, &x->cap_inst, t->ninstances + 1, sizeof *t->inst) ||
        grow((void **)&t->local, &x->cap_sites, t->nsites + nn, sizeof *t->local)) {
        x->st = ag_error_set(x->err, AG_ERR_NOMEM, 0, "out of memory");
        return -1;
    }
    size_t cap = x->cap_sites;
    ag_box *w = realloc(t->world, cap * sizeof *w);
    if (!w) {
        x->st = ag_error_set(x->err, AG_ERR_NOMEM, 0, "out of memory");
        return -1;
    }
    t->world = w;
    int32_t me = (int32_t)t->ninstances++;
    ag_trace_instance *in = &t->inst[me];
    *in = (ag_trace_instance){.rule = rule, .parent = parent, .stmt = stmt, .cell = cell,
                              .rot = rot & 3, .depth = depth, .frame = *F, .site0 = t->nsites,
                              .first_child = -1, .next_sibling = -1};
    size_t s0 = t->nsites;
    t->nsites += nn;
    t->local[s0] = *p;
    for (size_t i = 1; i < nn; i++)
        t->local[s0 + i] = *p;
    if (rule >= 0)
        t->uses[rule]++;
    size_t terminals = 0;
    int32_t last = -1;
    for (size_t i = 0; i < r->nstmts && !x->st; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            t->local[s0 + s->node_ix] =
                ag_splittree_child_box(&t->local[s0 + s->parent_ix], s->v, s->octant);
            continue;
        }
        ag_box B = t->local[s0 + s->node_ix];
        uint32_t cells[3] = {1, 1, 1};
        ag_gframe_cells gc;
        if (s->subdivide) {
            ag_gframe_cells_of(s, &B, &gc);
            memcpy(cells, s->counts, sizeof cells);
        }
        uint32_t ci = 0;
        for (uint32_t k = 0; k < cells[2] && !x->st; k++)
            for (uint32_t j = 0; j < cells[1] && !x->st; j++)
                for (uint32_t c = 0; c < cells[0] && !x->st; c++, ci++) {
                    if (!s->callee_is_rule) {
                        terminals++;
                        continue;
                    }
                    ag_box cb = s->subdivide ? ag_gframe_cell(&gc, c, j, k) : B;
                    const ag_grule *cr = &x->g->rules[s->callee_ix];
                    ag_gframe G = ag_gframe_place(F, cr->size, s->rot, &cb);
                    ag_box lb = {{0, 0, 0}, {cr->size[0], cr->size[1], cr->size[2]}};
                    int32_t ch = visit(x, s->callee_ix, me, (int32_t)i, ci, rot + s->rot, &G, &lb,
                                       depth + 1);
                    if (ch < 0)
                        break;
                    /* t->inst may have moved */
                    if (last < 0)
                        t->inst[me].first_child = ch;
                    else
                        t->inst[last].next_sibling = ch;
                    last = ch;
                    terminals += t->inst[ch].terminals;
                }
    }
    t->inst[me].terminals = terminals;
    const ag_gframe Fc = t->inst[me].frame;
    for (size_t i = 0; i < nn; i++)
        t->world[s0 + i] = world_box(&Fc, &t->local[s0 + i]);
    return me;
}

ag_status ag_trace_build(const ag_grammar *g, size_t max_instances, ag_trace **out,
                         ag_error *err)
{
    *out = NULL;
    if (!g->has_axiom)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the grammar has no axiom");
    ag_trace *t = calloc(1, sizeof *t);
    if (!t || !(t->uses = calloc(g->nrules + 1, sizeof *t->uses))) {
        free(t);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    t->nrules = g->nrules;
    tctx x = {.g = g, .t = t, .max_inst = max_instances ? max_instances : 5000000, .err = err};
    visit(&x, -1, -1, -1, 0, 0, &ag_gframe_identity, &g->axiom.box, 0);
    if (x.st) {
        ag_trace_free(t);
        return x.st;
    }
    *out = t;
    return AG_OK;
}

void ag_trace_free(ag_trace *t)
{
    if (!t)
        return;
    free(t->inst);
    free(t->local);
    free(t->world);
    free(t->uses);
    free(t);
}

size_t ag_trace_site_terminals(const ag_trace *t, const ag_grammar *g, ag_trace_site s)
{
    const ag_trace_instance *in = &t->inst[s.instance];
    if (s.node == 0)
        return in->terminals;
    const ag_grule *r = ag_trace_body(g, in);
    /* which body nodes lie below s.node: one pass, splits define nodes in order */
    uint8_t stackmark[256];
    uint8_t *below = r->nnodes <= sizeof stackmark ? stackmark : calloc(r->nnodes, 1);
    if (!below)
        return (size_t)-1;
    memset(below, 0, r->nnodes);
    below[s.node] = 1;
    for (size_t i = 0; i < r->nstmts; i++)
        if (r->stmts[i].kind == AG_GSTMT_SPLIT && below[r->stmts[i].parent_ix])
            below[r->stmts[i].node_ix] = 1;
    size_t n = 0;
    for (size_t i = 0; i < r->nstmts; i++) {
        const ag_gstmt *st = &r->stmts[i];
        if (st->kind == AG_GSTMT_APPLY && below[st->node_ix] && !st->callee_is_rule)
            n += st->subdivide ? (size_t)st->counts[0] * st->counts[1] * st->counts[2] : 1;
    }
    /* rules applied below the node: their instances, one pass over the children */
    for (int32_t c = in->first_child; c >= 0; c = t->inst[c].next_sibling)
        if (below[r->stmts[t->inst[c].stmt].node_ix])
            n += t->inst[c].terminals;
    if (below != stackmark)
        free(below);
    return n;
}

static size_t subtree_components(const ag_splittree *tr, int32_t node)
{
    size_t n = 0;
    int32_t stack[512];
    size_t sp = 0;
    int32_t *st = stack;
    int32_t *heap = NULL;
    size_t cap = 512;
    st[sp++] = node;
    while (sp) {
        int32_t v = st[--sp];
        n += tr->nodes[v].kind == AG_NODE_COMPONENT && tr->nodes[v].component >= 0;
        for (int32_t c = tr->nodes[v].first_child; c >= 0; c = tr->nodes[c].next_sibling) {
            if (sp == cap) {
                int32_t *h = realloc(heap, 2 * cap * sizeof *h);
                if (!h) {
                    free(heap);
                    return (size_t)-1;
                }
                if (!heap)
                    memcpy(h, stack, sizeof stack);
                heap = h;
                st = heap;
                cap *= 2;
            }
            st[sp++] = c;
        }
    }
    free(heap);
    return n;
}

static int box_near(const ag_box *a, const ag_box *b, double tol)
{
    for (int k = 0; k < 3; k++)
        if (fabs(a->min[k] - b->min[k]) > tol || fabs(a->max[k] - b->max[k]) > tol)
            return 0;
    return 1;
}

ag_status ag_trace_find_node(const ag_trace *t, const ag_grammar *g,
                             const ag_proceduralize_result *r, int32_t node, ag_trace_site *out,
                             ag_error *err)
{
    const ag_splittree *tr = r->tree;
    if (node < 0 || (size_t)node >= tr->nnodes || tr->nodes[node].kind == AG_NODE_DEAD)
        return ag_error_set(err, AG_ERR_NOT_FOUND, node, "node %d is not a node of the tree "
                            "(it has %zu)", (int)node, tr->nnodes);
    if (node == 0) {
        *out = (ag_trace_site){0, 0};
        return AG_OK;
    }
    const ag_box *B = &tr->nodes[node].box;
    double tol = 1e-7 * ag_box_diagonal(&tr->nodes[0].box) + tr->eps;
    size_t want = subtree_components(tr, node);
    if (want == (size_t)-1)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    int found = 0;
    ag_trace_site best = {0, 0};
    uint32_t best_depth = 0;
    for (size_t i = 0; i < t->ninstances; i++) {
        const ag_trace_instance *in = &t->inst[i];
        if (found && in->depth >= best_depth)
            continue;
        const ag_grule *body = ag_trace_body(g, in);
        size_t nn = body->nnodes ? body->nnodes : 1;
        /* the last body node of a split chain with this box is the one its content hangs on */
        for (size_t j = nn; j-- > 0;) {
            if (!box_near(&t->world[in->site0 + j], B, tol))
                continue;
            ag_trace_site s = {(int32_t)i, (int32_t)j};
            if (ag_trace_site_terminals(t, g, s) != want)
                continue;
            best = s;
            best_depth = in->depth;
            found = 1;
            break;
        }
    }
    if (!found)
        return ag_error_set(err, AG_ERR_NOT_FOUND, node,
                            "node %d has no statement of the grammar that places its %zu "
                            "components",
                            (int)node, want);
    *out = best;
    return AG_OK;
}
