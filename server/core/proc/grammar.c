#include "grammar.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "gframe.h"

/* Work limits: a subdivide or repeat of more cells is refused (its derivation would not fit
 * in memory); a derivation stops past this many triangles (unless the caller sets its own)
 * or rules nested this deep (a rule calling itself). */
#define GRAMMAR_MAX_CELLS 1e7
#define DERIVE_MAX_TRIANGLES 50000000
#define DERIVE_MAX_DEPTH 512

/* ---- building blocks -------------------------------------------------------------------- */

ag_grammar *ag_grammar_create(void)
{
    return calloc(1, sizeof(ag_grammar));
}

static void free_rule(ag_grule *r)
{
    for (size_t i = 0; i < r->nstmts; i++) {
        free(r->stmts[i].node);
        free(r->stmts[i].parent);
        free(r->stmts[i].callee);
    }
    free(r->stmts);
    free(r->name);
}

void ag_grammar_free(ag_grammar *g)
{
    if (!g)
        return;
    for (size_t i = 0; i < g->nterminals; i++) {
        free(g->terminals[i].name);
        free(g->terminals[i].path);
        free(g->terminals[i].label_name);
        free(g->terminals[i].pos);
        free(g->terminals[i].tri);
    }
    free(g->terminals);
    for (size_t i = 0; i < g->nrules; i++)
        free_rule(&g->rules[i]);
    free(g->rules);
    free_rule(&g->axiom);
    free(g);
}

ag_status ag_grammar_add_terminal(ag_grammar *g, const char *name, const double size[3],
                                  size_t *index)
{
    ag_status st = AG_ARRAY_RESERVE(g->terminals, g->cap_terminals, g->nterminals + 1);
    if (st)
        return st;
    ag_gterminal *t = &g->terminals[g->nterminals];
    memset(t, 0, sizeof *t);
    t->name = strdup(name);
    if (!t->name)
        return AG_ERR_NOMEM;
    memcpy(t->size, size, sizeof t->size);
    t->label = -1;
    if (index)
        *index = g->nterminals;
    g->nterminals++;
    return AG_OK;
}

ag_status ag_grammar_add_rule(ag_grammar *g, const char *name, const double size[3],
                              size_t *index)
{
    ag_status st = AG_ARRAY_RESERVE(g->rules, g->cap_rules, g->nrules + 1);
    if (st)
        return st;
    ag_grule *r = &g->rules[g->nrules];
    memset(r, 0, sizeof *r);
    r->name = strdup(name);
    if (!r->name)
        return AG_ERR_NOMEM;
    memcpy(r->size, size, sizeof r->size);
    if (index)
        *index = g->nrules;
    g->nrules++;
    return AG_OK;
}

static ag_gstmt *new_stmt(ag_grule *r)
{
    if (AG_ARRAY_RESERVE(r->stmts, r->cap, r->nstmts + 1))
        return NULL;
    ag_gstmt *s = &r->stmts[r->nstmts++];
    memset(s, 0, sizeof *s);
    s->node_ix = s->parent_ix = s->callee_ix = -1;
    return s;
}

ag_status ag_grammar_add_split(ag_grule *r, const char *node, const char *parent,
                               const double v[3], int octant, long line, long col)
{
    ag_gstmt *s = new_stmt(r);
    if (!s)
        return AG_ERR_NOMEM;
    s->kind = AG_GSTMT_SPLIT;
    s->node = strdup(node);
    s->parent = strdup(parent);
    memcpy(s->v, v, sizeof s->v);
    s->octant = octant;
    s->line = line;
    s->col = col;
    return s->node && s->parent ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_grammar_add_apply(ag_grule *r, const char *callee, const char *node, int rot,
                               const uint32_t *counts, const double *step, long line, long col)
{
    ag_gstmt *s = new_stmt(r);
    if (!s)
        return AG_ERR_NOMEM;
    s->kind = AG_GSTMT_APPLY;
    s->callee = strdup(callee);
    s->node = strdup(node);
    s->rot = rot;
    if (counts) {
        s->subdivide = 1;
        memcpy(s->counts, counts, sizeof s->counts);
        memcpy(s->step, step, sizeof s->step);
    }
    s->line = line;
    s->col = col;
    return s->callee && s->node ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_grammar_add_repeat(ag_grule *r, const char *callee, const char *node, int rot,
                                int nvec, const uint32_t *counts, const double vec[][3],
                                long line, long col)
{
    ag_status st = ag_grammar_add_apply(r, callee, node, rot, NULL, NULL, line, col);
    if (st)
        return st;
    ag_gstmt *s = &r->stmts[r->nstmts - 1];
    s->subdivide = 2;
    s->nvec = nvec < 1 ? 1 : nvec > 3 ? 3 : nvec;
    for (int k = 0; k < 3; k++) {
        s->counts[k] = k < s->nvec ? counts[k] : 1;
        for (int a = 0; a < 3; a++)
            s->vec[k][a] = k < s->nvec ? vec[k][a] : 0;
    }
    return AG_OK;
}

ag_status ag_grammar_set_terminal_geometry(ag_gterminal *t, const double *pos, size_t nverts,
                                           const uint32_t *tri, size_t ntris)
{
    double *p = malloc((3 * nverts + 1) * sizeof *p);
    uint32_t *q = malloc((3 * ntris + 1) * sizeof *q);
    if (!p || !q) {
        free(p);
        free(q);
        return AG_ERR_NOMEM;
    }
    memcpy(p, pos, 3 * nverts * sizeof *p);
    memcpy(q, tri, 3 * ntris * sizeof *q);
    free(t->pos);
    free(t->tri);
    t->pos = p;
    t->tri = q;
    t->nverts = nverts;
    t->ntris = ntris;
    return AG_OK;
}

/* ---- resolve ---------------------------------------------------------------------------- */

static ag_status rerr(ag_error *err, long *col, long line, long c, const char *fmt, const char *a)
{
    if (col)
        *col = c;
    return ag_error_set(err, AG_ERR_PARSE, line, fmt, a ? a : "");
}

/* Node names of one body: an open-addressing table over string hashes. */
typedef struct {
    char **names;
    int32_t *slot; /* index into names, -1 empty */
    size_t n, cap;
} nametab;

static uint64_t str_hash(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 0x100000001b3ULL;
    return h;
}

static int find_node(const nametab *t, const char *s)
{
    size_t i = str_hash(s) & (t->cap - 1);
    while (t->slot[i] >= 0) {
        if (!strcmp(t->names[t->slot[i]], s))
            return t->slot[i];
        i = (i + 1) & (t->cap - 1);
    }
    return -1;
}

static void add_node(nametab *t, char *s)
{
    size_t i = str_hash(s) & (t->cap - 1);
    while (t->slot[i] >= 0)
        i = (i + 1) & (t->cap - 1);
    t->slot[i] = (int32_t)t->n;
    t->names[t->n++] = s;
}

/* Terminal and rule names: index by hash as well, rules only up to `limit`. */
static int find_callee(const ag_grammar *g, const nametab *rt, const nametab *tt, const char *s,
                       size_t limit, int *is_rule)
{
    int k = find_node(rt, s);
    if (k >= 0 && (size_t)k < limit) {
        *is_rule = 1;
        return k;
    }
    k = find_node(tt, s);
    *is_rule = 0;
    (void)g;
    return k;
}

static int tab_init(nametab *t, size_t n)
{
    t->n = 0;
    if (ag_array_hash_size(n + 1, &t->cap))
        return -1;
    t->names = malloc((n + 1) * sizeof *t->names);
    t->slot = malloc(t->cap * sizeof *t->slot);
    if (!t->names || !t->slot)
        return -1;
    for (size_t i = 0; i < t->cap; i++)
        t->slot[i] = -1;
    return 0;
}

static ag_status resolve_rule(ag_grammar *g, ag_grule *r, size_t nrules_before, const nametab *rt,
                              const nametab *tt, ag_error *err, long *col)
{
    nametab nt = {0};
    if (tab_init(&nt, r->nstmts)) {
        free(nt.names);
        free(nt.slot);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    add_node(&nt, "p");
    ag_status st = AG_OK;
    for (size_t i = 0; i < r->nstmts && !st; i++) {
        ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            int p = find_node(&nt, s->parent);
            if (p < 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is not defined", s->parent);
                break;
            }
            if (find_node(&nt, s->node) >= 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is defined twice", s->node);
                break;
            }
            if (s->octant < 1 || s->octant > 8) {
                st = rerr(err, col, s->line, s->col, "octant must be 1 to 8%s", "");
                break;
            }
            for (int a = 0; a < 3; a++)
                if (!isfinite(s->v[a])) {
                    st = rerr(err, col, s->line, s->col, "pivot is not finite%s", "");
                    break;
                }
            if (st)
                break;
            s->parent_ix = p;
            s->node_ix = (int32_t)nt.n;
            add_node(&nt, s->node);
        } else {
            int p = find_node(&nt, s->node);
            if (p < 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is not defined", s->node);
                break;
            }
            s->node_ix = p;
            int is_rule = 0;
            s->callee_ix = find_callee(g, rt, tt, s->callee, nrules_before, &is_rule);
            s->callee_is_rule = is_rule;
            if (s->callee_ix < 0) {
                int later = find_node(rt, s->callee) >= 0;
                st = rerr(err, col, s->line, s->col,
                          later ? "rule '%s' is used before it is declared"
                                : "'%s' is neither a terminal nor a rule",
                          s->callee);
                break;
            }
            if (s->rot < 0 || s->rot > 3) {
                st = rerr(err, col, s->line, s->col, "rot must be 0, 90, 180 or 270%s", "");
                break;
            }
            if (s->subdivide) {
                double cells = 1;
                for (int a = 0; a < 3; a++) {
                    int bad = s->counts[a] < 1 || !isfinite(s->step[a]);
                    for (int b = 0; b < 3; b++)
                        bad |= !isfinite(s->vec[a][b]);
                    if (bad) {
                        st = rerr(err, col, s->line, s->col,
                                  "%s needs counts >= 1 and finite steps",
                                  s->subdivide == 2 ? "repeat" : "subdivide");
                        break;
                    }
                    cells *= s->counts[a];
                }
                if (!st && cells > GRAMMAR_MAX_CELLS)
                    st = rerr(err, col, s->line, s->col, "subdivide has too many cells%s", "");
            }
        }
    }
    r->nnodes = nt.n;
    free(nt.names);
    free(nt.slot);
    return st;
}

ag_status ag_grammar_resolve(ag_grammar *g, ag_error *err, long *col)
{
    if (col)
        *col = 0;
    nametab rt = {0}, tt = {0};
    ag_status st = AG_OK;
    if (tab_init(&rt, g->nrules) || tab_init(&tt, g->nterminals)) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < g->nterminals && !st; i++) {
        ag_gterminal *t = &g->terminals[i];
        if (find_node(&tt, t->name) >= 0) {
            st = rerr(err, col, 0, 0, "terminal '%s' is declared twice", t->name);
            break;
        }
        add_node(&tt, t->name);
        for (int a = 0; a < 3; a++)
            if (!(t->size[a] >= 0) || !isfinite(t->size[a])) {
                st = rerr(err, col, 0, 0, "terminal '%s' has a bad size", t->name);
                break;
            }
    }
    for (size_t i = 0; i < g->nrules && !st; i++) {
        ag_grule *r = &g->rules[i];
        if (find_node(&rt, r->name) >= 0) {
            st = rerr(err, col, r->line, r->col, "rule '%s' is declared twice", r->name);
            break;
        }
        if (find_node(&tt, r->name) >= 0) {
            st = rerr(err, col, r->line, r->col, "'%s' names a terminal and a rule", r->name);
            break;
        }
        add_node(&rt, r->name);
        for (int a = 0; a < 3; a++)
            if (!(r->size[a] >= 0) || !isfinite(r->size[a])) {
                st = rerr(err, col, r->line, r->col, "rule '%s' has a bad size", r->name);
                break;
            }
    }
    /* bodies: a rule may call only the rules before it */
    for (size_t i = 0; i < g->nrules && !st; i++)
        st = resolve_rule(g, &g->rules[i], i, &rt, &tt, err, col);
    if (!st && !g->has_axiom)
        st = rerr(err, col, 0, 0, "the grammar has no axiom%s", "");
    if (!st)
        st = resolve_rule(g, &g->axiom, g->nrules, &rt, &tt, err, col);
done:
    free(rt.names);
    free(rt.slot);
    free(tt.names);
    free(tt.slot);
    return st;
}

/* ---- export ----------------------------------------------------------------------------- */

typedef struct {
    const ag_mesh *m;
    const ag_labels *L;
    const ag_splittree *t;
    ag_grammar *g;
    int pass;            /* 1: count applications, 2: emit */
    uint32_t *apps;      /* per class */
    int32_t *exemplar;   /* per class: node */
    uint8_t *visited;    /* per class */
    uint8_t *in_pattern; /* per class: used by a subdivide */
    int32_t *rule_of;    /* per class: grammar rule */
    int32_t *term_of;    /* per variant: terminal */
    uint32_t *vmap;      /* scratch: vertex → terminal vertex */
    double *tpos;
    uint32_t *ttri;
    ag_status st;
} exctx;

static ag_grule scratch_rule; /* never used in pass 2 */

static int is_rule(exctx *x, int32_t cls)
{
    if (cls < 0)
        return 0;
    if (x->pass == 1)
        return x->t->rule_count[cls] >= 2;
    /* a repeated lone terminal is placed directly unless a pattern needs it as a rule */
    if (x->apps[cls] < 2)
        return 0;
    return x->t->nodes[x->exemplar[cls]].first_child >= 0 || x->in_pattern[cls];
}

static void emit_content(exctx *x, ag_grule *r, int32_t v, const char *vname, unsigned *counter);

static int32_t terminal_for(exctx *x, int32_t variant)
{
    if (x->term_of[variant] >= 0)
        return x->term_of[variant];
    const ag_labels *L = x->L;
    uint32_t c = L->variant_exemplar[variant];
    const ag_box *nb = &x->t->nodes[x->t->comp_node[c]].box;
    double size[3];
    ag_box_extents(nb, size);
    char name[32];
    snprintf(name, sizeof name, "T%zu", x->g->nterminals + 1);
    size_t ti;
    if ((x->st = ag_grammar_add_terminal(x->g, name, size, &ti)))
        return 0;
    x->g->terminals[ti].label = L->variant_label[variant];
    snprintf(name, sizeof name, "L%d", L->variant_label[variant] + 1);
    if (!(x->g->terminals[ti].label_name = strdup(name))) {
        x->st = AG_ERR_NOMEM;
        return 0;
    }
    size_t nv = 0, nt = 0;
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++) {
        uint32_t tr = L->tris[s];
        for (int k = 0; k < 3; k++) {
            uint32_t v = x->m->tri[3 * tr + k];
            if (x->vmap[v] == UINT32_MAX) {
                x->vmap[v] = (uint32_t)nv;
                for (int a = 0; a < 3; a++)
                    x->tpos[3 * nv + a] = x->m->pos[3 * v + a] - nb->min[a];
                nv++;
            }
            x->ttri[3 * nt + k] = x->vmap[v];
        }
        nt++;
    }
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++)
        for (int k = 0; k < 3; k++)
            x->vmap[x->m->tri[3 * L->tris[s] + k]] = UINT32_MAX;
    if ((x->st = ag_grammar_set_terminal_geometry(&x->g->terminals[ti], x->tpos, nv, x->ttri, nt)))
        return 0;
    x->term_of[variant] = (int32_t)ti;
    return (int32_t)ti;
}

static const char *node_name(unsigned *counter, char *buf, size_t cap)
{
    snprintf(buf, cap, "n%u", ++*counter);
    return buf;
}

/* Makes sure class cls is available; returns the grammar rule index in pass 2. */
static int32_t use_rule(exctx *x, int32_t cls, int32_t node, int weight)
{
    if (x->pass == 1) {
        x->apps[cls] += (uint32_t)weight;
        if (weight > 1)
            x->in_pattern[cls] = 1;
        if (!x->visited[cls]) {
            x->visited[cls] = 1;
            x->exemplar[cls] = node;
            unsigned counter = 0;
            emit_content(x, &scratch_rule, node, "p", &counter);
        }
        return -1;
    }
    if (x->rule_of[cls] >= 0)
        return x->rule_of[cls];
    /* body into a detached rule first: nested rules are declared while it is emitted */
    ag_grule body;
    memset(&body, 0, sizeof body);
    unsigned counter = 0;
    int32_t ex = x->exemplar[cls];
    emit_content(x, &body, ex, "p", &counter);
    double size[3];
    ag_box_extents(&x->t->nodes[ex].box, size);
    char name[32];
    snprintf(name, sizeof name, "R%zu", x->g->nrules + 1);
    size_t ri;
    if (!x->st)
        x->st = ag_grammar_add_rule(x->g, name, size, &ri);
    if (x->st) {
        free_rule(&body);
        return -1;
    }
    ag_grule *r = &x->g->rules[ri];
    r->stmts = body.stmts;
    r->nstmts = body.nstmts;
    r->cap = body.cap;
    x->rule_of[cls] = (int32_t)ri;
    return (int32_t)ri;
}

static void emit_content(exctx *x, ag_grule *r, int32_t v, const char *vname, unsigned *counter)
{
    const ag_splittree *t = x->t;
    const ag_tnode *n = &t->nodes[v];
    int emit = x->pass == 2;
    if (x->st)
        return;
    if (n->kind == AG_NODE_COMPONENT && emit) {
        int32_t ti = terminal_for(x, n->variant);
        if (x->st)
            return;
        x->st = ag_grammar_add_apply(r, x->g->terminals[ti].name, vname, n->rot, NULL, NULL, 0, 0);
    }
    for (int32_t s = n->first_child; s >= 0 && !x->st; s = t->nodes[s].next_sibling) {
        char prev[24], cur[24];
        snprintf(prev, sizeof prev, "%s", vname);
        int32_t k = s;
        for (;;) {
            node_name(counter, cur, sizeof cur);
            if (emit && (x->st = ag_grammar_add_split(r, cur, prev, t->nodes[k].pivot,
                                                      t->nodes[k].octant, 0, 0)))
                return;
            memcpy(prev, cur, sizeof prev);
            if (t->nodes[k].kind != AG_NODE_SPLIT)
                break;
            k = t->nodes[k].first_child;
        }
        const ag_tnode *e = &t->nodes[k];
        if (e->kind == AG_NODE_PATTERN) {
            const ag_pattern *p = &t->patterns[e->pattern];
            int32_t ri = use_rule(x, p->rule, e->first_child, 2);
            if (emit && !x->st) {
                int rot = (p->rot - t->nodes[x->exemplar[p->rule]].rule_rot) & 3;
                if (p->nvec)
                    x->st = ag_grammar_add_repeat(r, x->g->rules[ri].name, cur, rot, p->nvec,
                                                  p->counts, p->vec, 0, 0);
                else
                    x->st = ag_grammar_add_apply(r, x->g->rules[ri].name, cur, rot, p->counts,
                                                 p->step, 0, 0);
            }
        } else if (e->kind == AG_NODE_COMPONENT && is_rule(x, e->rule)) {
            int32_t ri = use_rule(x, e->rule, k, 1);
            if (emit && !x->st) {
                int rot = (e->rule_rot - t->nodes[x->exemplar[e->rule]].rule_rot) & 3;
                x->st = ag_grammar_add_apply(r, x->g->rules[ri].name, cur, rot, NULL, NULL, 0, 0);
            }
        } else {
            emit_content(x, r, k, cur, counter);
        }
    }
}

void ag_grammar_export_info_free(ag_grammar_export_info *info)
{
    if (!info)
        return;
    free(info->rule_of_class);
    free(info->terminal_of_variant);
    memset(info, 0, sizeof *info);
}

ag_status ag_grammar_export(const ag_mesh *m, const ag_labels *L, const ag_splittree *t,
                            ag_grammar **out, ag_grammar_export_info *info, ag_error *err)
{
    *out = NULL;
    exctx x = {.m = m, .L = L, .t = t};
    size_t nc = t->nrules;
    size_t maxt = 0;
    for (size_t c = 0; c < L->ncomponents; c++)
        if (L->ntris[c] > maxt)
            maxt = L->ntris[c];
    x.g = ag_grammar_create();
    x.apps = calloc(nc + 1, sizeof *x.apps);
    x.exemplar = malloc((nc + 1) * sizeof *x.exemplar);
    x.visited = calloc(nc + 1, 1);
    x.in_pattern = calloc(nc + 1, 1);
    x.rule_of = malloc((nc + 1) * sizeof *x.rule_of);
    x.term_of = malloc((L->nvariants + 1) * sizeof *x.term_of);
    x.vmap = malloc((m->nverts + 1) * sizeof *x.vmap);
    x.tpos = malloc((9 * maxt + 3) * sizeof *x.tpos);
    x.ttri = malloc((3 * maxt + 3) * sizeof *x.ttri);
    ag_status st = AG_ERR_NOMEM;
    if (!x.g || !x.apps || !x.exemplar || !x.visited || !x.in_pattern || !x.rule_of || !x.term_of || !x.vmap ||
        !x.tpos || !x.ttri)
        goto done;
    for (size_t i = 0; i < nc; i++)
        x.rule_of[i] = -1;
    for (size_t i = 0; i < L->nvariants; i++)
        x.term_of[i] = -1;
    for (size_t i = 0; i < m->nverts; i++)
        x.vmap[i] = UINT32_MAX;
    unsigned counter = 0;
    x.pass = 1;
    emit_content(&x, &scratch_rule, 0, "p", &counter);
    x.pass = 2;
    counter = 0;
    x.g->has_axiom = 1;
    x.g->axiom.box = t->nodes[0].box;
    emit_content(&x, &x.g->axiom, 0, "p", &counter);
    st = x.st;
    if (st)
        goto done;
    {
        long col;
        ag_error why;
        ag_error_clear(&why);
        st = ag_grammar_resolve(x.g, &why, &col);
        if (st) {
            /* the reason is copied first: err may not be both the source and the target */
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "exported grammar does not resolve: %s",
                              why.text);
            goto done;
        }
    }
    if (info) {
        info->rule_of_class = x.rule_of;
        info->terminal_of_variant = x.term_of;
        info->nclasses = nc;
        info->nvariants = L->nvariants;
        x.rule_of = NULL;
        x.term_of = NULL;
    }
    *out = x.g;
    x.g = NULL;
    st = AG_OK;
done:
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory while exporting the grammar");
    ag_grammar_free(x.g);
    free(x.apps);
    free(x.exemplar);
    free(x.visited);
    free(x.in_pattern);
    free(x.rule_of);
    free(x.term_of);
    free(x.vmap);
    free(x.tpos);
    free(x.ttri);
    return st;
}

/* ---- derivation ------------------------------------------------------------------------- */

typedef struct {
    const ag_grammar *g;
    ag_mesh *out;
    size_t max_tris;
    int32_t *tgroup; /* per terminal: group of the derived mesh */
    ag_status st;
    ag_error *err;
} dctx;

static void derive_body(dctx *d, const ag_grule *r, const ag_box *p, const ag_gframe *F, int depth);

static void apply_one(dctx *d, const ag_gstmt *s, const ag_box *B, const ag_gframe *F, int depth)
{
    if (d->st)
        return;
    /* derivation takes a resolved grammar: every callee is an index */
    assert(s->callee_ix >= 0 &&
           (size_t)s->callee_ix < (s->callee_is_rule ? d->g->nrules : d->g->nterminals));
    if (s->callee_is_rule) {
        const ag_grule *r = &d->g->rules[s->callee_ix];
        ag_gframe G = ag_gframe_place(F, r->size, s->rot, B);
        ag_box lb = {{0, 0, 0}, {r->size[0], r->size[1], r->size[2]}};
        derive_body(d, r, &lb, &G, depth + 1);
        return;
    }
    const ag_gterminal *T = &d->g->terminals[s->callee_ix];
    if (!T->pos && T->ntris) {
        d->st = ag_error_set(d->err, AG_ERR_INVALID, s->line,
                             "terminal '%s' has no geometry loaded", T->name);
        return;
    }
    if (d->out->ntris + T->ntris > d->max_tris) {
        d->st = ag_error_set(d->err, AG_ERR_TOO_LARGE, s->line,
                             "the derivation exceeds %zu triangles", d->max_tris);
        return;
    }
    ag_gframe G = ag_gframe_place(F, T->size, s->rot, B);
    ag_mesh *m = d->out;
    size_t base = m->nverts, comp;
    if ((d->st = ag_mesh_add_component(m, d->tgroup[s->callee_ix], &comp)))
        return;
    for (size_t v = 0; v < T->nverts; v++) {
        double y[3];
        ag_gframe_apply(&G, T->pos + 3 * v, y);
        if ((d->st = ag_mesh_add_vertex(m, y[0], y[1], y[2])))
            return;
    }
    for (size_t t = 0; t < T->ntris; t++) {
        const uint32_t *q = T->tri + 3 * t;
        if (q[0] >= T->nverts || q[1] >= T->nverts || q[2] >= T->nverts) {
            d->st = ag_error_set(d->err, AG_ERR_INVALID, 0, "terminal '%s' has a bad index",
                                 T->name);
            return;
        }
        if ((d->st = ag_mesh_add_triangle(m, (uint32_t)(base + q[0]), (uint32_t)(base + q[1]),
                                          (uint32_t)(base + q[2]), (uint32_t)comp)))
            return;
    }
}

static void derive_body(dctx *d, const ag_grule *r, const ag_box *p, const ag_gframe *F, int depth)
{
    if (d->st)
        return;
    if (depth > DERIVE_MAX_DEPTH) {
        d->st = ag_error_set(d->err, AG_ERR_TOO_LARGE, r->line,
                             "rules are nested more than %d deep", DERIVE_MAX_DEPTH);
        return;
    }
    ag_box stackb[64];
    ag_box *b = r->nnodes <= 64 ? stackb : malloc(r->nnodes * sizeof *b);
    if (!b) {
        d->st = AG_ERR_NOMEM;
        return;
    }
    b[0] = *p;
    for (size_t i = 0; i < r->nstmts && !d->st; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            b[s->node_ix] = ag_splittree_child_box(&b[s->parent_ix], s->v, s->octant);
            continue;
        }
        const ag_box *B = &b[s->node_ix];
        if (!s->subdivide) {
            apply_one(d, s, B, F, depth);
            continue;
        }
        ag_gframe_cells cells;
        ag_gframe_cells_of(s, B, &cells);
        for (uint32_t k = 0; k < s->counts[2] && !d->st; k++)
            for (uint32_t j = 0; j < s->counts[1] && !d->st; j++)
                for (uint32_t i2 = 0; i2 < s->counts[0] && !d->st; i2++) {
                    ag_box c = ag_gframe_cell(&cells, i2, j, k);
                    apply_one(d, s, &c, F, depth);
                }
    }
    if (b != stackb)
        free(b);
}

ag_status ag_grammar_derive(const ag_grammar *g, const ag_grammar_derive_options *opt,
                            ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (!g->has_axiom)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the grammar has no axiom");
    dctx d = {.g = g, .err = err};
    d.max_tris = opt && opt->max_triangles ? opt->max_triangles : DERIVE_MAX_TRIANGLES;
    d.out = ag_mesh_create();
    if (!d.out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    d.tgroup = malloc((g->nterminals + 1) * sizeof *d.tgroup);
    if (!d.tgroup)
        d.st = AG_ERR_NOMEM;
    for (size_t i = 0; i < g->nterminals && !d.st; i++) {
        const char *gn = g->terminals[i].label_name ? g->terminals[i].label_name
                                                    : g->terminals[i].name;
        size_t k = 0;
        while (k < d.out->ngroups && strcmp(d.out->group_names[k], gn))
            k++;
        if (k == d.out->ngroups)
            d.st = ag_mesh_add_group(d.out, gn, &k);
        d.tgroup[i] = (int32_t)k;
    }
    if (!d.st)
        derive_body(&d, &g->axiom, &g->axiom.box, &ag_gframe_identity, 0);
    free(d.tgroup);
    if (d.st) {
        ag_mesh_free(d.out);
        if (d.st == AG_ERR_NOMEM)
            ag_error_set(err, d.st, 0, "out of memory while deriving");
        return d.st;
    }
    if (d.out->ntris == 0) {
        ag_mesh_free(d.out);
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the grammar derives no triangle");
    }
    *out = d.out;
    return AG_OK;
}

/* ---- fidelity --------------------------------------------------------------------------- */

static double *soup_of(const ag_mesh *m)
{
    double *s = malloc((9 * m->ntris + 1) * sizeof *s);
    if (!s)
        return NULL;
    for (size_t t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++)
            memcpy(s + 9 * t + 3 * k, m->pos + 3 * m->tri[3 * t + k], 3 * sizeof *s);
    return s;
}

ag_status ag_grammar_fidelity(const ag_mesh *input, const ag_mesh *derived, double tol,
                              ag_fidelity *f, ag_error *err)
{
    memset(f, 0, sizeof *f);
    ag_box b = ag_mesh_bounds(input);
    double diag = ag_box_diagonal(&b);
    if (!(diag > 0))
        diag = 1;
    if (tol <= 0)
        tol = AG_PROC_FIDELITY * diag;
    double *a = soup_of(derived), *s = soup_of(input);
    if (!a || !s) {
        free(a);
        free(s);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    size_t miss = 0;
    double w = ag_label_match_triangles(a, derived->ntris, s, input->ntris, tol, &miss);
    free(a);
    free(s);
    if (w < 0)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    f->max_error = w;
    f->relative = w / diag;
    f->unmatched = miss;
    f->input_triangles = input->ntris;
    f->derived_triangles = derived->ntris;
    return AG_OK;
}
