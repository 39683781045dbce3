#include "gcopy.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ag_status ag_gcopy_stmt(ag_grule *r, const ag_gstmt *s, const char *node, const char *parent,
                        const char *callee)
{
    node = node ? node : s->node;
    if (s->kind == AG_GSTMT_SPLIT)
        return ag_grammar_add_split(r, node, parent ? parent : s->parent, s->v, s->octant, 0, 0);
    callee = callee ? callee : s->callee;
    if (s->subdivide == 2)
        return ag_grammar_add_repeat(r, callee, node, s->rot, s->nvec, s->counts,
                                     (const double(*)[3])s->vec, 0, 0);
    return ag_grammar_add_apply(r, callee, node, s->rot, s->subdivide ? s->counts : NULL,
                                s->subdivide ? s->step : NULL, 0, 0);
}

ag_status ag_gcopy_insert_rule(ag_grammar *g, size_t at, const char *name, const double size[3],
                               ag_grule **out)
{
    size_t ix;
    ag_status st = ag_grammar_add_rule(g, name, size, &ix);
    if (st)
        return st;
    if (at > ix)
        at = ix;
    ag_grule r = g->rules[ix];
    memmove(&g->rules[at + 1], &g->rules[at], (ix - at) * sizeof r);
    g->rules[at] = r;
    if (out)
        *out = &g->rules[at];
    return AG_OK;
}

ag_status ag_gcopy_terminal(ag_grammar *g, const ag_gterminal *t, const char *name)
{
    size_t ix;
    ag_status st = ag_grammar_add_terminal(g, name, t->size, &ix);
    if (st)
        return st;
    ag_gterminal *d = &g->terminals[ix];
    d->label = t->label;
    if ((t->label_name && !(d->label_name = strdup(t->label_name))) ||
        (t->path && !(d->path = strdup(t->path))))
        return AG_ERR_NOMEM;
    if (t->pos)
        return ag_grammar_set_terminal_geometry(d, t->pos, t->nverts, t->tri, t->ntris);
    return AG_OK;
}

static ag_status copy_rule_body(ag_grule *d, const ag_grule *s)
{
    for (size_t i = 0; i < s->nstmts; i++) {
        ag_status st = ag_gcopy_stmt(d, &s->stmts[i], NULL, NULL, NULL);
        if (st)
            return st;
    }
    return AG_OK;
}

ag_status ag_gcopy_grammar(const ag_grammar *g, ag_grammar **out, ag_error *err)
{
    *out = NULL;
    ag_grammar *c = ag_grammar_create();
    ag_status st = c ? AG_OK : AG_ERR_NOMEM;
    for (size_t i = 0; i < g->nterminals && !st; i++)
        st = ag_gcopy_terminal(c, &g->terminals[i], g->terminals[i].name);
    for (size_t i = 0; i < g->nrules && !st; i++) {
        size_t ix;
        st = ag_grammar_add_rule(c, g->rules[i].name, g->rules[i].size, &ix);
        if (!st)
            st = copy_rule_body(&c->rules[ix], &g->rules[i]);
    }
    if (!st && g->has_axiom) {
        c->has_axiom = 1;
        c->axiom.box = g->axiom.box;
        st = copy_rule_body(&c->axiom, &g->axiom);
    }
    if (st) {
        ag_grammar_free(c);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    long col;
    if ((st = ag_grammar_resolve(c, err, &col))) {
        ag_grammar_free(c);
        return st;
    }
    *out = c;
    return AG_OK;
}

int32_t ag_gcopy_find(const ag_grammar *g, const char *name, int *is_rule)
{
    for (size_t i = 0; i < g->nrules; i++)
        if (!strcmp(g->rules[i].name, name)) {
            if (is_rule)
                *is_rule = 1;
            return (int32_t)i;
        }
    for (size_t i = 0; i < g->nterminals; i++)
        if (!strcmp(g->terminals[i].name, name)) {
            if (is_rule)
                *is_rule = 0;
            return (int32_t)i;
        }
    return -1;
}

static int taken(const ag_grammar *g, const char *name)
{
    return g && ag_gcopy_find(g, name, NULL) >= 0;
}

void ag_gcopy_unique_name(const ag_grammar *a, const ag_grammar *b, const ag_grammar *c,
                          const char *want, char out[64])
{
    snprintf(out, 64, "%.63s", want);
    for (unsigned k = 2; taken(a, out) || taken(b, out) || taken(c, out); k++)
        snprintf(out, 64, "%.50s_%u", want, k);
}

void ag_gcopy_identifier(const char *text, char out[64])
{
    size_t n = 0;
    if (text && text[0] >= '0' && text[0] <= '9')
        out[n++] = '_';
    for (const char *s = text; s && *s && n < 40; s++) {
        char ch = *s;
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                 (ch >= '0' && ch <= '9') || ch == '_';
        out[n++] = ok ? ch : '_';
    }
    out[n] = 0;
    if (!n)
        snprintf(out, 64, "part");
}

void ag_gcopy_mark_reachable(const ag_grammar *g, const ag_grule *r, uint8_t *rules,
                             uint8_t *terminals)
{
    /* rules are declared before use: every rule r reaches has a smaller index, so one pass
     * downwards over the marked rules reaches everything (no recursion, whatever the depth) */
    size_t top = 0;
    for (size_t i = 0; i < r->nstmts; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind != AG_GSTMT_APPLY || s->callee_ix < 0)
            continue;
        if (!s->callee_is_rule) {
            terminals[s->callee_ix] = 1;
        } else {
            rules[s->callee_ix] = 1;
            if ((size_t)s->callee_ix + 1 > top)
                top = (size_t)s->callee_ix + 1;
        }
    }
    for (size_t k = top; k-- > 0;) {
        if (!rules[k])
            continue;
        const ag_grule *q = &g->rules[k];
        for (size_t i = 0; i < q->nstmts; i++) {
            const ag_gstmt *s = &q->stmts[i];
            if (s->kind != AG_GSTMT_APPLY || s->callee_ix < 0)
                continue;
            if (s->callee_is_rule)
                rules[s->callee_ix] = 1;
            else
                terminals[s->callee_ix] = 1;
        }
    }
}

typedef struct {
    const char *name;
    size_t index;
} named;

static int by_name(const void *a, const void *b)
{
    return strcmp(((const named *)a)->name, ((const named *)b)->name);
}

ag_status ag_gcopy_sort_rules(ag_grammar *g, ag_error *err)
{
    size_t n = g->nrules;
    named *idx = malloc((n + 1) * sizeof *idx);
    uint8_t *state = calloc(n + 1, 1); /* 0 new, 1 on the stack, 2 placed */
    size_t *order = malloc((n + 1) * sizeof *order);
    /* an explicit stack of (rule, next statement) */
    size_t *stack = malloc((2 * n + 2) * sizeof *stack);
    ag_grule *sorted = malloc((n + 1) * sizeof *sorted);
    ag_status st = AG_OK;
    if (!idx || !state || !order || !stack || !sorted) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        idx[i] = (named){g->rules[i].name, i};
    qsort(idx, n, sizeof *idx, by_name);
    size_t placed = 0;
    for (size_t root = 0; root < n && !st; root++) {
        if (state[root])
            continue;
        size_t sp = 0;
        stack[sp++] = root;
        stack[sp++] = 0;
        state[root] = 1;
        while (sp && !st) {
            size_t r = stack[sp - 2], k = stack[sp - 1];
            const ag_grule *rule = &g->rules[r];
            if (k == rule->nstmts) {
                state[r] = 2;
                order[placed++] = r;
                sp -= 2;
                continue;
            }
            stack[sp - 1] = k + 1;
            const ag_gstmt *s = &rule->stmts[k];
            if (s->kind != AG_GSTMT_APPLY)
                continue;
            named key = {s->callee, 0};
            named *f = bsearch(&key, idx, n, sizeof *idx, by_name);
            if (!f)
                continue;
            if (state[f->index] == 1)
                st = ag_error_set(err, AG_ERR_INVALID, 0, "rule '%s' applies itself through '%s'",
                                  g->rules[f->index].name, rule->name);
            else if (!state[f->index]) {
                state[f->index] = 1;
                stack[sp++] = f->index;
                stack[sp++] = 0;
            }
        }
    }
    if (!st) {
        for (size_t i = 0; i < n; i++)
            sorted[i] = g->rules[order[i]];
        memcpy(g->rules, sorted, n * sizeof *sorted);
    }
done:
    free(idx);
    free(state);
    free(order);
    free(stack);
    free(sorted);
    return st;
}
