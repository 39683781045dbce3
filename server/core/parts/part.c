#include "part.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../edit/place.h"
#include "gcopy.h"
#include "trace.h"

void ag_part_free(ag_part *p)
{
    if (!p)
        return;
    free(p->name);
    free(p->description);
    for (size_t i = 0; i < p->ntags; i++)
        free(p->tags[i]);
    free(p->tags);
    free(p->source);
    for (size_t i = 0; i < p->nattrs; i++) {
        free(p->attrs[i].key);
        free(p->attrs[i].value);
    }
    free(p->attrs);
    ag_grammar_free(p->grammar);
    free(p->root);
    free(p->nodes);
    free(p);
}

ag_status ag_part_check_meta(const ag_part_meta *meta, ag_error *err)
{
    if (!meta || !meta->name || !meta->name[0])
        return ag_error_set(err, AG_ERR_INVALID, 0, "name: a part needs a name");
    if (strlen(meta->name) > AG_PART_NAME_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "name: longer than %d bytes",
                            AG_PART_NAME_MAX);
    if (meta->description && strlen(meta->description) > AG_PART_TEXT_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "description: longer than %d bytes",
                            AG_PART_TEXT_MAX);
    if (meta->source && strlen(meta->source) > AG_PART_TEXT_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "source: longer than %d bytes",
                            AG_PART_TEXT_MAX);
    if (meta->ntags > AG_PART_TAGS_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "tags: more than %d", AG_PART_TAGS_MAX);
    for (size_t i = 0; i < meta->ntags; i++)
        if (!meta->tags[i] || !meta->tags[i][0] || strlen(meta->tags[i]) > AG_PART_NAME_MAX)
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "tags[%zu]: empty or longer than %d bytes", i, AG_PART_NAME_MAX);
    return AG_OK;
}

static char *dup_or_null(const char *s, int *bad)
{
    if (!s)
        return NULL;
    char *d = strdup(s);
    if (!d)
        *bad = 1;
    return d;
}

ag_status ag_part_set_meta(ag_part *p, const ag_part_meta *meta)
{
    int bad = 0;
    p->name = dup_or_null(meta->name, &bad);
    p->description = dup_or_null(meta->description, &bad);
    p->source = dup_or_null(meta->source, &bad);
    p->source_version = meta->source_version;
    if (meta->ntags) {
        p->tags = calloc(meta->ntags, sizeof *p->tags);
        if (!p->tags)
            return AG_ERR_NOMEM;
        for (size_t i = 0; i < meta->ntags; i++)
            p->tags[p->ntags++] = dup_or_null(meta->tags[i], &bad);
    }
    return bad ? AG_ERR_NOMEM : AG_OK;
}

ag_status ag_part_copy(const ag_part *p, ag_part **out, ag_error *err)
{
    *out = NULL;
    ag_part *c = calloc(1, sizeof *c);
    if (!c)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_part_meta meta = {.name = p->name, .description = p->description,
                         .tags = (const char *const *)p->tags, .ntags = p->ntags,
                         .source = p->source, .source_version = p->source_version};
    int bad = ag_part_set_meta(c, &meta) != AG_OK;
    for (size_t i = 0; i < p->nattrs && !bad; i++)
        bad = ag_part_add_attr(c, p->attrs[i].key, p->attrs[i].value) != AG_OK;
    c->version = p->version;
    c->source_node = p->source_node;
    c->box = p->box;
    c->facing = p->facing;
    c->root = bad ? NULL : dup_or_null(p->root, &bad);
    if (!bad && p->nnodes) {
        if ((c->nodes = malloc(p->nnodes * sizeof *c->nodes))) {
            memcpy(c->nodes, p->nodes, p->nnodes * sizeof *c->nodes);
            c->nnodes = p->nnodes;
        } else {
            bad = 1;
        }
    }
    ag_status st = bad ? ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory")
                       : ag_gcopy_grammar(p->grammar, &c->grammar, err);
    if (st) {
        ag_part_free(c);
        return st;
    }
    *out = c;
    return AG_OK;
}

ag_status ag_part_add_attr(ag_part *p, const char *key, const char *value)
{
    ag_part_attr *a = realloc(p->attrs, (p->nattrs + 1) * sizeof *a);
    if (!a)
        return AG_ERR_NOMEM;
    p->attrs = a;
    a[p->nattrs].key = strdup(key);
    a[p->nattrs].value = strdup(value);
    p->nattrs++;
    return a[p->nattrs - 1].key && a[p->nattrs - 1].value ? AG_OK : AG_ERR_NOMEM;
}

int32_t ag_part_root_rule(const ag_part *p)
{
    int is_rule = 0;
    int32_t i = p->grammar && p->root ? ag_gcopy_find(p->grammar, p->root, &is_rule) : -1;
    return i >= 0 && is_rule ? i : -1;
}

int ag_part_root_rot(const ag_part *p)
{
    return p->grammar && p->grammar->axiom.nstmts ? p->grammar->axiom.stmts[0].rot & 3 : 0;
}

ag_status ag_part_validate(const ag_part *p, ag_error *err)
{
    const ag_grammar *g = p->grammar;
    if (!g || !g->has_axiom)
        return ag_error_set(err, AG_ERR_INVALID, 0, "grammar: the part has no grammar");
    int32_t root = ag_part_root_rule(p);
    if (root < 0)
        return ag_error_set(err, AG_ERR_INVALID, 0, "root: '%s' is not a rule of the part",
                            p->root ? p->root : "");
    const ag_grule *ax = &g->axiom;
    if (ax->nstmts != 1 || ax->stmts[0].kind != AG_GSTMT_APPLY || ax->stmts[0].subdivide ||
        strcmp(ax->stmts[0].callee, p->root) || strcmp(ax->stmts[0].node, "p"))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "grammar: the axiom must be exactly '%s(p)' (with a turn)", p->root);
    for (size_t i = 0; i < g->nterminals; i++)
        if (!g->terminals[i].pos && g->terminals[i].ntris == 0)
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "terminal '%s' has no geometry", g->terminals[i].name);
    for (int a = 0; a < 3; a++)
        if (!isfinite(p->box.min[a]) || !isfinite(p->box.max[a]) || p->box.max[a] < p->box.min[a])
            return ag_error_set(err, AG_ERR_INVALID, 0, "box: not a finite box");
    for (int k = 0; k < 6; k++) {
        double v = k < 3 ? p->box.min[k] : p->box.max[k - 3];
        if (fabs(v) > AG_PART_MAX_COORD)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "box: %s %c = %.15g m is beyond the +-%g m a part can hold "
                                "(move the model nearer its origin)",
                                k < 3 ? "min" : "max", "xyz"[k % 3], v, AG_PART_MAX_COORD);
    }
    if (p->facing < 0 || p->facing > 3)
        return ag_error_set(err, AG_ERR_INVALID, 0, "facing: %d is not 0..3", p->facing);
    for (size_t i = 0; i < p->nnodes; i++) {
        const ag_part_node *n = &p->nodes[i];
        if (n->parent < -1 || n->parent >= (int32_t)i || (i == 0) != (n->parent == -1))
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "nodes[%zu]: parent %d is not an earlier node", i,
                                (int)n->parent);
        for (int k = 0; k < 6; k++)
            if (!isfinite(n->box[k]) || n->box[k] < -1e-6 || n->box[k] > 1 + 1e-6)
                return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                    "nodes[%zu]: box is not inside the part's box", i);
    }
    return AG_OK;
}

/* The proportions: the subtree of node in depth-first order, split nodes left out. */
static ag_status collect_nodes(ag_part *p, const ag_proceduralize_result *r, int32_t node)
{
    const ag_splittree *t = r->tree;
    size_t cap = 64, sp = 0;
    int32_t *stack = malloc(cap * 2 * sizeof *stack);
    if (!stack)
        return AG_ERR_NOMEM;
    const ag_box *B = &t->nodes[node].box;
    stack[0] = node;
    stack[1] = -1;
    sp = 1;
    size_t capn = 0;
    while (sp) {
        sp--;
        int32_t v = stack[2 * sp], parent = stack[2 * sp + 1];
        int32_t me = parent;
        const ag_tnode *n = &t->nodes[v];
        if (n->kind != AG_NODE_SPLIT) {
            if (p->nnodes == capn) {
                capn = capn ? 2 * capn : 64;
                ag_part_node *q = realloc(p->nodes, capn * sizeof *q);
                if (!q) {
                    free(stack);
                    return AG_ERR_NOMEM;
                }
                p->nodes = q;
            }
            ag_part_node *d = &p->nodes[p->nnodes];
            memset(d, 0, sizeof *d);
            d->parent = parent;
            d->kind = v == node && n->kind != AG_NODE_COMPONENT ? AG_NODE_ROOT : n->kind;
            if (d->kind == AG_NODE_ROOT && n->kind == AG_NODE_PATTERN)
                d->kind = AG_NODE_PATTERN;
            d->label = n->label;
            int32_t cls = n->kind == AG_NODE_PATTERN ? t->patterns[n->pattern].rule : n->rule;
            int32_t ri = cls >= 0 && r->info.rule_of_class && (size_t)cls < r->info.nclasses
                             ? r->info.rule_of_class[cls]
                             : -1;
            if (ri >= 0)
                snprintf(d->rule, sizeof d->rule, "%s", r->grammar->rules[ri].name);
            for (int a = 0; a < 3; a++) {
                double s = B->max[a] - B->min[a];
                d->box[a] = s > 0 ? (n->box.min[a] - B->min[a]) / s : 0;
                d->box[a + 3] = s > 0 ? (n->box.max[a] - B->min[a]) / s : 0;
                for (int k = 0; k < 2; k++) { /* rounding at the faces */
                    double *x = &d->box[a + 3 * k];
                    *x = *x < 0 ? 0 : *x > 1 ? 1 : *x;
                }
            }
            me = (int32_t)p->nnodes++;
        }
        for (int32_t c = n->first_child; c >= 0; c = t->nodes[c].next_sibling) {
            if (sp == cap) {
                cap *= 2;
                int32_t *q = realloc(stack, cap * 2 * sizeof *q);
                if (!q) {
                    free(stack);
                    return AG_ERR_NOMEM;
                }
                stack = q;
            }
            stack[2 * sp] = c;
            stack[2 * sp + 1] = me;
            sp++;
        }
    }
    free(stack);
    return AG_OK;
}

/* The part's grammar: reachable terminals and rules in their source order, the root rule made
 * of the site's statements (the site's node renamed p), the axiom placing it. */
static ag_status build_grammar(ag_part *p, const ag_grammar *g, const ag_trace *t,
                               ag_trace_site site, ag_error *err)
{
    const ag_trace_instance *in = &t->inst[site.instance];
    const ag_grule *body = ag_trace_body(g, in);
    size_t nn = body->nnodes ? body->nnodes : 1;
    uint8_t *below = calloc(nn, 1);
    uint8_t *rules = calloc(g->nrules + 1, 1), *terms = calloc(g->nterminals + 1, 1);
    ag_grule root = {0};
    ag_grammar *pg = ag_grammar_create();
    ag_status st = AG_ERR_NOMEM;
    if (!below || !rules || !terms || !pg)
        goto done;
    below[site.node] = 1;
    const char *site_name = "p";
    for (size_t i = 0; i < body->nstmts; i++) {
        const ag_gstmt *s = &body->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT && s->node_ix == site.node)
            site_name = s->node;
        if (s->kind == AG_GSTMT_SPLIT && below[s->parent_ix])
            below[s->node_ix] = 1;
    }
    st = AG_OK;
    for (size_t i = 0; i < body->nstmts && !st; i++) {
        const ag_gstmt *s = &body->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            if (below[s->parent_ix])
                st = ag_gcopy_stmt(&root, s, NULL, s->parent_ix == site.node ? "p" : NULL, NULL);
        } else if (below[s->node_ix]) {
            st = ag_gcopy_stmt(&root, s, s->node_ix == site.node ? "p" : NULL, NULL, NULL);
        }
    }
    (void)site_name;
    if (st)
        goto done;
    /* resolve the root's callees against g to walk what it reaches */
    for (size_t i = 0; i < root.nstmts; i++) {
        ag_gstmt *s = &root.stmts[i];
        if (s->kind != AG_GSTMT_APPLY)
            continue;
        int is_rule = 0;
        s->callee_ix = ag_gcopy_find(g, s->callee, &is_rule);
        s->callee_is_rule = is_rule;
    }
    ag_gcopy_mark_reachable(g, &root, rules, terms);
    for (size_t i = 0; i < g->nterminals && !st; i++)
        if (terms[i])
            st = ag_gcopy_terminal(pg, &g->terminals[i], g->terminals[i].name);
    for (size_t i = 0; i < g->nrules && !st; i++) {
        if (!rules[i])
            continue;
        size_t ix;
        if ((st = ag_grammar_add_rule(pg, g->rules[i].name, g->rules[i].size, &ix)))
            break;
        for (size_t k = 0; k < g->rules[i].nstmts && !st; k++)
            st = ag_gcopy_stmt(&pg->rules[ix], &g->rules[i].stmts[k], NULL, NULL, NULL);
    }
    if (st)
        goto done;
    char ident[64], name[64];
    ag_gcopy_identifier(p->name, ident);
    ag_gcopy_unique_name(g, pg, NULL, ident, name);
    const ag_box *L = &t->local[in->site0 + site.node];
    double size[3];
    for (int a = 0; a < 3; a++)
        size[a] = L->max[a] - L->min[a];
    size_t ri;
    if ((st = ag_grammar_add_rule(pg, name, size, &ri)))
        goto done;
    pg->rules[ri].stmts = root.stmts;
    pg->rules[ri].nstmts = root.nstmts;
    pg->rules[ri].cap = root.cap;
    memset(&root, 0, sizeof root);
    pg->has_axiom = 1;
    pg->axiom.box = t->world[in->site0 + site.node];
    if ((st = ag_grammar_add_apply(&pg->axiom, name, "p", in->rot, NULL, NULL, 0, 0)))
        goto done;
    if (!(p->root = strdup(name))) {
        st = AG_ERR_NOMEM;
        goto done;
    }
    long col;
    if ((st = ag_grammar_resolve(pg, err, &col))) {
        st = ag_error_set(err, AG_ERR_INTERNAL, 0, "the part's grammar does not resolve: %s",
                          err ? err->text : "");
        goto done;
    }
    p->grammar = pg;
    pg = NULL;
done:
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory");
    for (size_t i = 0; i < root.nstmts; i++) {
        free(root.stmts[i].node);
        free(root.stmts[i].parent);
        free(root.stmts[i].callee);
    }
    free(root.stmts);
    ag_grammar_free(pg);
    free(below);
    free(rules);
    free(terms);
    return st;
}

ag_status ag_part_extract(const ag_proceduralize_result *r, int32_t node, const ag_part_meta *meta,
                          ag_part **out, ag_error *err)
{
    return ag_part_extract_traced(r, NULL, node, meta, out, err);
}

ag_status ag_part_extract_traced(const ag_proceduralize_result *r, const ag_trace *trace,
                                 int32_t node, const ag_part_meta *meta, ag_part **out,
                                 ag_error *err)
{
    *out = NULL;
    ag_status st = ag_part_check_meta(meta, err);
    if (st)
        return st;
    if ((st = ag_place_check_node(r, node, "node", err)))
        return st;
    ag_trace *own = NULL; /* the trace made here, when none is given */
    if (!trace && (st = ag_trace_build(r->grammar, 0, &own, err)))
        return st;
    const ag_trace *t = trace ? trace : own;
    ag_trace_site site;
    ag_part *p = calloc(1, sizeof *p);
    if (!p) {
        ag_trace_free(own);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    p->version = 1;
    p->source_node = node;
    if ((st = ag_trace_find_node(t, r->grammar, r, node, &site, err)))
        goto fail;
    if ((st = ag_part_set_meta(p, meta)) || (st = collect_nodes(p, r, node))) {
        ag_error_set(err, st, 0, "out of memory");
        goto fail;
    }
    if ((st = build_grammar(p, r->grammar, t, site, err)))
        goto fail;
    p->box = p->grammar->axiom.box;
    p->facing = ag_place_facing(&r->tree->nodes[node].box, &r->tree->nodes[0].box);
    /* attributes: what the part is made of */
    char buf[64];
    size_t tris = 0;
    for (size_t i = 0; i < p->grammar->nterminals; i++)
        tris += p->grammar->terminals[i].ntris;
    snprintf(buf, sizeof buf, "%zu", ag_trace_site_terminals(t, r->grammar, site));
    st = ag_part_add_attr(p, "placed_terminals", buf);
    snprintf(buf, sizeof buf, "%zu", p->grammar->nrules);
    if (!st)
        st = ag_part_add_attr(p, "rules", buf);
    snprintf(buf, sizeof buf, "%zu", p->grammar->nterminals);
    if (!st)
        st = ag_part_add_attr(p, "terminals", buf);
    snprintf(buf, sizeof buf, "%zu", tris);
    if (!st)
        st = ag_part_add_attr(p, "terminal_triangles", buf);
    if (st) {
        ag_error_set(err, st, 0, "out of memory");
        goto fail;
    }
    ag_trace_free(own);
    *out = p;
    return AG_OK;
fail:
    ag_trace_free(own);
    ag_part_free(p);
    return st;
}
