#include "compose.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../edit/place.h"
#include "gcopy.h"
#include "trace.h"

int ag_compose_mode_parse(const char *s)
{
    return !s ? -1 : !strcmp(s, "replace") ? AG_COMPOSE_REPLACE
                   : !strcmp(s, "insert")  ? AG_COMPOSE_INSERT
                   : !strcmp(s, "fill")    ? AG_COMPOSE_FILL
                                           : -1;
}

int ag_compose_scope_parse(const char *s)
{
    return !s ? -1 : !strcmp(s, "node") ? AG_COMPOSE_NODE : !strcmp(s, "rule") ? AG_COMPOSE_RULE : -1;
}

const char *ag_compose_mode_name(int mode)
{
    return mode == AG_COMPOSE_REPLACE ? "replace" : mode == AG_COMPOSE_INSERT ? "insert"
                                      : mode == AG_COMPOSE_FILL ? "fill" : "?";
}

const char *ag_compose_scope_name(int scope)
{
    return scope == AG_COMPOSE_NODE ? "node" : scope == AG_COMPOSE_RULE ? "rule" : "?";
}

/* ---- body surgery ------------------------------------------------------------------------ */

static void free_stmt(ag_gstmt *s)
{
    free(s->node);
    free(s->parent);
    free(s->callee);
}

static void free_body(ag_grule *r)
{
    for (size_t i = 0; i < r->nstmts; i++)
        free_stmt(&r->stmts[i]);
    free(r->stmts);
    r->stmts = NULL;
    r->nstmts = r->cap = 0;
}

/* Drops the statements marked in drop. */
static void body_drop(ag_grule *r, const uint8_t *drop)
{
    size_t k = 0;
    for (size_t i = 0; i < r->nstmts; i++) {
        if (drop[i])
            free_stmt(&r->stmts[i]);
        else
            r->stmts[k++] = r->stmts[i];
    }
    r->nstmts = k;
}

/* Replaces statement `at` of r by the statements of `with` (emptied). */
static ag_status body_splice(ag_grule *r, size_t at, ag_grule *with)
{
    size_t n = r->nstmts - 1 + with->nstmts;
    ag_gstmt *s = malloc((n + 1) * sizeof *s);
    if (!s)
        return AG_ERR_NOMEM;
    memcpy(s, r->stmts, at * sizeof *s);
    memcpy(s + at, with->stmts, with->nstmts * sizeof *s);
    memcpy(s + at + with->nstmts, r->stmts + at + 1, (r->nstmts - at - 1) * sizeof *s);
    free_stmt(&r->stmts[at]);
    free(r->stmts);
    r->stmts = s;
    r->nstmts = r->cap = n;
    free(with->stmts);
    with->stmts = NULL;
    with->nstmts = with->cap = 0;
    return AG_OK;
}

/* A node name not used in r: prefix + counter. */
static void fresh_node(const ag_grule *r, const char *prefix, unsigned *counter, char out[24])
{
    for (;;) {
        snprintf(out, 24, "%s%u", prefix, ++*counter);
        int used = !strcmp(out, "p");
        for (size_t i = 0; i < r->nstmts && !used; i++)
            used = r->stmts[i].kind == AG_GSTMT_SPLIT && !strcmp(r->stmts[i].node, out);
        if (!used)
            return;
    }
}

/* Two splits from `from` (box F, local) to box b: the node is named in out. */
static ag_status split_to(ag_grule *dst, const ag_grule *names, const char *from, const ag_box *F,
                          const ag_box *b, unsigned *counter, char out[24])
{
    char a[24];
    fresh_node(names, "q", counter, a);
    /* the second name must differ from the first and from the body's */
    do
        fresh_node(names, "q", counter, out);
    while (!strcmp(out, a));
    double v1[3], v2[3];
    for (int k = 0; k < 3; k++) {
        v1[k] = b->min[k] - F->min[k];
        v2[k] = b->max[k] - b->min[k];
    }
    ag_status st = ag_grammar_add_split(dst, a, from, v1, 8, 0, 0);
    return st ? st : ag_grammar_add_split(dst, out, a, v2, 1, 0, 0);
}

static const char *node_name(const ag_grule *r, int32_t node)
{
    if (node == 0)
        return "p";
    for (size_t i = 0; i < r->nstmts; i++)
        if (r->stmts[i].kind == AG_GSTMT_SPLIT && r->stmts[i].node_ix == node)
            return r->stmts[i].node;
    return NULL;
}

static ag_grule *rule_named(ag_grammar *g, const char *name)
{
    if (!name)
        return &g->axiom;
    int is_rule = 0;
    int32_t i = ag_gcopy_find(g, name, &is_rule);
    return i >= 0 && is_rule ? &g->rules[i] : NULL;
}

static int32_t rule_index(const ag_grammar *g, const char *name)
{
    int is_rule = 0;
    int32_t i = ag_gcopy_find(g, name, &is_rule);
    return i >= 0 && is_rule ? i : -1;
}

/* ---- instantiation of the part ----------------------------------------------------------- */

static int same_terminal(const ag_gterminal *a, const ag_gterminal *b)
{
    if (a->nverts != b->nverts || a->ntris != b->ntris || !a->pos || !b->pos)
        return 0;
    for (int k = 0; k < 3; k++)
        if (fabs(a->size[k] - b->size[k]) > 1e-12)
            return 0;
    for (size_t i = 0; i < 3 * a->nverts; i++)
        if (fabs(a->pos[i] - b->pos[i]) > 1e-12)
            return 0;
    return !memcmp(a->tri, b->tri, 3 * a->ntris * sizeof *a->tri);
}

/* Body a (callees renamed through map) equals body b. */
static int same_body(const ag_grule *a, const ag_grule *b, char **map_from, char **map_to,
                     size_t nmap)
{
    if (a->nstmts != b->nstmts)
        return 0;
    for (int k = 0; k < 3; k++)
        if (fabs(a->size[k] - b->size[k]) > 1e-12)
            return 0;
    for (size_t i = 0; i < a->nstmts; i++) {
        const ag_gstmt *s = &a->stmts[i], *t = &b->stmts[i];
        if (s->kind != t->kind || strcmp(s->node, t->node))
            return 0;
        if (s->kind == AG_GSTMT_SPLIT) {
            if (strcmp(s->parent, t->parent) || s->octant != t->octant ||
                memcmp(s->v, t->v, sizeof s->v))
                return 0;
            continue;
        }
        const char *callee = s->callee;
        for (size_t m = 0; m < nmap; m++)
            if (!strcmp(map_from[m], callee)) {
                callee = map_to[m];
                break;
            }
        if (strcmp(callee, t->callee) || s->rot != t->rot || s->subdivide != t->subdivide ||
            memcmp(s->counts, t->counts, sizeof s->counts) || memcmp(s->step, t->step, sizeof s->step) ||
            s->nvec != t->nvec || memcmp(s->vec, t->vec, sizeof s->vec))
            return 0;
    }
    return 1;
}

typedef struct {
    char **from, **to;
    size_t n;
} namemap;

static ag_status map_add(namemap *m, const char *from, const char *to)
{
    char **f = realloc(m->from, (m->n + 1) * sizeof *f);
    if (!f)
        return AG_ERR_NOMEM;
    m->from = f;
    char **t = realloc(m->to, (m->n + 1) * sizeof *t);
    if (!t)
        return AG_ERR_NOMEM;
    m->to = t;
    m->from[m->n] = strdup(from);
    m->to[m->n] = strdup(to);
    m->n++;
    return m->from[m->n - 1] && m->to[m->n - 1] ? AG_OK : AG_ERR_NOMEM;
}

static const char *map_get(const namemap *m, const char *from)
{
    for (size_t i = 0; i < m->n; i++)
        if (!strcmp(m->from[i], from))
            return m->to[i];
    return from;
}

static void map_free(namemap *m)
{
    for (size_t i = 0; i < m->n; i++) {
        free(m->from[i]);
        free(m->to[i]);
    }
    free(m->from);
    free(m->to);
}

/* Brings the part's rules and terminals that `fitted` reaches into W (rules at *at, advancing
 * it), sharing identical ones; renames fitted's callees. */
static ag_status instantiate(ag_grammar *W, const ag_part *part, ag_grule *fitted, size_t *at,
                             const char *ident, const char *body, ag_compose_report *rep,
                             namemap *map)
{
    /* never share a rule that reaches the rewritten body: it would come to apply itself */
    uint8_t *noshare = calloc(W->nrules + 1, 1);
    if (!noshare)
        return AG_ERR_NOMEM;
    if (body && body[0]) {
        int32_t b = rule_index(W, body);
        if (b >= 0) {
            noshare[b] = 1;
            /* rules are in declare-before-use order: one pass upwards */
            for (size_t i = (size_t)b + 1; i < W->nrules; i++)
                for (size_t k = 0; k < W->rules[i].nstmts && !noshare[i]; k++) {
                    const ag_gstmt *s = &W->rules[i].stmts[k];
                    int32_t c = s->kind == AG_GSTMT_APPLY && s->callee_is_rule ? s->callee_ix : -1;
                    if (c >= 0 && (size_t)c < W->nrules && noshare[c])
                        noshare[i] = 1;
                }
        }
    }
    size_t nshareable = W->nrules;
    const ag_grammar *P = part->grammar;
    uint8_t *rules = calloc(P->nrules + 1, 1), *terms = calloc(P->nterminals + 1, 1);
    if (!rules || !terms) {
        free(rules);
        free(terms);
        return AG_ERR_NOMEM;
    }
    /* fitted's callees are P's names: resolve them to walk what they reach */
    for (size_t i = 0; i < fitted->nstmts; i++) {
        ag_gstmt *s = &fitted->stmts[i];
        if (s->kind == AG_GSTMT_APPLY) {
            int is_rule = 0;
            s->callee_ix = ag_gcopy_find(P, s->callee, &is_rule);
            s->callee_is_rule = is_rule;
        }
    }
    ag_gcopy_mark_reachable(P, fitted, rules, terms);
    ag_status st = AG_OK;
    char name[64];
    for (size_t i = 0; i < P->nterminals && !st; i++) {
        if (!terms[i])
            continue;
        const ag_gterminal *t = &P->terminals[i];
        int32_t same = -1;
        for (size_t k = 0; k < W->nterminals && same < 0; k++)
            if (same_terminal(t, &W->terminals[k]))
                same = (int32_t)k;
        if (same >= 0) {
            rep->terminals_shared++;
            st = map_add(map, t->name, W->terminals[same].name);
            continue;
        }
        ag_gcopy_unique_name(W, NULL, NULL, t->name, name);
        rep->renamed += strcmp(name, t->name) != 0;
        if ((st = ag_gcopy_terminal(W, t, name)))
            break;
        ag_gterminal *d = &W->terminals[W->nterminals - 1];
        char label[64];
        snprintf(label, sizeof label, "%.30s_%.30s", ident, t->label_name ? t->label_name : t->name);
        free(d->label_name);
        if (!(d->label_name = strdup(label)))
            st = AG_ERR_NOMEM;
        rep->terminals_added++;
        if (!st)
            st = map_add(map, t->name, name);
    }
    for (size_t i = 0; i < P->nrules && !st; i++) {
        if (!rules[i])
            continue;
        const ag_grule *r = &P->rules[i];
        int32_t same = -1;
        /* target rules keep their indices until the part's are inserted in front of them */
        for (size_t k = 0; k < nshareable && same < 0; k++)
            if (!noshare[k] && same_body(r, &W->rules[*at + k], map->from, map->to, map->n))
                same = (int32_t)(*at + k);
        if (same >= 0) {
            rep->rules_shared++;
            st = map_add(map, r->name, W->rules[same].name);
            continue;
        }
        ag_gcopy_unique_name(W, NULL, NULL, r->name, name);
        rep->renamed += strcmp(name, r->name) != 0;
        ag_grule *d;
        if ((st = ag_gcopy_insert_rule(W, (*at)++, name, r->size, &d)))
            break;
        for (size_t k = 0; k < r->nstmts && !st; k++)
            st = ag_gcopy_stmt(d, &r->stmts[k], NULL, NULL,
                               r->stmts[k].kind == AG_GSTMT_APPLY ? map_get(map, r->stmts[k].callee)
                                                                  : NULL);
        rep->rules_added++;
        if (!st)
            st = map_add(map, r->name, name);
    }
    for (size_t i = 0; i < fitted->nstmts && !st; i++) {
        ag_gstmt *s = &fitted->stmts[i];
        if (s->kind != AG_GSTMT_APPLY)
            continue;
        char *c = strdup(map_get(map, s->callee));
        if (!c) {
            st = AG_ERR_NOMEM;
            break;
        }
        free(s->callee);
        s->callee = c;
    }
    free(rules);
    free(terms);
    free(noshare);
    return st;
}

/* ---- the composition ------------------------------------------------------------------- */

typedef struct {
    const ag_trace *t;
    const ag_grammar *g;
    int32_t inst, node;
} site_ref;

/* The statements under a site: marks below[] (body nodes) and returns how many there are;
 * *only is the single statement when there is exactly one. */
static size_t under(const ag_grule *r, int32_t node, uint8_t *below, int32_t *only)
{
    memset(below, 0, r->nnodes ? r->nnodes : 1);
    below[node] = 1;
    size_t n = 0;
    *only = -1;
    for (size_t i = 0; i < r->nstmts; i++) {
        const ag_gstmt *s = &r->stmts[i];
        int in = s->kind == AG_GSTMT_SPLIT ? below[s->parent_ix] : below[s->node_ix];
        if (s->kind == AG_GSTMT_SPLIT && in)
            below[s->node_ix] = 1;
        if (in) {
            n++;
            *only = (int32_t)i;
        }
    }
    return n;
}

static int32_t child_of(const ag_trace *t, int32_t inst, int32_t stmt)
{
    for (int32_t c = t->inst[inst].first_child; c >= 0; c = t->inst[c].next_sibling)
        if (t->inst[c].stmt == stmt)
            return c;
    return -1;
}

ag_status ag_compose(const ag_proceduralize_result *target, const ag_part *part,
                     const ag_compose_op *op, ag_grammar **out, ag_compose_report *rep,
                     ag_error *err)
{
    return ag_compose_traced(target, NULL, part, op, out, rep, err);
}

ag_status ag_compose_traced(const ag_proceduralize_result *target, const ag_trace *trace,
                            const ag_part *part, const ag_compose_op *op, ag_grammar **out,
                            ag_compose_report *rep, ag_error *err)
{
    *out = NULL;
    ag_compose_report local;
    if (!rep)
        rep = &local;
    memset(rep, 0, sizeof *rep);
    if (op->mode < AG_COMPOSE_REPLACE || op->mode > AG_COMPOSE_FILL)
        return ag_error_set(err, AG_ERR_INVALID, 0, "mode: must be replace, insert or fill");
    if (op->scope != AG_COMPOSE_NODE && op->scope != AG_COMPOSE_RULE)
        return ag_error_set(err, AG_ERR_INVALID, 0, "scope: must be node or rule");
    ag_status st = ag_place_check_node(target, op->target, "target", err);
    if (st)
        return st;
    if ((st = ag_part_validate(part, err)))
        return st;
    const ag_grammar *g = target->grammar;
    const ag_splittree *tree = target->tree;
    ag_trace *own = NULL; /* the trace made here, when none is given */
    ag_grammar *W = NULL;
    uint8_t *below = NULL;
    ag_grule fitted = {0}, tmp = {0};
    namemap map = {0};
    if (!trace && (st = ag_trace_build(g, 0, &own, err)))
        return st;
    const ag_trace *t = trace ? trace : own;
    ag_trace_site site;
    if ((st = ag_trace_find_node(t, g, target, op->target, &site, err)))
        goto done;
    size_t maxn = 1;
    for (size_t i = 0; i < g->nrules; i++)
        maxn = g->rules[i].nnodes > maxn ? g->rules[i].nnodes : maxn;
    maxn = g->axiom.nnodes > maxn ? g->axiom.nnodes : maxn;
    below = malloc(maxn + 64);
    if (!below || (st = ag_gcopy_grammar(g, &W, err))) {
        st = st ? st : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }

    /* the content site: through rules that only wrap the target */
    ag_trace_site content = site;
    for (;;) {
        const ag_grule *body = ag_trace_body(g, &t->inst[content.instance]);
        int32_t only;
        if (under(body, content.node, below, &only) != 1)
            break;
        const ag_gstmt *s = &body->stmts[only];
        if (s->kind != AG_GSTMT_APPLY || !s->callee_is_rule || s->subdivide ||
            s->node_ix != content.node)
            break;
        int32_t c = child_of(t, content.instance, only);
        if (c < 0)
            break;
        content = (ag_trace_site){c, 0};
    }
    ag_trace_site work = op->scope == AG_COMPOSE_NODE && op->mode == AG_COMPOSE_REPLACE ? site : content;
    const ag_trace_instance *wi = &t->inst[work.instance];
    int rc = wi->rot; /* the frame the new statements live in */
    ag_box L = t->local[wi->site0 + work.node];
    char body_name[64] = ""; /* "" = the axiom */
    int32_t body_node = work.node;

    if (op->scope == AG_COMPOSE_RULE) {
        const ag_grule *cb = ag_trace_body(g, &t->inst[content.instance]);
        int32_t only;
        size_t nu = under(cb, content.node, below, &only);
        if (content.node == 0 && t->inst[content.instance].rule >= 0) {
            int32_t R = t->inst[content.instance].rule;
            snprintf(body_name, sizeof body_name, "%s", g->rules[R].name);
            rep->instances = t->uses[R];
            rc = t->inst[content.instance].rot;
            L = (ag_box){{0, 0, 0}, {g->rules[R].size[0], g->rules[R].size[1], g->rules[R].size[2]}};
            body_node = 0;
        } else if (nu == 1 && cb->stmts[only].kind == AG_GSTMT_APPLY &&
                   !cb->stmts[only].callee_is_rule && !cb->stmts[only].subdivide &&
                   cb->stmts[only].node_ix == content.node) {
            /* a terminal: wrap it in a rule that replaces its every application */
            const ag_gstmt *s = &cb->stmts[only];
            const ag_gterminal *T = &g->terminals[s->callee_ix];
            char wname[64];
            snprintf(wname, sizeof wname, "%.40s_of_%.16s", "wrap", T->name);
            ag_gcopy_unique_name(W, part->grammar, NULL, wname, body_name);
            ag_grule *wr;
            if ((st = ag_gcopy_insert_rule(W, 0, body_name, T->size, &wr)) ||
                (st = ag_grammar_add_apply(wr, T->name, "p", 0, NULL, NULL, 0, 0))) {
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                goto done;
            }
            for (size_t ri = 0; ri <= W->nrules; ri++) {
                ag_grule *r = ri < W->nrules ? &W->rules[ri] : &W->axiom;
                if (ri == 0)
                    continue; /* the wrapper itself */
                for (size_t k = 0; k < r->nstmts; k++) {
                    ag_gstmt *x = &r->stmts[k];
                    if (x->kind == AG_GSTMT_APPLY && !strcmp(x->callee, T->name)) {
                        char *c = strdup(body_name);
                        if (!c) {
                            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                            goto done;
                        }
                        free(x->callee);
                        x->callee = c;
                    }
                }
            }
            for (size_t i = 0; i < t->ninstances; i++) {
                const ag_grule *r = ag_trace_body(g, &t->inst[i]);
                for (size_t k = 0; k < r->nstmts; k++)
                    if (r->stmts[k].kind == AG_GSTMT_APPLY && !r->stmts[k].callee_is_rule &&
                        r->stmts[k].callee_ix == s->callee_ix)
                        rep->instances += r->stmts[k].subdivide
                                              ? (size_t)r->stmts[k].counts[0] * r->stmts[k].counts[1] *
                                                    r->stmts[k].counts[2]
                                              : 1;
            }
            long wcol;
            if ((st = ag_grammar_resolve(W, err, &wcol))) {
                st = ag_error_set(err, AG_ERR_INTERNAL, 0, "wrapping the target: %s",
                                  err ? err->text : "");
                goto done;
            }
            rc = (t->inst[content.instance].rot + s->rot) & 3;
            L = (ag_box){{0, 0, 0}, {T->size[0], T->size[1], T->size[2]}};
            body_node = 0;
        } else if (nu == 1 && cb->stmts[only].kind == AG_GSTMT_APPLY && cb->stmts[only].subdivide) {
            st = ag_error_set(err, AG_ERR_INVALID, op->target,
                              "target: node %d is a pattern of rule %s; compose into one of its "
                              "cells for scope rule, or use scope node",
                              (int)op->target, cb->stmts[only].callee);
            goto done;
        } else {
            const ag_trace_instance *ci = &t->inst[content.instance];
            st = ag_error_set(err, AG_ERR_INVALID, op->target,
                              "target: node %d is not an instance of a rule (its content is "
                              "inlined in %s%s); compose it with scope node",
                              (int)op->target, ci->rule < 0 ? "the axiom" : "rule ",
                              ci->rule < 0 ? "" : g->rules[ci->rule].name);
            goto done;
        }
        snprintf(rep->target_rule, sizeof rep->target_rule, "%s", body_name);
    } else {
        /* separate the target: clone every shared rule on the path from the axiom */
        int32_t path[600];
        size_t np = 0;
        for (int32_t i = work.instance; i > 0 && np < 600; i = t->inst[i].parent)
            path[np++] = i;
        char parent_name[64] = "";
        rep->instances = 1;
        for (size_t pi = np; pi-- > 0;) {
            const ag_trace_instance *in = &t->inst[path[pi]];
            const ag_grule *orig = &g->rules[in->rule];
            char name[64];
            snprintf(name, sizeof name, "%s", orig->name);
            if (t->uses[in->rule] > 1) {
                char want[64];
                snprintf(want, sizeof want, "%.40s_n%d", orig->name, (int)op->target);
                ag_gcopy_unique_name(W, part->grammar, NULL, want, name);
                int32_t at = rule_index(W, orig->name);
                ag_grule *d;
                if ((st = ag_gcopy_insert_rule(W, (size_t)at + 1, name, orig->size, &d)))
                    goto nomem;
                for (size_t k = 0; k < orig->nstmts && !st; k++)
                    st = ag_gcopy_stmt(d, &orig->stmts[k], NULL, NULL, NULL);
                if (st)
                    goto nomem;
                rep->cloned++;
                /* the parent's statement now applies the clone */
                ag_grule *pr = rule_named(W, parent_name[0] ? parent_name : NULL);
                const ag_grule *porig = ag_trace_body(g, &t->inst[in->parent]);
                const ag_gstmt *s = &porig->stmts[in->stmt];
                /* statements of pr before this one are unchanged, so the index holds */
                if (!s->subdivide) {
                    char *c = strdup(name);
                    if (!c)
                        goto nomem;
                    free(pr->stmts[in->stmt].callee);
                    pr->stmts[in->stmt].callee = c;
                } else {
                    size_t cells = (size_t)s->counts[0] * s->counts[1] * s->counts[2];
                    if (cells > AG_COMPOSE_MAX_EXPANDED_CELLS) {
                        st = ag_error_set(err, AG_ERR_TOO_LARGE, op->target,
                                          "target: separating node %d expands a pattern of "
                                          "%zu cells (at most %d)",
                                          (int)op->target, cells, AG_COMPOSE_MAX_EXPANDED_CELLS);
                        goto done;
                    }
                    const ag_box *B = &t->local[t->inst[in->parent].site0 + s->node_ix];
                    ag_gframe_cells gc;
                    ag_gframe_cells_of(s, B, &gc);
                    unsigned counter = 0;
                    uint32_t ci = 0;
                    for (uint32_t z = 0; z < s->counts[2] && !st; z++)
                        for (uint32_t y = 0; y < s->counts[1] && !st; y++)
                            for (uint32_t x = 0; x < s->counts[0] && !st; x++, ci++) {
                                ag_box cell = ag_gframe_cell(&gc, x, y, z);
                                char nn[24];
                                if ((st = split_to(&tmp, pr, s->node, B, &cell, &counter, nn)))
                                    break;
                                st = ag_grammar_add_apply(&tmp, ci == in->cell ? name : s->callee,
                                                          nn, s->rot, NULL, NULL, 0, 0);
                            }
                    if (st || (st = body_splice(pr, (size_t)in->stmt, &tmp)))
                        goto nomem;
                    rep->expanded_cells += cells;
                }
            }
            snprintf(parent_name, sizeof parent_name, "%s", name);
        }
        snprintf(body_name, sizeof body_name, "%s", parent_name);
        long col;
        if ((st = ag_grammar_resolve(W, err, &col))) {
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "separating the target: %s",
                              err ? err->text : "");
            goto done;
        }
    }

    /* the turn and the size the part is fitted to */
    const ag_grammar *P = part->grammar;
    int32_t proot = ag_part_root_rule(part);
    int fs = part->facing;
    int fd = ag_place_facing(&tree->nodes[op->target].box, &tree->nodes[0].box);
    int k = (ag_part_root_rot(part) + fd - fs - rc) & 3;
    rep->turn = (fd - fs) & 3;
    double D[3], Sk[3];
    for (int a = 0; a < 3; a++)
        D[a] = L.max[a] - L.min[a];
    const double *PS = P->rules[proot].size;
    /* the part's size in the target body's axes */
    double Pk[3] = {k & 1 ? PS[1] : PS[0], k & 1 ? PS[0] : PS[1], PS[2]};
    ag_box fillbox = L;
    double cell[3] = {D[0], D[1], D[2]};
    if (op->mode == AG_COMPOSE_FILL) {
        /* the grid in the body's local axes: the face it faces there */
        double step[3];
        if (ag_place_fill_grid(&L, Pk, (fd - rc) & 3, rep->counts, step, &fillbox)) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, op->target,
                              "the part is too small to fill node %d", (int)op->target);
            goto done;
        }
        double total = (double)rep->counts[0] * rep->counts[1] * rep->counts[2], tris = 0;
        for (size_t i = 0; i < P->nterminals; i++)
            tris += (double)P->terminals[i].ntris;
        if (total > AG_COMPOSE_MAX_FILL_CELLS || total * tris > 5e7) {
            st = ag_error_set(err, AG_ERR_TOO_LARGE, op->target,
                              "filling node %d needs %.0f copies of the part (at most %d cells, "
                              "50 million triangles)",
                              (int)op->target, total, AG_COMPOSE_MAX_FILL_CELLS);
            goto done;
        }
        for (int a = 0; a < 3; a++) {
            cell[a] = fillbox.max[a] - fillbox.min[a];
            fillbox.max[a] += (rep->counts[a] - 1) * step[a];
        }
    }
    Sk[0] = k & 1 ? cell[1] : cell[0];
    Sk[1] = k & 1 ? cell[0] : cell[1];
    Sk[2] = cell[2];
    /* through the part's own wrappers, to the body that holds its members */
    int32_t inner = proot;
    int q = 0;
    for (;;) {
        const ag_grule *r = &P->rules[inner];
        if (r->nstmts != 1 || r->stmts[0].kind != AG_GSTMT_APPLY || !r->stmts[0].callee_is_rule ||
            r->stmts[0].subdivide || r->stmts[0].node_ix != 0)
            break;
        q = (q + r->stmts[0].rot) & 3;
        if (r->stmts[0].rot & 1) {
            double x = Sk[0];
            Sk[0] = Sk[1];
            Sk[1] = x;
        }
        inner = r->stmts[0].callee_ix;
    }
    memcpy(rep->fitted, Sk, sizeof Sk);
    if ((st = ag_fit_body(P, &P->rules[inner], Sk, &fitted, &rep->fit, err)))
        goto done;
    char ident[64];
    ag_gcopy_identifier(part->name, ident);
    size_t at = 0;
    if ((st = instantiate(W, part, &fitted, &at, ident, body_name, rep, &map)))
        goto nomem;
    ag_gcopy_unique_name(W, NULL, NULL, part->root, rep->root);
    {
        ag_grule *fr;
        if ((st = ag_gcopy_insert_rule(W, at++, rep->root, Sk, &fr)))
            goto nomem;
        fr->stmts = fitted.stmts;
        fr->nstmts = fitted.nstmts;
        fr->cap = fitted.cap;
        memset(&fitted, 0, sizeof fitted);
        long col;
        if ((st = ag_gcopy_sort_rules(W, err)) || (st = ag_grammar_resolve(W, err, &col))) {
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "instantiating the part: %s",
                              err ? err->text : "");
            goto done;
        }
    }
    int kq = (k + q) & 3;

    /* the rewrite in the target's body */
    ag_grule *M = rule_named(W, body_name[0] ? body_name : NULL);
    if (!M) {
        st = ag_error_set(err, AG_ERR_INTERNAL, 0, "the target body '%s' is missing", body_name);
        goto done;
    }
    int32_t only;
    under(M, body_node, below, &only);
    const char *nj0 = node_name(M, body_node);
    if (!nj0) {
        st = ag_error_set(err, AG_ERR_INTERNAL, 0, "the target's node is missing in its body");
        goto done;
    }
    char nj[64];
    snprintf(nj, sizeof nj, "%s", nj0);
    uint8_t *drop = calloc(M->nstmts + 1, 1);
    if (!drop)
        goto nomem;
    for (size_t i = 0; i < M->nstmts; i++) {
        const ag_gstmt *s = &M->stmts[i];
        int in = s->kind == AG_GSTMT_SPLIT ? below[s->parent_ix] : below[s->node_ix];
        /* the target's own geometry: terminals placed on it; rules and patterns applied on
         * its box are content below it */
        int own = s->kind == AG_GSTMT_APPLY && s->node_ix == body_node && !s->callee_is_rule &&
                  !s->subdivide;
        drop[i] = in && (op->mode == AG_COMPOSE_REPLACE || !own);
    }
    if (op->mode == AG_COMPOSE_INSERT) {
        /* a rule of the part followed by the target's children, in the target's box */
        char iname[64], want[80];
        snprintf(want, sizeof want, "%.40s_over_%.16s", ident, body_name[0] ? body_name : "axiom");
        ag_gcopy_unique_name(W, part->grammar, NULL, want, iname);
        st = ag_grammar_add_apply(&tmp, rep->root, "p", kq, NULL, NULL, 0, 0);
        for (size_t i = 0; i < M->nstmts && !st; i++) {
            if (!drop[i])
                continue;
            const ag_gstmt *s = &M->stmts[i];
            st = ag_gcopy_stmt(&tmp, s, s->kind == AG_GSTMT_APPLY && s->node_ix == body_node ? "p" : NULL,
                               s->kind == AG_GSTMT_SPLIT && s->parent_ix == body_node ? "p" : NULL,
                               NULL);
        }
        body_drop(M, drop);
        free(drop);
        if (st || (st = ag_grammar_add_apply(M, iname, nj, 0, NULL, NULL, 0, 0)))
            goto nomem;
        size_t mi = body_name[0] ? (size_t)rule_index(W, body_name) : W->nrules;
        double isz[3] = {D[0], D[1], D[2]};
        ag_grule *ir;
        if ((st = ag_gcopy_insert_rule(W, mi, iname, isz, &ir)))
            goto nomem;
        ir->stmts = tmp.stmts;
        ir->nstmts = tmp.nstmts;
        ir->cap = tmp.cap;
        memset(&tmp, 0, sizeof tmp);
        rep->rules_added++;
    } else {
        body_drop(M, drop);
        free(drop);
        if (op->mode == AG_COMPOSE_REPLACE) {
            st = ag_grammar_add_apply(M, rep->root, nj, kq, NULL, NULL, 0, 0);
        } else {
            unsigned counter = 0;
            char fn[24];
            st = split_to(M, M, nj, &L, &fillbox, &counter, fn);
            double step[3];
            for (int a = 0; a < 3; a++)
                step[a] = rep->counts[a] > 1 ? cell[a] : 0;
            if (!st)
                st = ag_grammar_add_apply(M, rep->root, fn, kq, rep->counts, step, 0, 0);
        }
        if (st)
            goto nomem;
    }
    long col;
    if ((st = ag_gcopy_sort_rules(W, err)) || (st = ag_grammar_resolve(W, err, &col))) {
        st = ag_error_set(err, AG_ERR_INTERNAL, 0, "the composed grammar does not resolve: %s",
                          err ? err->text : "");
        goto done;
    }
    /* the columns the fit re-counted, as "10 -> 8 columns" */
    char counts[64] = "";
    for (int a = 0; a < 3; a++)
        if (rep->fit.columns[a][1]) {
            size_t at = strlen(counts);
            snprintf(counts + at, sizeof counts - at, "%s%u -> %u columns", at ? ", " : " (",
                     rep->fit.columns[a][0], rep->fit.columns[a][1]);
        }
    if (counts[0])
        snprintf(counts + strlen(counts), sizeof counts - strlen(counts), ")");
    snprintf(rep->message, sizeof rep->message,
             "%s '%s' into node %d (scope %s%s%s): %zu instance%s, turned by %d, fitted to "
             "%.4g x %.4g x %.4g%s; %zu rules and %zu terminals added, %zu and %zu shared",
             ag_compose_mode_name(op->mode), part->name, (int)op->target,
             ag_compose_scope_name(op->scope), rep->target_rule[0] ? ", rule " : "",
             rep->target_rule, rep->instances, rep->instances == 1 ? "" : "s", 90 * rep->turn,
             Sk[0], Sk[1], Sk[2], counts, rep->rules_added, rep->terminals_added,
             rep->rules_shared, rep->terminals_shared);
    *out = W;
    W = NULL;
    st = AG_OK;
    goto done;
nomem:
    st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
done:
    free_body(&fitted);
    free_body(&tmp);
    map_free(&map);
    free(below);
    ag_grammar_free(W);
    ag_trace_free(own);
    return st;
}
